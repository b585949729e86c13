#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "synthetic_rig.h"
#include "vo/local_ba.h"

namespace rovo {
namespace {

// The bearing residual written with autodiff, as the reference for the analytic one.
struct AutodiffBearing {
  template <typename T>
  bool operator()(const T* rig, const T* cam, const T* x, T* r) const {
    T in_rig[3], in_cam[3];
    ceres::AngleAxisRotatePoint(rig, x, in_rig);
    for (int k = 0; k < 3; ++k) in_rig[k] += rig[3 + k];
    ceres::AngleAxisRotatePoint(cam, in_rig, in_cam);
    for (int k = 0; k < 3; ++k) in_cam[k] += cam[3 + k];
    const T norm = ceres::sqrt(in_cam[0] * in_cam[0] + in_cam[1] * in_cam[1] + in_cam[2] * in_cam[2]);
    for (int c = 0; c < 2; ++c) {
      r[c] = T(0.0);
      for (int k = 0; k < 3; ++k) r[c] += T(basis(k, c)) * in_cam[k] / norm;
    }
    return true;
  }
  Eigen::Matrix<double, 3, 2> basis;
};

TEST(LocalBa, TangentBasisIsOrthonormalAndPerpendicular) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> bearings = {Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY(),
                                           Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
  for (int k = 0; k < 200; ++k) bearings.push_back(Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized());
  for (const Eigen::Vector3d& b : bearings) {
    const Eigen::Matrix<double, 3, 2> basis = TangentBasis(b);
    EXPECT_NEAR((basis.transpose() * basis - Eigen::Matrix2d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR((basis.transpose() * b).norm(), 0.0, 1e-12);
    // The residual of a bearing rotated by an angle a away from b has norm sin(a).
    const Eigen::Vector3d off = std::cos(0.3) * b + std::sin(0.3) * basis.col(0);
    EXPECT_NEAR((basis.transpose() * off).norm(), std::sin(0.3), 1e-12);
  }
}

TEST(LocalBa, AnalyticBearingJacobiansMatchAutodiff) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_vector = [&](double scale) -> Eigen::Vector3d { return Eigen::Vector3d(u(rng), u(rng), u(rng)) * scale; };
  for (int trial = 0; trial < 200; ++trial) {
    // Rotations from tiny (series branch) to near pi; points in front of and behind the camera.
    const double rot_scale = trial % 4 == 0 ? 1e-6 : 1.7;
    Eigen::Matrix<double, 6, 1> rig, cam;
    rig << random_vector(rot_scale), random_vector(5.0);
    cam << random_vector(rot_scale), random_vector(0.5);
    Eigen::Vector3d x = random_vector(20.0);
    const Eigen::Vector3d bearing = random_vector(1.0).normalized();
    std::unique_ptr<ceres::CostFunction> analytic(CreateBearingResidual(bearing));
    ceres::AutoDiffCostFunction<AutodiffBearing, 2, 6, 6, 3> reference(new AutodiffBearing{TangentBasis(bearing)});
    const double* params[3] = {rig.data(), cam.data(), x.data()};
    double r_a[2], r_b[2], j_a[3][12], j_b[3][12];
    double* jac_a[3] = {j_a[0], j_a[1], j_a[2]};
    double* jac_b[3] = {j_b[0], j_b[1], j_b[2]};
    ASSERT_TRUE(analytic->Evaluate(params, r_a, jac_a));
    ASSERT_TRUE(reference.Evaluate(params, r_b, jac_b));
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(r_a[k], r_b[k], 1e-12);
    const int sizes[3] = {12, 12, 6};
    for (int b = 0; b < 3; ++b) {
      for (int k = 0; k < sizes[b]; ++k) EXPECT_NEAR(j_a[b][k], j_b[b][k], 1e-9) << "trial " << trial << " block " << b;
    }
    // Blocks without a Jacobian request (constant blocks) are skipped, the others unchanged.
    double j_c[6];
    double* partial[3] = {nullptr, nullptr, j_c};
    ASSERT_TRUE(analytic->Evaluate(params, r_a, partial));
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(j_c[k], j_b[2][k], 1e-9);
  }
}

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
    p.cam_from_rig[j] =
        Rigid3(test::RandomRotation(rng, 5.0) * p.cam_from_rig[j].rotation, p.cam_from_rig[j].translation);
    EXPECT_GT(RotationDistanceDeg(p.cam_from_rig[j].rotation, s.cam_from_rig[j].rotation), 4.9);
  }
  for (size_t i = 1; i < p.rig_from_world.size(); ++i) {
    p.rig_from_world[i] =
        Rigid3(test::RandomRotation(rng, 0.3) * p.rig_from_world[i].rotation,
               p.rig_from_world[i].translation + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)) * 0.05);
  }
  for (auto& x : p.points_in_world) x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng)) * 0.1;
  p.baseline_lengths = baselines;

  LocalBaOptions options;
  options.extrinsic_prior_deg = 0.0;  // no random-walk prior
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

// The anchor holds the centres only when extrinsic_anchor_m is set: with an anchor whose camera-2
// centre is 2 cm off, a tight centre sigma pulls the centre 2 cm to the anchor's (without it, the exact
// observations keep it at its true place).
TEST(LocalBa, TheAnchorHoldsTheCentresWhenAsked) {
  std::mt19937_64 rng(53);
  const Scenario s = MakeScenario(rng, 6, 300);
  std::vector<Rigid3> anchor = s.cam_from_rig;
  const Eigen::Vector3d anchor_centre = CameraPositionInRig(anchor[2]) + Eigen::Vector3d(0.0, 0.0, 0.02);
  anchor[2] = Rigid3(anchor[2].rotation, -(anchor[2].rotation * anchor_centre));
  for (double sigma_m : {0.0, 1e-6}) {
    LocalBaProblem p = s.problem;
    LocalBaOptions options;
    options.extrinsic_prior_deg = 0.0;  // no random-walk prior
    options.optimize_extrinsics = true;
    options.max_iterations = 30;
    options.extrinsic_anchor = anchor;
    options.extrinsic_anchor_deg = 0.02;
    options.extrinsic_anchor_m = sigma_m;
    ASSERT_TRUE(SolveLocalBa(p, options).usable);
    const Eigen::Vector3d centre = CameraPositionInRig(p.cam_from_rig[2]);
    const Eigen::Vector3d expected = sigma_m > 0.0 ? anchor_centre : CameraPositionInRig(s.cam_from_rig[2]);
    EXPECT_LT((centre - expected).norm(), 0.002) << "anchor sigma " << sigma_m << " m";
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
  options.extrinsic_prior_deg = 0.0;  // no random-walk prior
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
  a.cam_from_rig[2] =
      Rigid3(test::RandomRotation(rng, 2.0) * a.cam_from_rig[2].rotation, a.cam_from_rig[2].translation);
  LocalBaProblem b = a;
  LocalBaOptions options;
  options.extrinsic_prior_deg = 0.0;  // no random-walk prior
  options.optimize_extrinsics = true;
  SolveLocalBa(a, options);
  SolveLocalBa(b, options);
  for (int j = 0; j < 4; ++j) EXPECT_EQ(a.cam_from_rig[j].Matrix3x4(), b.cam_from_rig[j].Matrix3x4());
  for (size_t k = 0; k < a.points_in_world.size(); ++k) EXPECT_EQ(a.points_in_world[k], b.points_in_world[k]);
}

}  // namespace
}  // namespace rovo
