#pragma once
// Synthetic rig, world points, correspondences and front-end output for the back-end tests (no
// rendering).

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

#include "datasets/rigid3.h"
#include "vo/backend.h"
#include "vo/frontend.h"
#include "vo/ransac.h"

namespace rovo::test {

// cam_from_rig of camera j of a four-camera rig on a square of half-size `half` metres, camera j
// looking along rig yaw j * 90 deg (front, left, back, right), OpenCV camera axes.
// The back-end settings these synthetic tests were written for: a 0.01 rad RANSAC threshold, BA in
// line, no random-walk prior on the extrinsics.
inline BackendOptions SyntheticBackendOptions() {
  BackendOptions options;
  options.ransac.tau_rad = 0.01;
  options.ba.extrinsic_prior_deg = 0.0;
  options.async_ba = false;
  return options;
}

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

// A static point field and a rig trajectory for whole-sequence back-end tests.
struct World {
  std::vector<Eigen::Vector3d> points;
  std::vector<Rigid3> world_from_rig;  // per frame
  std::vector<Rigid3> cam_from_rig;
};

// A rig driving ~1 m per frame along a gentle S-curve through a corridor of points 4-15 m to the
// sides (20 per metre), plus `far_per_metre` points per metre 15-80 m to the sides, up to 30 m high.
inline World MakeWorld(int frames, uint64_t seed, int far_per_metre = 0) {
  World w;
  w.cam_from_rig = SquareRigExtrinsics();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> along(-20.0, frames + 20.0), side(4.0, 15.0), height(-1.5, 8.0),
      sign(-1.0, 1.0);
  for (int k = 0; k < 20 * (frames + 40); ++k) {
    const double x = along(rng);
    w.points.emplace_back(x, (sign(rng) < 0 ? -1 : 1) * side(rng) + 3.0 * std::sin(0.05 * x), height(rng));
  }
  std::uniform_real_distribution<double> far_side(15.0, 80.0), far_height(-1.5, 30.0);
  for (int k = 0; k < far_per_metre * (frames + 40); ++k) {
    const double x = along(rng);
    w.points.emplace_back(x, (sign(rng) < 0 ? -1 : 1) * far_side(rng), far_height(rng));
  }
  for (int f = 0; f < frames; ++f) {
    const double x = 1.0 * f;
    const double yaw = std::atan(0.15 * std::cos(0.05 * x));
    w.world_from_rig.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())),
                                  Eigen::Vector3d(x, 3.0 * std::sin(0.05 * x), 1.5));
  }
  return w;
}

// Front-end output at `frame`: bearings of the points within `max_range_m` of the rig in every
// camera that sees them, track id = point index + 1, Gaussian angular noise, and a fraction of
// outliers (bearings off by ~3 deg).
inline FrontendFrame Observe(const World& w, int frame, std::mt19937_64& rng, double noise_rad, double outlier_ratio,
                             double max_range_m = 25.0) {
  FrontendFrame out;
  out.features_per_camera.resize(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Rigid3 rig_from_world = w.world_from_rig[frame].Inverse();
  for (size_t k = 0; k < w.points.size(); ++k) {
    const Eigen::Vector3d in_rig = rig_from_world * w.points[k];
    if (in_rig.norm() > max_range_m) continue;
    for (int j = 0; j < 4; ++j) {
      const Eigen::Vector3d in_cam = w.cam_from_rig[j] * in_rig;
      if (!InFov220(in_cam)) continue;
      Feature f;
      f.track_id = k + 1;
      f.camera = j;
      f.warped_px = Eigen::Vector2f::Zero();
      f.bearing_in_cam = NoisyBearing(rng, in_cam.normalized(), noise_rad);
      if (u(rng) < outlier_ratio) f.bearing_in_cam = NoisyBearing(rng, f.bearing_in_cam, 0.05);
      out.features_per_camera[j].push_back(f);
    }
  }
  return out;
}

}  // namespace rovo::test
