#pragma once
// Minimal absolute pose from three bearing <-> point correspondences (P3P), for central cameras of
// any field of view.
//
// Problem: find cam_from_world = (R, t) and depths lambda_i > 0 with
//     lambda_i * bearing_i = R * point_in_world_i + t,   i = 1, 2, 3,
// where bearing_i are unit 3-vectors in the camera frame. Nothing assumes bearing_i.z > 0: a ray
// 120 deg off the optical axis is as good as one on it, so the solver serves 220 deg fisheye lenses.
//
// Method: Lambda Twist (M. Persson, K. Nordberg, "Lambda Twist: An Accurate Fast Robust
// Perspective Three Point (P3P) Solver", ECCV 2018). Distances are preserved by rigid motion, so
//     lambda_i^2 + lambda_j^2 + b_ij lambda_i lambda_j = a_ij,
//     b_ij = -2 bearing_i . bearing_j,  a_ij = |X_i - X_j|^2,
// i.e. lambda^T M_ij lambda = a_ij with 3x3 symmetric M_ij. The homogeneous combinations
//     D1 = a23 M12 - a12 M23,  D2 = a23 M13 - a13 M23   (lambda^T D_k lambda = 0)
// are mixed into a degenerate conic D0 = D1 + gamma D2, det(D0) = 0 (a cubic in gamma; one real
// root suffices). D0 = sigma1 e1 e1^T + sigma2 e2 e2^T with sigma1 sigma2 <= 0 splits into two planes
// (e1 -+ s e2) . lambda = 0, s = sqrt(-sigma2 / sigma1). In each plane lambda^T D2 lambda = 0 is a
// homogeneous quadratic giving up to two rays; lambda^T M23 lambda = a23 fixes the scale. The depths
// are polished by Gauss-Newton on the three distance equations, and (R, t) follows from the three
// camera-frame points lambda_i bearing_i by a least-squares rigid alignment (Kabsch).
//
// Assumptions: the three world points are not collinear, the three bearings are distinct. Returns
// up to 4 solutions (0 for degenerate input), each with lambda_i > 0.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "datasets/rigid3.h"

namespace rovo {

std::vector<Rigid3> SolveP3P(const std::array<Eigen::Vector3d, 3>& bearings_in_cam,
                             const std::array<Eigen::Vector3d, 3>& points_in_world);

}  // namespace rovo
