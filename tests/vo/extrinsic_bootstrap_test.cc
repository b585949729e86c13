#include "vo/extrinsic_bootstrap.h"

#include <gtest/gtest.h>

#include <random>

#include "synthetic_rig.h"
#include "vo/local_ba.h"

namespace rovo {
namespace {

// One frame of features: every point seen by >= 2 cameras gets one track id in all of them.
FrontendFrame SharedFeatures(const std::vector<Rigid3>& cam_from_rig, const std::vector<Eigen::Vector3d>& points_in_rig,
                             std::mt19937_64& rng, double noise_rad) {
  FrontendFrame frame;
  frame.features_per_camera.resize(cam_from_rig.size());
  uint64_t id = 0;
  for (const Eigen::Vector3d& x : points_in_rig) {
    ++id;
    std::vector<int> seen;
    for (size_t j = 0; j < cam_from_rig.size(); ++j) {
      if (test::InFov220(cam_from_rig[j] * x)) seen.push_back(static_cast<int>(j));
    }
    if (seen.size() < 2) continue;
    for (int j : seen) {
      Feature f;
      f.warped_px.setZero();
      f.track_id = id;
      f.camera = j;
      f.bearing_in_cam = test::NoisyBearing(rng, (cam_from_rig[j] * x).normalized(), noise_rad);
      frame.features_per_camera[j].push_back(f);
    }
  }
  return frame;
}

double RelativeRotationErrorDeg(const std::vector<Rigid3>& estimate, const std::vector<Rigid3>& truth, int j) {
  const Eigen::Quaterniond est = estimate[j].rotation * estimate[0].rotation.conjugate();
  const Eigen::Quaterniond gt = truth[j].rotation * truth[0].rotation.conjugate();
  return RotationDistanceDeg(est, gt);
}

TEST(ExtrinsicBootstrap, RecoversTenDegreeErrorsFromNearAndFarPoints) {
  std::mt19937_64 rng(7);
  const std::vector<Rigid3> truth = test::SquareRigExtrinsics();
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 600; ++i) points.push_back(test::RandomPoint(rng, 3.0, 30.0));
  for (int i = 0; i < 200; ++i) points.push_back(test::RandomPoint(rng, 150.0, 400.0));
  const FrontendFrame frame = SharedFeatures(truth, points, rng, 0.02 * M_PI / 180.0);

  std::vector<Rigid3> estimate = truth;
  for (int j = 1; j < 4; ++j) {
    // Turn each camera about its own centre, as datasets/rig.h's PerturbExtrinsics does.
    const Eigen::Vector3d centre = truth[j].Inverse().translation;
    const Eigen::Quaterniond rotation = test::RandomRotation(rng, 10.0) * truth[j].rotation;
    estimate[j] = Rigid3(rotation, -(rotation * centre));
    ASSERT_GT(RelativeRotationErrorDeg(estimate, truth, j), 9.0);
  }
  const std::vector<double> baselines = RingBaselineLengths(truth);
  ExtrinsicBootstrapOptions options;
  options.max_error_deg = 15.0;
  ExtrinsicBootstrapReport report;
  for (int round = 0; round < 5; ++round) {
    report = CalibrateExtrinsicsFromFrame(frame, estimate, baselines, options);
    ASSERT_TRUE(report.usable) << "round " << round;
    estimate = report.cam_from_rig;
    options.max_error_deg = std::max(0.5, std::min(0.5 * options.max_error_deg, 3.0 * report.max_change_deg));
  }
  for (int j = 1; j < 4; ++j) EXPECT_LT(RelativeRotationErrorDeg(estimate, truth, j), 0.05) << "camera " << j;
  EXPECT_TRUE(estimate[0].rotation.isApprox(truth[0].rotation, 1e-12));  // the gauge
  const std::vector<double> lengths = RingBaselineLengths(estimate);
  for (size_t k = 0; k < lengths.size(); ++k) EXPECT_NEAR(lengths[k], baselines[k], 1e-3) << "baseline " << k;
  EXPECT_LT(report.median_error_deg_after, 0.05);
}

TEST(ExtrinsicBootstrap, TooFewSharedPointsLeavesTheExtrinsics) {
  std::mt19937_64 rng(3);
  const std::vector<Rigid3> truth = test::SquareRigExtrinsics();
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 5; ++i) points.push_back(test::RandomPoint(rng, 3.0, 30.0));
  const FrontendFrame frame = SharedFeatures(truth, points, rng, 0.0);
  const ExtrinsicBootstrapReport report =
      CalibrateExtrinsicsFromFrame(frame, truth, RingBaselineLengths(truth), ExtrinsicBootstrapOptions{});
  EXPECT_FALSE(report.usable);
  ASSERT_EQ(report.cam_from_rig.size(), truth.size());
  for (size_t j = 0; j < truth.size(); ++j) EXPECT_TRUE(report.cam_from_rig[j].rotation.isApprox(truth[j].rotation));
}

TEST(ExtrinsicBootstrap, WrongCameraCountIsNotUsable) {
  FrontendFrame frame;
  frame.features_per_camera.resize(2);
  const std::vector<Rigid3> truth = test::SquareRigExtrinsics();
  EXPECT_FALSE(CalibrateExtrinsicsFromFrame(frame, truth, RingBaselineLengths(truth), {}).usable);
}

}  // namespace
}  // namespace rovo
