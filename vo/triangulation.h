#pragma once
// Triangulation of a point from unit bearings (any direction, also > 90 deg off the optical axis).
//
// A ray is (origin_in_world, direction_in_world) with a unit direction: the camera centre and
// R_world_from_cam * bearing_in_cam. Multi-view: the linear midpoint
//     X0 = argmin_X sum_k |(I - d_k d_k^T)(X - o_k)|^2  =>  [sum_k (I - d_k d_k^T)] X0 = sum_k (I - d_k d_k^T) o_k
// followed by Gauss-Newton on the angular residuals r_k = d_k - (X - o_k) / |X - o_k| (chord of the angle).
// Checks, each failing with nullopt:
//   parallax: the largest angle between two rays' directions must reach min_parallax_deg (depth is
//             ill-conditioned otherwise);
//   cheirality: d_k . (X - o_k) > 0 for every ray (the point lies in front along each bearing);
//   error: every ray's angle to X below max_error_deg; distance: |X - o_k| <= max_distance.

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace rovo {

struct Ray {
  Eigen::Vector3d origin_in_world;
  Eigen::Vector3d direction_in_world;  // unit
};

struct TriangulationOptions {
  double min_parallax_deg = 1.0;
  double max_error_deg = 0.5;
  double max_distance = 1e4;  // in world units (m)
  int gauss_newton_iterations = 5;
  void Check() const;  // throws std::invalid_argument naming the field
};

struct TriangulatedPoint {
  Eigen::Vector3d point_in_world;
  double parallax_deg = 0.0;   // largest pairwise angle between ray directions
  double max_error_deg = 0.0;  // largest angular residual
};

std::optional<TriangulatedPoint> TriangulateRays(const std::vector<Ray>& rays,
                                                 const TriangulationOptions& options = {});
inline std::optional<TriangulatedPoint> TriangulateTwoRays(const Ray& a, const Ray& b,
                                                           const TriangulationOptions& options = {}) {
  return TriangulateRays({a, b}, options);
}

}  // namespace rovo
