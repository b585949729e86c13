#include "datasets/continuous_trajectory.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rovo {

namespace {

constexpr int kMaxRotationIterations = 200;
constexpr double kRotationTolerance = 1e-15;  // rad, largest knot residual

// Cumulative cubic basis lambda_1..3 and its first and second derivatives in u.
struct CumulativeBasis {
  double value[3], first[3], second[3];
};

CumulativeBasis BasisAt(double u) {
  const double u2 = u * u, u3 = u2 * u;
  CumulativeBasis b;
  b.value[0] = (5.0 + 3.0 * u - 3.0 * u2 + u3) / 6.0;
  b.value[1] = (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) / 6.0;
  b.value[2] = u3 / 6.0;
  b.first[0] = (3.0 - 6.0 * u + 3.0 * u2) / 6.0;
  b.first[1] = (3.0 + 6.0 * u - 6.0 * u2) / 6.0;
  b.first[2] = 3.0 * u2 / 6.0;
  b.second[0] = (-6.0 + 6.0 * u) / 6.0;
  b.second[1] = (6.0 - 12.0 * u) / 6.0;
  b.second[2] = u;
  return b;
}

// Solves x_k-1 + 4 x_k + x_k+1 = rhs_k for k = 1 .. m-2 with x_0 and x_m-1 given (Thomas algorithm).
// `x` holds the boundary values on entry and the solution on return.
void SolveInterior(const std::vector<Eigen::Vector3d>& rhs, std::vector<Eigen::Vector3d>* x) {
  const size_t m = x->size();
  if (m < 3) return;
  std::vector<double> c(m, 0.0);
  std::vector<Eigen::Vector3d> d(m, Eigen::Vector3d::Zero());
  // Row k (1..m-2): 1 x_k-1 + 4 x_k + 1 x_k+1; the known x_0 and x_m-1 move to the right-hand side.
  for (size_t k = 1; k + 1 < m; ++k) {
    Eigen::Vector3d r = rhs[k];
    if (k == 1) r -= (*x)[0];
    if (k + 2 == m) r -= (*x)[m - 1];
    const double denominator = 4.0 - (k > 1 ? c[k - 1] : 0.0);
    c[k] = 1.0 / denominator;
    d[k] = (r - (k > 1 ? d[k - 1] : Eigen::Vector3d::Zero())) / denominator;
  }
  (*x)[m - 2] = d[m - 2];
  for (size_t k = m - 2; k-- > 1;) (*x)[k] = d[k] - c[k] * (*x)[k + 1];
}

void CheckUniform(const Trajectory& frames, double dt) {
  for (size_t i = 1; i < frames.size(); ++i) {
    const double step = frames[i].timestamp - frames[i - 1].timestamp;
    if (!(std::abs(step - dt) <= 1e-6 * dt))
      throw std::invalid_argument("continuous trajectory: frame " + std::to_string(i) + " is " + std::to_string(step) +
                                  " s after frame " + std::to_string(i - 1) + "; the times must be uniformly spaced (" +
                                  std::to_string(dt) + " s)");
    const double turn = RotationDistanceDeg(frames[i - 1].world_from_rig.rotation, frames[i].world_from_rig.rotation);
    if (!(turn < 179.0))
      throw std::invalid_argument("continuous trajectory: the rig turns " + std::to_string(turn) + " deg from frame " +
                                  std::to_string(i - 1) + " to frame " + std::to_string(i) +
                                  "; turns between neighbouring frames must stay below 179 deg");
  }
}

}  // namespace

Eigen::Quaterniond QuaternionExp(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  const double half = 0.5 * angle;
  // sin(half) / angle with its series below 1e-4 rad.
  const double k = angle < 1e-4 ? 0.5 - angle * angle / 48.0 : std::sin(half) / angle;
  return Eigen::Quaterniond(std::cos(half), k * v.x(), k * v.y(), k * v.z());
}

Eigen::Vector3d QuaternionLog(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in;
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double s = q.vec().norm();
  // angle = 2 atan2(s, w); rotation vector = angle / s * vec, with its series for small s.
  const double k = s < 1e-8 ? 2.0 / q.w() * (1.0 - s * s / (3.0 * q.w() * q.w())) : 2.0 * std::atan2(s, q.w()) / s;
  return k * q.vec();
}

