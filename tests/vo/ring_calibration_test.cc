#include "vo/ring_calibration.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "datasets/rig.h"

namespace rovo {
namespace {

TEST(RingPairs, FourCameraRingClosesInYawOrder) {
  const Rig rig = MakeRigPreset("rovo4");
  auto pairs = RingPairs(rig);
  ASSERT_EQ(pairs.size(), 4u);
  // Every camera is in exactly two pairs.
  for (int j = 0; j < 4; ++j) {
    EXPECT_EQ(std::count_if(pairs.begin(), pairs.end(), [&](auto p) { return p.first == j || p.second == j; }), 2) << j;
  }
  // Neighbours face at most ~100 deg apart.
  for (const auto& [a, b] : pairs) {
    EXPECT_LT(AngleBetween(CameraAxisInRig(rig.cameras[a].cam_from_rig), CameraAxisInRig(rig.cameras[b].cam_from_rig)),
              100.0 * M_PI / 180.0);
  }
}

TEST(RingPairs, TwoBackToBackLensesMakeOnePairNarrowLensesNone) {
  Rig rig = MakeRigPreset("rovo4");
  rig.cameras.resize(2);
  rig.cameras[0].cam_from_rig = CamFromRigFromMount(0.0, 0.0, Eigen::Vector3d(0.1, 0, 0));
  rig.cameras[1].cam_from_rig = CamFromRigFromMount(180.0, 0.0, Eigen::Vector3d(-0.1, 0, 0));
  EXPECT_EQ(RingPairs(rig).size(), 1u);
  for (auto& c : rig.cameras) c.camera.max_fov_deg = 150.0;  // no overlap between opposite 150 deg lenses
  EXPECT_TRUE(RingPairs(rig).empty());
}

TEST(RingCalibrator, RejectsWrongImageAndMaskCounts) {
  const Rig rig = MakeRigPreset("rovo4").Scaled(0.125);
  EXPECT_THROW(RingCalibrator(rig, std::vector<cv::Mat>(3)), std::invalid_argument);
  RingCalibrator calibrator(rig);
  EXPECT_THROW(calibrator.AddFrame(std::vector<cv::Mat>(2)), std::invalid_argument);
  // Black images: no matches, so no calibration, and the report says why.
  std::vector<cv::Mat> black;
  for (const auto& c : rig.cameras) black.push_back(cv::Mat::zeros(c.camera.height, c.camera.width, CV_8UC1));
  calibrator.AddFrame(black);
  const RingCalibrationReport report = calibrator.Solve();
  EXPECT_FALSE(report.converged);
  EXPECT_NE(report.reason.find("too few overlap matches"), std::string::npos) << report.reason;
  EXPECT_EQ(report.cam_from_rig.size(), 4u);
}

}  // namespace
}  // namespace rovo
