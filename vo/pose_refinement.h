#pragma once
// Rig pose refinement with the 3D points fixed (ROVO paper, Sec. IV-C):
//     min_{rig_from_world} sum_j sum_{i in inliers_j} rho( | b_ij - pi0(cam_from_rig_j * rig_from_world * X_ij) |^2 )
// pi0(p) = p / |p| (projection onto the unit sphere, any direction), b_ij the observed unit bearing,
// rho the Cauchy loss with scale Options::cauchy_scale_rad. |b - pi0(p)| = 2 sin(angle / 2), so the
// residual is the chord of the angular error: monotonic over the whole sphere and ~angle when small.
// Parametrisation: rig_from_world as angle-axis (radians) + translation, solved by Ceres
// (Levenberg-Marquardt, dense QR over 6 unknowns). Ceres runs single-threaded here: deterministic.

#include <vector>

#include "datasets/rigid3.h"
#include "vo/ransac.h"

namespace rovo {

struct PoseRefinementOptions {
  double cauchy_scale_rad = 0.005;  // Cauchy loss scale on the chord (about 0.3 deg)
  int max_iterations = 20;
  void Check() const;
};

struct PoseRefinementResult {
  Rigid3 rig_from_world;
  int num_residuals = 0;
  double initial_cost = 0.0;  // Ceres cost (robustified)
  double final_cost = 0.0;
  bool usable = false;  // Ceres reported a usable solution
};

// inliers[j][i] selects camera j's correspondence i (same shape as correspondences); an empty
// `inliers` uses every correspondence.
PoseRefinementResult RefineRigPose(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
                                   const std::vector<Rigid3>& cam_from_rig,
                                   const std::vector<std::vector<char>>& inliers, const Rigid3& initial_rig_from_world,
                                   const PoseRefinementOptions& options = {});

// Mean angle (radians) between observed bearings and predicted directions over the selected
// correspondences (0 when none).
double MeanAngularError(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
                        const std::vector<Rigid3>& cam_from_rig, const std::vector<std::vector<char>>& inliers,
                        const Rigid3& rig_from_world);

}  // namespace rovo
