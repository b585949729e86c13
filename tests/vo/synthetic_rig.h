#pragma once
// Synthetic rig, world points and correspondences for the back-end tests (no rendering).

#include "datasets/rigid3.h"
#include "vo/ransac.h"

#include <Eigen/Core>

#include <cmath>
#include <random>
#include <vector>

namespace rovo::test {

// cam_from_rig of camera j of a four-camera rig on a square of half-size `half` metres, camera j
// looking along rig yaw j * 90 deg (front, left, back, right), OpenCV camera axes.
inline std::vector<Rigid3> SquareRigExtrinsics(double half = 0.4) {
  std::vector<Rigid3> out;
  for (int j = 0; j < 4; ++j) {
    const double yaw = j * M_PI / 2.0;
    const Eigen::Matrix3d yaw_rot = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Eigen::Matrix3d rig_from_cam_rot;
    // Columns: camera x (right) = -y_rig, camera y (down) = -z_rig, camera z (forward) = +x_rig; then yaw.
    rig_from_cam_rot << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    rig_from_cam_rot = yaw_rot * rig_from_cam_rot;
    const Eigen::Vector3d centre_in_rig = yaw_rot * Eigen::Vector3d(half, 0.0, 0.1 * j);
    const Rigid3 rig_from_cam(rig_from_cam_rot, centre_in_rig);
    out.push_back(rig_from_cam.Inverse());
  }
  return out;
}

// Random point around the origin at a distance in [near, far], with height in [-2, 6].
inline Eigen::Vector3d RandomPoint(std::mt19937_64& rng, double near = 3.0, double far = 30.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> d(near, far);
  std::uniform_real_distribution<double> h(-2.0, 6.0);
  Eigen::Vector3d dir(u(rng), u(rng), 0.0);
  if (dir.norm() < 1e-3) dir = Eigen::Vector3d::UnitX();
  dir.normalize();
  return dir * d(rng) + Eigen::Vector3d(0, 0, h(rng));
}

// Unit bearing of `point_in_cam` if within the 220 deg cone around +z.
inline bool InFov220(const Eigen::Vector3d& point_in_cam) {
  return AngleBetween(point_in_cam, Eigen::Vector3d::UnitZ()) < 110.0 * M_PI / 180.0;
}

// Random small rotation of about `deg` degrees about a random axis.
inline Eigen::Quaterniond RandomRotation(std::mt19937_64& rng, double deg) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector3d axis(n(rng), n(rng), n(rng));
  axis.normalize();
  return Eigen::Quaterniond(Eigen::AngleAxisd(deg * M_PI / 180.0, axis));
}

// Bearing perturbed by Gaussian angular noise of `sigma_rad` per tangent axis.
inline Eigen::Vector3d NoisyBearing(std::mt19937_64& rng, const Eigen::Vector3d& bearing, double sigma_rad) {
  if (sigma_rad <= 0.0) return bearing;
  std::normal_distribution<double> n(0.0, sigma_rad);
  const Eigen::Vector3d e1 = bearing.unitOrthogonal();
  const Eigen::Vector3d e2 = bearing.cross(e1);
  return (bearing + n(rng) * e1 + n(rng) * e2).normalized();
}

}  // namespace rovo::test