ContinuousTrajectory::ContinuousTrajectory(const Trajectory& frames) : frames_(frames) {
  if (frames_.empty()) throw std::invalid_argument("continuous trajectory: no poses");
  const size_t n = frames_.size();
  t0_ = frames_.front().timestamp;
  dt_ = n > 1 ? (frames_.back().timestamp - t0_) / static_cast<double>(n - 1) : 1.0;
  if (n > 1 && !(dt_ > 0.0)) throw std::invalid_argument("continuous trajectory: times do not increase");
  CheckUniform(frames_, dt_);

  // Positions: c_0 = p_0, c_n-1 = p_n-1, the interior from the tridiagonal system, natural ends.
  std::vector<Eigen::Vector3d> c(n), rhs(n);
  for (size_t i = 0; i < n; ++i) {
    c[i] = frames_[i].world_from_rig.translation;
    rhs[i] = 6.0 * c[i];
  }
  SolveInterior(rhs, &c);
  positions_.resize(n + 2);
  for (size_t i = 0; i < n; ++i) positions_[i + 1] = c[i];
  positions_[0] = n > 1 ? Eigen::Vector3d(2.0 * c[0] - c[1]) : c[0];
  positions_[n + 1] = n > 1 ? Eigen::Vector3d(2.0 * c[n - 1] - c[n - 2]) : c[n - 1];

  // Rotations: start at the frame rotations and correct the interior controls.
  std::vector<Eigen::Quaterniond> q(n);
  for (size_t i = 0; i < n; ++i) q[i] = frames_[i].world_from_rig.rotation.normalized();
  auto end_controls = [&] {
    rotations_.assign(n + 2, Eigen::Quaterniond::Identity());
    for (size_t i = 0; i < n; ++i) rotations_[i + 1] = q[i];
    if (n == 1) {
      rotations_[0] = rotations_[2] = q[0];
      return;
    }
    // d_0 = d_1: Q_-1 = Q_0 Exp(-Log(Q_0^-1 Q_1)); likewise after the last.
    rotations_[0] = (q[0] * QuaternionExp(-QuaternionLog(q[0].conjugate() * q[1]))).normalized();
    rotations_[n + 1] = (q[n - 1] * QuaternionExp(QuaternionLog(q[n - 2].conjugate() * q[n - 1]))).normalized();
  };
  for (int iteration = 0; iteration < kMaxRotationIterations && n > 2; ++iteration) {
    end_controls();
    // Residual at each interior knot, in the control's tangent space (r_i = Log(S_i^-1 R_i)).
    std::vector<Eigen::Vector3d> residual(n, Eigen::Vector3d::Zero()), delta(n, Eigen::Vector3d::Zero());
    double worst = 0.0;
    for (size_t i = 1; i + 1 < n; ++i) {
      const Eigen::Quaterniond &qm = rotations_[i], &qi = rotations_[i + 1], &qp = rotations_[i + 2];
      const Eigen::Quaterniond at_knot = qm * QuaternionExp(5.0 / 6.0 * QuaternionLog(qm.conjugate() * qi)) *
                                         QuaternionExp(1.0 / 6.0 * QuaternionLog(qi.conjugate() * qp));
      residual[i] = 6.0 * QuaternionLog(at_knot.conjugate() * frames_[i].world_from_rig.rotation);
      worst = std::max(worst, residual[i].norm() / 6.0);
    }
    if (worst < kRotationTolerance) break;
    SolveInterior(residual, &delta);
    for (size_t i = 1; i + 1 < n; ++i) q[i] = (q[i] * QuaternionExp(delta[i])).normalized();
  }
  end_controls();
}

int ContinuousTrajectory::ExactFrame(double t) const {
  const auto it = std::lower_bound(frames_.begin(), frames_.end(), t,
                                   [](const StampedPose& p, double time) { return p.timestamp < time; });
  if (it != frames_.end() && it->timestamp == t) return static_cast<int>(it - frames_.begin());
  return -1;
}

int ContinuousTrajectory::SegmentOf(double t, double* u) const {
  const int n = static_cast<int>(frames_.size());
  if (n == 1) {
    *u = 0.0;
    return 0;
  }
  const double x = (t - t0_) / dt_;
  const int segment = std::clamp(static_cast<int>(std::floor(x)), 0, n - 2);
  *u = x - segment;
  return segment;
}

Rigid3 ContinuousTrajectory::Pose(double t) const {
  const int frame = ExactFrame(t);
  if (frame >= 0) return frames_[frame].world_from_rig;
  return State(t).world_from_rig;
}

RigMotionState ContinuousTrajectory::State(double t) const {
  double u = 0.0;
  const int i = SegmentOf(t, &u);
  RigMotionState s;
  if (frames_.size() == 1) {
    s.world_from_rig = frames_[0].world_from_rig;
    return s;
  }
  const CumulativeBasis b = BasisAt(u);
  const double inv_dt = 1.0 / dt_, inv_dt2 = inv_dt * inv_dt;
  // Controls i-1 .. i+2 are rotations_/positions_[i .. i+3].
  Eigen::Quaterniond rotation = rotations_[i];
  Eigen::Vector3d position = positions_[i];
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d d = QuaternionLog(rotations_[i + j].conjugate() * rotations_[i + j + 1]);
    const Eigen::Quaterniond a = QuaternionExp(b.value[j] * d);
    const Eigen::Matrix3d a_transpose = a.toRotationMatrix().transpose();
    const Eigen::Vector3d rate = b.first[j] * inv_dt * d;
    const Eigen::Vector3d carried = a_transpose * s.angular_velocity;
    s.angular_acceleration = a_transpose * s.angular_acceleration + b.second[j] * inv_dt2 * d + carried.cross(rate);
    s.angular_velocity = carried + rate;
    rotation = rotation * a;
    const Eigen::Vector3d step = positions_[i + j + 1] - positions_[i + j];
    position += b.value[j] * step;
    s.linear_velocity += b.first[j] * inv_dt * step;
    s.linear_acceleration += b.second[j] * inv_dt2 * step;
  }
  s.world_from_rig = Rigid3(rotation.normalized(), position);
  const int frame = ExactFrame(t);
  if (frame >= 0) s.world_from_rig = frames_[frame].world_from_rig;
  return s;
}

}  // namespace rovo
