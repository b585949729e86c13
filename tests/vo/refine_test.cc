#include <gtest/gtest.h>

#include <random>

#include "synthetic_rig.h"
#include "vo/pose_refinement.h"

namespace rovo {
namespace {

// Noisy bearings: the RANSAC pose from a minimal sample is off; refinement over all inliers must
// bring the pose closer to the truth, and must ignore the few gross outliers (Cauchy loss).
TEST(PoseRefinement, ReducesErrorUnderNoise) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  int improved = 0;
  const int trials = 10;
  for (int trial = 0; trial < trials; ++trial) {
    const Rigid3 rig_from_world(test::RandomRotation(rng, 30.0), Eigen::Vector3d(u(rng), u(rng), u(rng)) * 3.0);
    std::vector<std::vector<BearingPointCorrespondence>> corrs(4);
    for (int j = 0; j < 4; ++j) {
      const Rigid3 cam_from_world = cam_from_rig[j] * rig_from_world;
      while (corrs[j].size() < 60) {
        const Eigen::Vector3d x = rig_from_world.Inverse() * test::RandomPoint(rng);
        const Eigen::Vector3d in_cam = cam_from_world * x;
        if (!test::InFov220(in_cam)) continue;
        Eigen::Vector3d b = test::NoisyBearing(rng, in_cam.normalized(), 0.002);
        if (corrs[j].size() < 3) b = test::NoisyBearing(rng, b, 0.05);  // gross outliers
        corrs[j].push_back({b, x});
      }
    }
    // Start from a perturbed pose (what a minimal-sample hypothesis looks like).
    const Rigid3 start(test::RandomRotation(rng, 0.5) * rig_from_world.rotation,
                       rig_from_world.translation + Eigen::Vector3d(0.05, -0.03, 0.02));
    const PoseRefinementResult result = RefineRigPose(corrs, cam_from_rig, {}, start);
    ASSERT_TRUE(result.usable);
    EXPECT_EQ(result.num_residuals, 240);
    EXPECT_LT(result.final_cost, result.initial_cost);
    const double rot_before = RotationDistanceDeg(start.rotation, rig_from_world.rotation);
    const double rot_after = RotationDistanceDeg(result.rig_from_world.rotation, rig_from_world.rotation);
    const double t_before = (start.translation - rig_from_world.translation).norm();
    const double t_after = (result.rig_from_world.translation - rig_from_world.translation).norm();
    EXPECT_LT(rot_after, 0.05);
    EXPECT_LT(t_after, 0.02);
    if (rot_after < rot_before && t_after < t_before) ++improved;
    EXPECT_LT(MeanAngularError(corrs, cam_from_rig, {}, result.rig_from_world),
              MeanAngularError(corrs, cam_from_rig, {}, start));
  }
  EXPECT_EQ(improved, trials);
}

TEST(PoseRefinement, InlierMaskSelectsResiduals) {
  const auto cam_from_rig = test::SquareRigExtrinsics();
  std::vector<std::vector<BearingPointCorrespondence>> corrs(4);
  std::vector<std::vector<char>> mask(4);
  std::mt19937_64 rng(2);
  for (int j = 0; j < 4; ++j) {
    while (corrs[j].size() < 10) {
      const Eigen::Vector3d x = test::RandomPoint(rng);
      const Eigen::Vector3d in_cam = cam_from_rig[j] * x;
      if (!test::InFov220(in_cam)) continue;
      corrs[j].push_back({in_cam.normalized(), x});
      mask[j].push_back(corrs[j].size() % 2);
    }
  }
  const auto result = RefineRigPose(corrs, cam_from_rig, mask, Rigid3());
  EXPECT_EQ(result.num_residuals, 20);
  EXPECT_LT(result.rig_from_world.translation.norm(), 1e-9);
}

}  // namespace
}  // namespace rovo
