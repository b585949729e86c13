#include "datasets/rigid3.h"

#include <gtest/gtest.h>

#include <random>

namespace rovo {
namespace {

Rigid3 RandomRigid3(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d rotation_vector(u(rng) * 2.0, u(rng) * 2.0, u(rng) * 2.0);
  return Rigid3::FromAxisAngle(rotation_vector, Eigen::Vector3d(u(rng) * 5, u(rng) * 5, u(rng) * 5));
}

TEST(Rigid3, ComposeMatchesMatrices) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 50; ++i) {
    const Rigid3 b_from_a = RandomRigid3(rng);
    const Rigid3 c_from_b = RandomRigid3(rng);
    const Rigid3 c_from_a = c_from_b * b_from_a;
    EXPECT_TRUE(c_from_a.Matrix4().isApprox(c_from_b.Matrix4() * b_from_a.Matrix4(), 1e-12));
    const Eigen::Vector3d x_in_a(0.3, -2.0, 1.5);
    EXPECT_TRUE((c_from_a * x_in_a).isApprox(c_from_b * (b_from_a * x_in_a), 1e-12));
  }
}

TEST(Rigid3, InverseUndoes) {
  std::mt19937_64 rng(2);
  for (int i = 0; i < 50; ++i) {
    const Rigid3 b_from_a = RandomRigid3(rng);
    const Rigid3 identity = b_from_a.Inverse() * b_from_a;
    EXPECT_LT(RotationAngleDeg(identity.rotation), 1e-9);
    EXPECT_LT(identity.translation.norm(), 1e-12);
    EXPECT_TRUE(b_from_a.Inverse().Matrix4().isApprox(b_from_a.Matrix4().inverse(), 1e-12));
  }
}

TEST(Rigid3, AxisAngleRoundTrip) {
  const Eigen::Vector3d rotation_vector(0.3, -0.4, 1.2);
  const Rigid3 b_from_a = Rigid3::FromAxisAngle(rotation_vector, Eigen::Vector3d::Zero());
  EXPECT_TRUE(b_from_a.AxisAngle().isApprox(rotation_vector, 1e-12));
  EXPECT_NEAR(RotationAngleDeg(b_from_a.rotation), rotation_vector.norm() * 180.0 / M_PI, 1e-10);
  // Zero vector gives the identity.
  EXPECT_LT(RotationAngleDeg(Rigid3::FromAxisAngle(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).rotation), 1e-12);
  // 90 degrees about z maps x to y.
  const Rigid3 rz = Rigid3::FromAxisAngle(Eigen::Vector3d(0, 0, M_PI / 2), Eigen::Vector3d::Zero());
  EXPECT_TRUE((rz * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
}

TEST(Rigid3, QuaternionConstructionNormalises) {
  const Rigid3 b_from_a(Eigen::Quaterniond(2.0, 0.0, 0.0, 0.0), Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(b_from_a.rotation.norm(), 1.0, 1e-15);
  EXPECT_TRUE((b_from_a * Eigen::Vector3d(1, 1, 1)).isApprox(Eigen::Vector3d(2, 3, 4), 1e-15));
}

TEST(Rigid3, RollPitchYawConventionAndRoundTrip) {
  // Yaw +90 (about z, REP-103 up) turns forward (x) into left (y).
  const Eigen::Quaterniond yaw90 = QuaternionFromRollPitchYawDeg(0, 0, 90);
  EXPECT_TRUE((yaw90 * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  // Pitch +90 about y turns forward (x) into down (-z).
  const Eigen::Quaterniond pitch90 = QuaternionFromRollPitchYawDeg(0, 90, 0);
  EXPECT_TRUE((pitch90 * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-179.0, 179.0), pitch(-89.0, 89.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d rpy(angle(rng), pitch(rng), angle(rng));
    const Eigen::Vector3d back = RollPitchYawDegFromQuaternion(QuaternionFromRollPitchYawDeg(rpy[0], rpy[1], rpy[2]));
    EXPECT_TRUE(back.isApprox(rpy, 1e-9)) << rpy.transpose() << " vs " << back.transpose();
  }
}

TEST(Rigid3, InterpolationIsGeodesic) {
  const Rigid3 a(QuaternionFromRollPitchYawDeg(0, 0, 10), Eigen::Vector3d(0, 0, 0));
  const Rigid3 b(QuaternionFromRollPitchYawDeg(0, 0, 50), Eigen::Vector3d(2, 4, -6));
  const Rigid3 mid = Interpolate(a, b, 0.5);
  EXPECT_NEAR(RollPitchYawDegFromQuaternion(mid.rotation)[2], 30.0, 1e-9);
  EXPECT_TRUE(mid.translation.isApprox(Eigen::Vector3d(1, 2, -3), 1e-12));
  EXPECT_LT(RotationDistanceDeg(Interpolate(a, b, 0.0).rotation, a.rotation), 1e-9);
  EXPECT_LT(RotationDistanceDeg(Interpolate(a, b, 1.0).rotation, b.rotation), 1e-9);
  EXPECT_NEAR(RotationDistanceDeg(a.rotation, b.rotation), 40.0, 1e-9);
}

TEST(Rigid3, AngleBetweenIsRobustNearZeroAndPi) {
  const Eigen::Vector3d a(1, 0, 0);
  EXPECT_NEAR(AngleBetween(a, Eigen::Vector3d(1, 1e-9, 0)), 1e-9, 1e-15);  // acos would return 0 here
  EXPECT_NEAR(AngleBetween(a, Eigen::Vector3d(-1, 1e-9, 0)), M_PI - 1e-9, 1e-15);
  EXPECT_NEAR(AngleBetween(a, Eigen::Vector3d(0, 0, -3)), M_PI / 2, 1e-15);
}

TEST(Rigid3, OriginOfAInB) {
  // Camera 1 m left of the rig origin: rig_from_cam has translation (0, 1, 0).
  const Rigid3 rig_from_cam(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 1, 0));
  EXPECT_TRUE(rig_from_cam.OriginOfAInB().isApprox(Eigen::Vector3d(0, 1, 0)));
  EXPECT_TRUE((rig_from_cam * Eigen::Vector3d::Zero()).isApprox(Eigen::Vector3d(0, 1, 0)));
}

}  // namespace
}  // namespace rovo
