// The rovo4_stereo rig: `rovo render --rig rovo4_stereo` renders the fisheye ring and the forward
// pair from one sequence; `rovo vo` runs on the ring alone (--cameras auto) and records it; the
// forward pair exports as a two-camera Basalt dataset.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/run.h"
#include "datasets/trajectory.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;

int RunCommand(const std::string& command) { return std::system(command.c_str()); }

TEST(StereoRig, RendersRingAndForwardPairAndTheVoRunsOnTheRing) {
  const fs::path root = fs::temp_directory_path() / "rovo_stereo_rig_test";
  fs::remove_all(root);
  const std::string dataset = (root / "dataset").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " render --preset cloudy_urban --quick --rig rovo4_stereo " +
                       "--frames 0:8 --spp 1 --quiet --out " + dataset),
            0);
  const DatasetInfo info = ReadDatasetInfo(dataset);
  ASSERT_EQ(info.rig.NumCameras(), 6);
  // The forward pair at the quick scale: 512 x 384, images with content (not a black frame).
  for (const std::string name : {"cam4", "cam5"}) {
    const cv::Mat image = cv::imread(ImagePath(dataset, name, 0), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(image.cols, 512) << name;
    ASSERT_EQ(image.rows, 384) << name;
    double lo = 0, hi = 0;
    cv::minMaxLoc(image, &lo, &hi);
    EXPECT_GT(hi - lo, 50.0) << name;
  }

  const std::string run_dir = (root / "run").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics gt --quiet --out " + run_dir), 0);
  const RunData run = ReadRun(run_dir);
  EXPECT_EQ(run.info["vo_cameras"], nlohmann::json({0, 1, 2, 3}));
  EXPECT_EQ(run.info["cameras"], "auto");
  ASSERT_EQ(run.trajectory.size(), 8u);
  for (const ExtrinsicsRecord& r : run.extrinsics) EXPECT_LT(r.camera, 4);
  EXPECT_EQ(run.extrinsics.size(), 8u * 4u);
  int ok = 0;
  for (const FrameRecord& f : run.frames) ok += f.status == FrameStatus::kOk;
  EXPECT_GE(ok, 5);
  const Trajectory gt = ReadTum(GroundTruthPath(dataset));
  for (size_t i = 0; i < run.trajectory.size(); ++i) {
    EXPECT_LT((run.trajectory[i].world_from_rig.translation - gt[i].world_from_rig.translation).norm(), 0.1) << i;
  }
  // A camera list without camera 0 (the gauge) is refused before any frame, naming the flag.
  EXPECT_NE(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics gt --cameras 1,2 --quiet --out " +
                       (root / "bad").string() + " 2> " + (root / "bad.log").string()),
            0);
  EXPECT_NE(ReadFile((root / "bad.log").string()).find("must include camera 0"), std::string::npos);

  // The forward pair as Basalt reads it: two cameras, kb4, exact.
  const std::string exported = (root / "basalt").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " dataset export " + dataset +
                       " --format basalt --cameras 4,5 --out " + exported + " > " + (root / "export.log").string()),
            0);
  const nlohmann::json calibration = ReadJsonFile(exported + "/calibration.json");
  ASSERT_EQ(calibration["value0"]["intrinsics"].size(), 2u);
  EXPECT_EQ(calibration["value0"]["intrinsics"][0]["camera_type"], "kb4");
  const nlohmann::json report = ReadJsonFile(exported + "/rovo_export.json");
  EXPECT_LT(report["fits"][0]["max_error_px"].get<double>(), 1e-6);
  const cv::Mat grey =
      cv::imread(exported + "/mav0/cam0/data/" + std::to_string(std::llround(gt[0].timestamp * 1e9)) + ".png",
                 cv::IMREAD_UNCHANGED);
  EXPECT_EQ(grey.channels(), 1);
  EXPECT_EQ(grey.cols, 512);
  fs::remove_all(root);
}

}  // namespace
}  // namespace rovo
