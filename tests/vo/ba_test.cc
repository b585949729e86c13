#include "vo/local_ba.h"

#include "synthetic_rig.h"

#include <gtest/gtest.h>

#include <random>

namespace rovo {
namespace {

struct Scenario {
  std::vector<Rigid3> rig_from_world;
  std::vector<Rigid3> cam_from_rig;
  std::vector<Eigen::Vector3d> points;
  LocalBaProblem problem;  // exact observations, ground-truth parameters
};

// A rig driving 1 m per frame with a slow turn through a field of points; exact bearings.
Scenario MakeScenario(std::mt19937_64& rng, int num_poses, int num_points) {
  Scenario s;
  s.cam_from_rig = test::SquareRigExtrinsics();
  for (int i = 0; i < num_poses; ++i) {
    const Rigid3 world_from_rig(Eigen::Quaterniond(Eigen::AngleAxisd(0.03 * i, Eigen::Vector3d::UnitZ())),
                                Eigen::Vector3d(1.0 * i, 0.05 * i * i, 0.0));
    s.rig_from_world.push_back(world_from_rig.Inverse());
  }
  for (int k = 0; k < num_points; ++k) {
    s.points.push_back(test::RandomPoint(rng, 4.0, 25.0) + Eigen::Vector3d(0.5 * num_poses, 0.0, 0.0));
  }
  LocalBaProblem& p = s.problem;
  p.rig_from_world = s.rig_from_world;
  p.cam_from_rig = s.cam_from_rig;
  p.points_in_world = s.points;
  p.point_num_cameras.assign(num_points, 0);
  for (int k = 0; k < num_points; ++k) {
    std::vector<char> seen(4, 0);
    for (int i = 0; i < num_poses; ++i) {
      for (int j = 0; j < 4; ++j) {
        const Eigen::Vector3d in_cam = s.cam_from_rig[j] * (s.rig_from_world[i] * s.points[k]);
        if (!test::InFov220(in_cam) || in_cam.norm() > 40.0) continue;
        p.observations.push_back({i, j, k, in_cam.normalized()});
        seen[j] = 1;
      }
    }
    p.point_num_cameras[k] = seen[0] + seen[1] + seen[2] + seen[3];
  }
  return s;
}

TEST(LocalBa, OnlineCalibrationRecoversPerturbedExtrinsics) {
  std::mt19937_64 rng(37);
  Scenario s = MakeScenario(rng, 8, 400);
  LocalBaProblem p = s.problem;
  const std::vector<double> baselines = RingBaselineLengths(s.cam_from_rig);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int j = 1; j < 4; ++j) {
    p.cam_from_rig[j] = Rigid3(test::RandomRotation(rng, 5.0) * p.cam_from_rig[j].rotation, p.cam_from_rig[j].translation);
    EXPECT_GT(RotationDistanceDeg(p.cam_from_rig[j].rotation, s.cam_from_rig[j].rotation), 4.9);
  }
  for (size_t i = 1; i < p.rig_from_world.size(); ++i) {
    p.rig_from_world[i] = Rigid3(test::RandomRotation(rng, 0.3) * p.rig_from_world[i].rotation,
                                 p.rig_from_world[i].translation + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)) * 0.05);
  }
  for (auto& x : p.points_in_world) x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng)) * 0.1;
  p.baseline_lengths = baselines;

  LocalBaOptions options;
  options.optimize_extrinsics = true;
  options.max_iterations = 50;
  const LocalBaReport report = SolveLocalBa(p, options);
  ASSERT_TRUE(report.usable);
  EXPECT_LT(report.final_cost, 1e-3 * report.initial_cost);
  for (int j = 0; j < 4; ++j) {
    EXPECT_LT(RotationDistanceDeg(p.cam_from_rig[j].rotation, s.cam_from_rig[j].rotation), 0.1) << "camera " << j;
  }
  EXPECT_EQ(p.cam_from_rig[0].Matrix3x4(), s.cam_from_rig[0].Matrix3x4());  // gauge
  const std::vector<double> after = RingBaselineLengths(p.cam_from_rig);
  for (size_t k = 0; k < baselines.size(); ++k) EXPECT_NEAR(after[k], baselines[k], 1e-3);
  for (size_t i = 0; i < p.rig_from_world.size(); ++i) {
    EXPECT_LT((p.rig_from_world[i].Inverse().translation - s.rig_from_world[i].Inverse().translation).norm(), 0.01);
  }
}

TEST(LocalBa, FixedExtrinsicsStayFixedAndPosesImprove) {
  std::mt19937_64 rng(41);
  Scenario s = MakeScenario(rng, 6, 300);
  LocalBaProblem p = s.problem;
  for (size_t i = 1; i < p.rig_from_world.size(); ++i) {
    p.rig_from_world[i].translation += Eigen::Vector3d(0.1, -0.05, 0.02);
  }
  LocalBaOptions options;
  options.max_iterations = 30;
  const LocalBaReport report = SolveLocalBa(p, options);
  ASSERT_TRUE(report.usable);
  for (int j = 0; j < 4; ++j) EXPECT_EQ(p.cam_from_rig[j].Matrix3x4(), s.cam_from_rig[j].Matrix3x4());
  EXPECT_EQ(p.rig_from_world[0].Matrix3x4(), s.rig_from_world[0].Matrix3x4());
  for (size_t i = 1; i < p.rig_from_world.size(); ++i) {
    EXPECT_LT((p.rig_from_world[i].translation - s.rig_from_world[i].translation).norm(), 1e-4);
  }
}

TEST(LocalBa, DeterministicForSameInput) {
  std::mt19937_64 rng(43);
  Scenario s = MakeScenario(rng, 5, 200);
  LocalBaProblem a = s.problem;
  for (auto& x : a.points_in_world) x += Eigen::Vector3d(0.05, 0.0, -0.05);
  a.cam_from_rig[2] = Rigid3(test::RandomRotation(rng, 2.0) * a.cam_from_rig[2].rotation, a.cam_from_rig[2].translation);
  LocalBaProblem b = a;
  LocalBaOptions options;
  options.optimize_extrinsics = true;
  SolveLocalBa(a, options);
  SolveLocalBa(b, options);
  for (int j = 0; j < 4; ++j) EXPECT_EQ(a.cam_from_rig[j].Matrix3x4(), b.cam_from_rig[j].Matrix3x4());
  for (size_t k = 0; k < a.points_in_world.size(); ++k) EXPECT_EQ(a.points_in_world[k], b.points_in_world[k]);
}

}  // namespace
}  // namespace rovo
