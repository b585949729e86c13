#pragma once
// The continuous-time ground truth of a dataset: world_from_rig(t) at any time, C2-smooth, through
// every pose of groundtruth.tum at its time; with the rig's angular velocity and acceleration and
// its linear velocity and acceleration. Frames, motion blur, rolling-shutter rows, trigger offsets
// (render/timing.h) and the IMU (datasets/imu_model.h) are all sampled from it.
//
// The curve (Sommer, Usenko, Schubert, Demmel, Cremers, "Efficient Derivative Computation for
// Cumulative B-Splines on Lie Groups", CVPR 2020; Kim, Kim, Shin, SIGGRAPH 1995) is a uniform
// cumulative cubic B-spline on SO(3) x R^3, knots at the n frame times t_i = t_0 + i dt.
// Segment i (t_i <= t < t_i+1, u = (t - t_i) / dt in [0, 1)) is blended from the control poses
// i-1 .. i+2 (control poses -1 .. n, n + 2 of them):
//   lambda_1(u) = (5 + 3u - 3u^2 + u^3) / 6,  lambda_2(u) = (1 + 3u + 3u^2 - 2u^3) / 6,
//   lambda_3(u) = u^3 / 6   (the cumulative cubic basis),
//   R(t) = Q_i-1 Exp(lambda_1 d_1) Exp(lambda_2 d_2) Exp(lambda_3 d_3),  d_j = Log(Q_i+j-2^-1 Q_i+j-1),
//   p(t) = c_i-1 + sum_j lambda_j (c_i+j-1 - c_i+j-2).
// Both are C2 in t (the basis is; each d_j is constant on the segment). Derivatives in closed
// form: with A_j = Exp(lambda_j d_j), omega_0 = alpha_0 = 0,
//   omega_j = A_j^T omega_j-1 + lambda_j' d_j,
//   alpha_j = A_j^T alpha_j-1 + lambda_j'' d_j + (A_j^T omega_j-1) x (lambda_j' d_j),
// omega_3 and alpha_3 are the rig's angular velocity and its time derivative in the rig frame
// (R^T dR/dt = [omega]x); velocity and acceleration sum lambda_j' and lambda_j'' over the position
// differences, in the world frame.
//
// Interpolation. At a knot (u = 0) the basis is (5/6, 1/6, 0), so the curve passes through the
// frame poses when c_i-1 + 4 c_i + c_i+1 = 6 p_i (a tridiagonal system, solved exactly) and
// Q_i-1 Exp(5/6 d_i) Exp(1/6 d_i+1) = R_i (solved by Newton-like iterations: the residual
// Log(S_i^-1 R_i) is pushed through the same tridiagonal system until it is below 1e-15 rad).
// The ends are natural: c_-1 - 2 c_0 + c_1 = 0, d_0 = d_1 (and likewise at n - 1), which makes
// c_0 = p_0 and Q_0 = R_0 exactly. Before t_0 and after t_n-1 the first and last segments' polynomials
// continue (u < 0 or u > 1). At a frame time exactly, the pose is the frame's pose bit for bit (the
// curve agrees with it to ~1e-15), so renders that sample only frame times are unchanged.
//
// Requirements (checked, std::invalid_argument): times uniformly spaced (every interval within
// 1e-6 dt of dt), and each frame-to-frame turn below 180 deg (the spline takes the shorter way);
// a single pose gives a constant curve.

#include <Eigen/Core>
#include <vector>

#include "datasets/rigid3.h"
#include "datasets/trajectory.h"

namespace rovo {

// The rig's motion at one time.
struct RigMotionState {
  Rigid3 world_from_rig;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();      // rad/s, rig frame
  Eigen::Vector3d angular_acceleration = Eigen::Vector3d::Zero();  // rad/s^2, rig frame
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();       // m/s, of the rig origin, world frame
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();   // m/s^2, of the rig origin, world frame
};

class ContinuousTrajectory {
 public:
  // Throws std::invalid_argument for an empty trajectory, non-uniform times or a turn >= 180 deg
  // between neighbouring frames.
  explicit ContinuousTrajectory(const Trajectory& frames);

  // Pose only (the frame's own pose at a frame time).
  Rigid3 Pose(double t) const;
  // Pose and derivatives.
  RigMotionState State(double t) const;

  double start_time() const { return t0_; }
  double end_time() const { return t0_ + dt_ * (static_cast<double>(frames_.size()) - 1.0); }
  const Trajectory& frames() const { return frames_; }

  // Control poses (n + 2: index 0 is control -1), for tests.
  const std::vector<Eigen::Quaterniond>& control_rotations() const { return rotations_; }
  const std::vector<Eigen::Vector3d>& control_positions() const { return positions_; }

 private:
  int SegmentOf(double t, double* u) const;
  int ExactFrame(double t) const;  // frame whose time is exactly t, or -1

  Trajectory frames_;
  double t0_ = 0.0;
  double dt_ = 1.0;
  std::vector<Eigen::Quaterniond> rotations_;
  std::vector<Eigen::Vector3d> positions_;
};

// SO(3) exponential and logarithm on quaternions (Log returns the rotation vector of angle <= pi).
Eigen::Quaterniond QuaternionExp(const Eigen::Vector3d& rotation_vector);
Eigen::Vector3d QuaternionLog(const Eigen::Quaterniond& q);

}  // namespace rovo
