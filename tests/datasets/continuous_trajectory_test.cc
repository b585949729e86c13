#include "datasets/continuous_trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace rovo {
namespace {

// A driving-like motion sampled at `rate`: a weaving path with yaw turning `total_yaw_deg` over
// the whole, plus pitch and roll wobble.
Trajectory Drive(int n, double rate, double total_yaw_deg, double t0 = 12.3) {
  Trajectory traj;
  for (int i = 0; i < n; ++i) {
    const double t = t0 + i / rate;
    const double s = static_cast<double>(i) / (n - 1);
    const Eigen::Quaterniond q =
        QuaternionFromRollPitchYawDeg(3.0 * std::sin(7.0 * s), 2.0 * std::cos(5.0 * s), total_yaw_deg * s * s);
    const Eigen::Vector3d p(10.0 * s + std::sin(3.0 * s), 4.0 * s * s, 0.3 * std::sin(9.0 * s));
    traj.push_back({t, Rigid3(q, p)});
  }
  return traj;
}

double RotationErrorRad(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return QuaternionLog(a.conjugate() * b).norm();
}

TEST(ContinuousTrajectory, ExpLogRoundTrip) {
  for (const Eigen::Vector3d& v : {Eigen::Vector3d(1e-12, 0, 0), Eigen::Vector3d(0.3, -0.2, 0.1),
                                   Eigen::Vector3d(0, 3.1, 0), Eigen::Vector3d(1e-6, -2e-6, 3e-6)}) {
    EXPECT_LT((QuaternionLog(QuaternionExp(v)) - v).norm(), 1e-14 * (1.0 + v.norm())) << v.transpose();
  }
}

TEST(ContinuousTrajectory, PassesThroughEveryFrame) {
  const Trajectory traj = Drive(40, 10.0, 270.0);
  const ContinuousTrajectory curve(traj);
  for (size_t i = 0; i < traj.size(); ++i) {
    // At the frame time the pose is the frame's own, bit for bit.
    const Rigid3 exact = curve.Pose(traj[i].timestamp);
    EXPECT_EQ(exact.translation, traj[i].world_from_rig.translation);
    EXPECT_EQ(exact.rotation.coeffs(), traj[i].world_from_rig.rotation.coeffs());
    // The spline itself agrees to ~1e-12 there (evaluated a hair away from the knot).
    const RigMotionState s = curve.State(traj[i].timestamp + 1e-13);
    EXPECT_LT((s.world_from_rig.translation - traj[i].world_from_rig.translation).norm(), 1e-11) << i;
    EXPECT_LT(RotationErrorRad(s.world_from_rig.rotation, traj[i].world_from_rig.rotation), 1e-11) << i;
  }
}

TEST(ContinuousTrajectory, TurnsBeyondHalfARevolution) {
  // 720 deg of yaw over 30 frames (up to ~50 deg per frame), quaternion signs flipping along the way.
  const Trajectory traj = Drive(30, 20.0, 720.0);
  const ContinuousTrajectory curve(traj);
  for (size_t i = 0; i + 1 < traj.size(); ++i) {
    const double tm = 0.5 * (traj[i].timestamp + traj[i + 1].timestamp);
    const RigMotionState s = curve.State(tm);
    // Between neighbours the curve stays between them: at most the frame-to-frame turn away.
    const double step = RotationErrorRad(traj[i].world_from_rig.rotation, traj[i + 1].world_from_rig.rotation);
    EXPECT_LT(RotationErrorRad(s.world_from_rig.rotation, traj[i].world_from_rig.rotation), step) << i;
    EXPECT_LT(RotationErrorRad(curve.State(traj[i + 1].timestamp + 1e-13).world_from_rig.rotation,
                               traj[i + 1].world_from_rig.rotation),
              1e-11)
        << i;
  }
  // The yaw rate integrates to the whole turn: mean yaw rate near 720 deg / 1.45 s.
  double yaw = 0.0;
  const double h = 1e-3;
  for (double t = curve.start_time(); t < curve.end_time() - 0.5 * h; t += h) {
    const RigMotionState s = curve.State(t + 0.5 * h);
    yaw += (s.world_from_rig.RotationMatrix() * s.angular_velocity).z() * h;
  }
  EXPECT_NEAR(yaw * 180.0 / M_PI, 720.0, 5.0);
}

TEST(ContinuousTrajectory, DerivativesMatchFiniteDifferences) {
  const Trajectory traj = Drive(25, 10.0, 200.0);
  const ContinuousTrajectory curve(traj);
  const double h = 1e-5;
  for (double t = curve.start_time() + 0.013; t < curve.end_time(); t += 0.0937) {
    const RigMotionState s = curve.State(t), before = curve.State(t - h), after = curve.State(t + h);
    // Velocity and acceleration of the position.
    const Eigen::Vector3d v_fd = (after.world_from_rig.translation - before.world_from_rig.translation) / (2 * h);
    EXPECT_LT((v_fd - s.linear_velocity).norm(), 1e-7 * (1.0 + s.linear_velocity.norm())) << t;
    const Eigen::Vector3d a_fd = (after.linear_velocity - before.linear_velocity) / (2 * h);
    EXPECT_LT((a_fd - s.linear_acceleration).norm(), 1e-6 * (1.0 + s.linear_acceleration.norm())) << t;
    // Angular velocity in the rig frame: R^T dR/dt.
    const Eigen::Vector3d w_fd =
        QuaternionLog(before.world_from_rig.rotation.conjugate() * after.world_from_rig.rotation) / (2 * h);
    EXPECT_LT((w_fd - s.angular_velocity).norm(), 1e-6 * (1.0 + s.angular_velocity.norm())) << t;
    const Eigen::Vector3d alpha_fd = (after.angular_velocity - before.angular_velocity) / (2 * h);
    EXPECT_LT((alpha_fd - s.angular_acceleration).norm(), 1e-5 * (1.0 + s.angular_acceleration.norm())) << t;
  }
}

TEST(ContinuousTrajectory, SecondDerivativesAreContinuousAcrossKnots) {
  const Trajectory traj = Drive(20, 10.0, 300.0);
  const ContinuousTrajectory curve(traj);
  const double e = 1e-9;
  double largest_jump_seen = 0.0;
  for (size_t i = 1; i + 1 < traj.size(); ++i) {
    const double t = traj[i].timestamp;
    const RigMotionState left = curve.State(t - e), right = curve.State(t + e);
    EXPECT_LT((left.linear_acceleration - right.linear_acceleration).norm(), 1e-5) << i;
    EXPECT_LT((left.angular_acceleration - right.angular_acceleration).norm(), 1e-5) << i;
    EXPECT_LT((left.linear_velocity - right.linear_velocity).norm(), 1e-6) << i;
    EXPECT_LT((left.angular_velocity - right.angular_velocity).norm(), 1e-6) << i;
    // The third derivative does jump (a cubic spline): the check above is not vacuous.
    const RigMotionState far_left = curve.State(t - 1e-3), far_right = curve.State(t + 1e-3);
    largest_jump_seen = std::max(largest_jump_seen, ((far_right.linear_acceleration - right.linear_acceleration) -
                                                     (left.linear_acceleration - far_left.linear_acceleration))
                                                        .norm());
  }
  EXPECT_GT(largest_jump_seen, 1e-4);
}

TEST(ContinuousTrajectory, StraightLineAtConstantSpeedIsExact) {
  Trajectory traj;
  const Eigen::Quaterniond q = QuaternionFromRollPitchYawDeg(0, 0, 30);
  for (int i = 0; i < 10; ++i) traj.push_back({0.1 * i, Rigid3(q, Eigen::Vector3d(2.0 * 0.1 * i, 1.0, 0.0))});
  const ContinuousTrajectory curve(traj);
  const RigMotionState s = curve.State(0.437);
  EXPECT_NEAR(s.world_from_rig.translation.x(), 0.874, 1e-12);
  EXPECT_LT((s.linear_velocity - Eigen::Vector3d(2.0, 0.0, 0.0)).norm(), 1e-12);
  EXPECT_LT(s.linear_acceleration.norm(), 1e-10);
  EXPECT_LT(s.angular_velocity.norm(), 1e-12);
}

TEST(ContinuousTrajectory, RejectsWhatItCannotRepresent) {
  EXPECT_THROW(ContinuousTrajectory(Trajectory{}), std::invalid_argument);
  Trajectory uneven = Drive(5, 10.0, 10.0);
  uneven[2].timestamp += 0.01;
  EXPECT_THROW(ContinuousTrajectory{uneven}, std::invalid_argument);
  Trajectory spin = Drive(3, 10.0, 0.0);
  spin[1].world_from_rig.rotation = QuaternionFromRollPitchYawDeg(0, 0, 179.5);
  EXPECT_THROW(ContinuousTrajectory{spin}, std::invalid_argument);
  // One pose: constant.
  const ContinuousTrajectory still(Trajectory{{1.0, Rigid3(QuaternionFromRollPitchYawDeg(1, 2, 3), {1, 2, 3})}});
  EXPECT_EQ(still.State(5.0).world_from_rig.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(still.State(5.0).linear_velocity, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace rovo
