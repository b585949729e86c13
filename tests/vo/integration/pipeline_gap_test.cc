// End to end: render a short cloudy_urban sequence, black out three frames of every camera, run
// `rovo vo` and check that the run reports the gap as lost, re-initialises, tracks again, and stays
// close to the ground truth.
#include "datasets/dataset.h"
#include "datasets/run.h"
#include "datasets/trajectory.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace rovo {
namespace {

namespace fs = std::filesystem;

int RunCommand(const std::string& command) { return std::system(command.c_str()); }

TEST(PipelineIntegration, RecoversFromGapOfBlackFrames) {
  const fs::path root = fs::temp_directory_path() / "rovo_vo_gap_test";
  fs::remove_all(root);
  const std::string dataset = (root / "dataset").string();
  const std::string run_dir = (root / "run").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " render --preset cloudy_urban --quick --frames 0:30 --quiet --out " + dataset),
            0);
  const DatasetInfo info = ReadDatasetInfo(dataset);
  ASSERT_GE(info.frame_count, 30);
  const int gap_begin = 12, gap_end = 15;
  for (int frame = gap_begin; frame < gap_end; ++frame) {
    for (const RigCamera& cam : info.rig.cameras) {
      const std::string path = ImagePath(dataset, cam.name, frame);
      cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(image.empty()) << path;
      image.setTo(0);
      ASSERT_TRUE(cv::imwrite(path, image)) << path;
    }
  }
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics gt --frames 0:30 --quiet --out " + run_dir),
            0);
  const RunData run = ReadRun(run_dir);
  ASSERT_EQ(run.frames.size(), 30u);
  ASSERT_EQ(run.trajectory.size(), 30u);
  EXPECT_EQ(run.frames[0].status, "init");
  for (int frame = gap_begin; frame < gap_end; ++frame) EXPECT_EQ(run.frames[frame].status, "lost") << frame;
  int ok_after = 0;
  for (int frame = gap_end; frame < 30; ++frame) ok_after += run.frames[frame].status == "ok";
  EXPECT_GE(ok_after, 30 - gap_end - 3);  // re-initialised, then tracking
  const Trajectory gt = ReadTum(GroundTruthPath(dataset));
  const double length = PathLength(Trajectory(gt.begin(), gt.begin() + 30));
  for (int frame = 0; frame < 30; ++frame) {
    const double error = (run.trajectory[frame].world_from_rig.translation - gt[frame].world_from_rig.translation).norm();
    EXPECT_LT(error, 0.05 * length + 0.5) << "frame " << frame;
  }
  EXPECT_EQ(run.info["mode"], "gt");
  fs::remove_all(root);
}

}  // namespace
}  // namespace rovo
