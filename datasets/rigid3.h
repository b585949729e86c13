#pragma once
// Rigid transforms named by frames.
//
// Convention (stated once, used everywhere): a transform called `b_from_a` maps coordinates of a
// point in frame a to frame b,
//     x_in_b = b_from_a * x_in_a = R * x_in_a + t,
// and composes right to left: c_from_a = c_from_b * b_from_a.
// Quaternions are Eigen's (stored x, y, z, w in memory; constructed w, x, y, z). Serialized forms
// always state their order (TUM files: qx qy qz qw).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace rovo {

struct Rigid3 {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q.normalized()), translation(t) {}
  Rigid3(const Eigen::Matrix3d& rotation_matrix, const Eigen::Vector3d& t)
      : rotation(Eigen::Quaterniond(rotation_matrix).normalized()), translation(t) {}

  static Rigid3 Identity() { return Rigid3(); }

  // From an axis-angle (rotation) vector in radians, as in the paper's theta = (r, t).
  static Rigid3 FromAxisAngle(const Eigen::Vector3d& rotation_vector, const Eigen::Vector3d& t) {
    const double angle = rotation_vector.norm();
    if (angle < 1e-15) return Rigid3(Eigen::Quaterniond::Identity(), t);
    return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector / angle)), t);
  }

  Eigen::Vector3d AxisAngle() const {
    Eigen::AngleAxisd aa(rotation);
    return aa.axis() * aa.angle();
  }

  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }

  // 3x4 [R | t].
  Eigen::Matrix<double, 3, 4> Matrix3x4() const {
    Eigen::Matrix<double, 3, 4> m;
    m.leftCols<3>() = RotationMatrix();
    m.col(3) = translation;
    return m;
  }
  Eigen::Matrix4d Matrix4() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topRows<3>() = Matrix3x4();
    return m;
  }

  Rigid3 Inverse() const {
    const Eigen::Quaterniond q_inv = rotation.conjugate();
    return Rigid3(q_inv, -(q_inv * translation));
  }

  Eigen::Vector3d operator*(const Eigen::Vector3d& x_in_a) const { return rotation * x_in_a + translation; }

  // c_from_a = c_from_b * b_from_a.
  Rigid3 operator*(const Rigid3& b_from_a) const {
    return Rigid3(rotation * b_from_a.rotation, rotation * b_from_a.translation + translation);
  }

  // Camera/rig centre of frame a expressed in frame b (the translation of b_from_a's inverse is the
  // position of b's origin in a; this is the position of a's origin in b).
  const Eigen::Vector3d& OriginOfAInB() const { return translation; }
};

// Angle of a rotation in degrees, in [0, 180].
inline double RotationAngleDeg(const Eigen::Quaterniond& q) {
  const Eigen::Quaterniond n = q.normalized();
  const double v = n.vec().norm();
  return 2.0 * std::atan2(v, std::abs(n.w())) * 180.0 / M_PI;
}

// Angle between two rotations in degrees.
inline double RotationDistanceDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return RotationAngleDeg(a.conjugate() * b);
}

// Geodesic interpolation between two transforms: slerp on rotation, linear on translation.
// alpha = 0 gives a, alpha = 1 gives b.
inline Rigid3 Interpolate(const Rigid3& a, const Rigid3& b, double alpha) {
  return Rigid3(a.rotation.slerp(alpha, b.rotation), (1.0 - alpha) * a.translation + alpha * b.translation);
}

// Rotation from roll/pitch/yaw in degrees, applied as R = Rz(yaw) * Ry(pitch) * Rx(roll) (ZYX
// intrinsic, the aerospace/ROS convention).
inline Eigen::Quaterniond QuaternionFromRollPitchYawDeg(double roll_deg, double pitch_deg, double yaw_deg) {
  const double d2r = M_PI / 180.0;
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw_deg * d2r, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(pitch_deg * d2r, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll_deg * d2r, Eigen::Vector3d::UnitX()));
}

// Inverse of QuaternionFromRollPitchYawDeg: (roll, pitch, yaw) in degrees, pitch in [-90, 90].
inline Eigen::Vector3d RollPitchYawDegFromQuaternion(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d m = q.normalized().toRotationMatrix();
  const double r2d = 180.0 / M_PI;
  const double pitch = std::asin(std::clamp(-m(2, 0), -1.0, 1.0));
  const double roll = std::atan2(m(2, 1), m(2, 2));
  const double yaw = std::atan2(m(1, 0), m(0, 0));
  return Eigen::Vector3d(roll * r2d, pitch * r2d, yaw * r2d);
}

// Angle between two directions, robust for all angles: atan2(|a x b|, a . b), in radians.
inline double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace rovo
