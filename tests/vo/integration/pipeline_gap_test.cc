// End to end: render a short cloudy_urban sequence, black out three frames of every camera, run
// `rovo vo` and check that the run reports the gap as lost, re-initialises, tracks again, and stays
// close to the ground truth.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "datasets/dataset.h"
#include "datasets/run.h"
#include "datasets/trajectory.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;

int RunCommand(const std::string& command) { return std::system(command.c_str()); }

TEST(PipelineIntegration, RecoversFromGapOfBlackFrames) {
  const fs::path root = fs::temp_directory_path() / "rovo_vo_gap_test";
  fs::remove_all(root);
  const std::string dataset = (root / "dataset").string();
  const std::string run_dir = (root / "run").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " render --preset cloudy_urban --quick --frames 0:30 --quiet --out " +
                       dataset),
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
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics gt --frames 0:30 --quiet --out " +
                       run_dir),
            0);
  const RunData run = ReadRun(run_dir);
  ASSERT_EQ(run.frames.size(), 30u);
  ASSERT_EQ(run.trajectory.size(), 30u);
  EXPECT_EQ(run.frames[0].status, FrameStatus::kInit);
  for (int frame = gap_begin; frame < gap_end; ++frame)
    EXPECT_EQ(run.frames[frame].status, FrameStatus::kLost) << frame;
  int ok_after = 0;
  for (int frame = gap_end; frame < 30; ++frame) ok_after += run.frames[frame].status == FrameStatus::kOk;
  EXPECT_GE(ok_after, 30 - gap_end - 3);  // re-initialised, then tracking
  const Trajectory gt = ReadTum(GroundTruthPath(dataset));
  const double length = PathLength(Trajectory(gt.begin(), gt.begin() + 30));
  for (int frame = 0; frame < 30; ++frame) {
    const double error =
        (run.trajectory[frame].world_from_rig.translation - gt[frame].world_from_rig.translation).norm();
    EXPECT_LT(error, 0.05 * length + 0.5) << "frame " << frame;
  }
  EXPECT_EQ(run.info["mode"], "gt");
  EXPECT_EQ(run.info["summary"]["missing_images"], 0);

  // An unreadable image of one camera is counted per frame and camera, in frames.csv and run.json.
  const std::string broken = ImagePath(dataset, info.rig.cameras[2].name, 5);
  { std::ofstream(broken, std::ios::trunc) << "not a png"; }
  fs::remove(ImagePath(dataset, info.rig.cameras[1].name, 6));
  const std::string run2 = (root / "run_missing").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics gt --frames 0:8 --quiet --out " +
                       run2 + " > " + (root / "stdout.txt").string()),
            0);
  const RunData missing = ReadRun(run2);
  EXPECT_EQ(missing.frames[5].missing_cameras, "2");
  EXPECT_EQ(missing.frames[6].missing_cameras, "1");
  EXPECT_EQ(missing.frames[4].missing_cameras, "");
  EXPECT_EQ(missing.info["summary"]["missing_images"], 2);
  EXPECT_EQ(missing.info["summary"]["frames_with_missing_images"], 2);
  std::ifstream out((root / "stdout.txt").string());
  const std::string printed((std::istreambuf_iterator<char>(out)), std::istreambuf_iterator<char>());
  EXPECT_NE(printed.find("2 images missing or unreadable in 2 frames"), std::string::npos) << printed;

  // A camera folder missing entirely is an error before any work, naming the folder.
  fs::remove_all(fs::path(dataset) / info.rig.cameras[3].name);
  const std::string err = (root / "stderr.txt").string();
  EXPECT_NE(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics gt --frames 0:8 --quiet --out " +
                       (root / "run_nofolder").string() + " 2> " + err),
            0);
  std::ifstream in(err);
  const std::string message((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find((fs::path(dataset) / info.rig.cameras[3].name).string() + ": image folder of camera"),
            std::string::npos)
      << message;
  EXPECT_FALSE(fs::exists((root / "run_nofolder" / "run.json")));
  fs::remove_all(root);
}

}  // namespace
}  // namespace rovo
