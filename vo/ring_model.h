#pragma once
// The ring calibration's model (ring_calibration.h, step 3 and the ring): each pair's rotation from
// its pooled matches, the pair rotations averaged and chained around the ring, the joint refinement of
// every camera's rotation and the lenses' angle scale on the epipolar residuals, and its covariance.
// Internal to the ring calibration; the policy (passes, starts, decisions) is ring_calibration.cc's.

#include <Eigen/Geometry>
#include <vector>

#include "datasets/rig.h"
#include "vo/ring_calibration.h"
#include "vo/ring_views.h"

namespace rovo::ring {

// The joint unknowns: every camera's rotation and the lenses' common angle scale.
struct RingModel {
  std::vector<Eigen::Quaterniond> rotations;  // cam_j_from_rig
  double kappa = 0.0;                         // off-axis angles scaled by 1 + kappa
};

// One pair's rotation R_ba from its pooled matches (rotation-only RANSAC, then the epipolar
// residuals with the nominal baseline direction); `*inliers` receives the final inliers when usable.
RingPairEstimate EstimatePair(const OverlapPair& p, const Rig& rig, const RingCalibrationOptions& o,
                              std::vector<int>* inliers);

// The usable pairs' rotations averaged into cam_j_from_cam0 (weights: inliers), from `rotations`;
// `rotations[0]` stays fixed.
std::vector<Eigen::Quaterniond> AverageRing(const std::vector<RingPairEstimate>& pairs, int num_cams,
                                            std::vector<Eigen::Quaterniond> rotations);

// c_b - c_a in the rig frame (the rig's given centres).
Eigen::Vector3d PairBaselineInRig(const OverlapPair& p, const Rig& rig);

// |epipolar residual| (sine of the angle) of match `i` of pair `p` under `model`.
double RingResidual(const OverlapPair& p, int i, const Eigen::Vector3d& baseline_in_rig, const RingModel& model);

// Every cam_j_from_rig rotation refined on all pairs' `inliers` at once (Cauchy at `scale_rad`),
// camera 0 held near its start (prior_sigma_deg); the angle scale too when angle_scale_sigma > 0.
RingModel RefineRing(const std::vector<OverlapPair>& pairs, const std::vector<std::vector<int>>& inliers,
                     const Rig& rig, RingModel model, double scale_rad, double prior_sigma_deg,
                     double angle_scale_sigma);

// One sigma (degrees) of the worst-determined camera's rotation relative to camera 0 at `model`;
// camera_zero_free: camera 0's own one sigma with every camera free. -1: not computable.
double RingUncertaintyDeg(const std::vector<OverlapPair>& pairs, const std::vector<std::vector<int>>& inliers,
                          const Rig& rig, RingModel model, bool angle_scale_free, bool camera_zero_free = false);

// `model` with every camera turned by the one rig-frame rotation that best explains all the matches.
RingModel FitCommonRotation(const std::vector<OverlapPair>& pairs, const Rig& rig, RingModel model, double scale_rad);

// Per pair, the matches that `model` explains (residual below `threshold_rad`, in front of both).
std::vector<std::vector<int>> ReselectInliers(const std::vector<OverlapPair>& pairs, const Rig& rig,
                                              const RingModel& model, double threshold_rad);

// Median |epipolar residual| over `indices` of pair `p` under `model`, degrees; -1: no indices.
double MedianResidualDeg(const OverlapPair& p, const std::vector<int>& indices, const Rig& rig, const RingModel& model);

// Angle between the joint rotation of a pair and the pair's own, refined on its inliers alone.
double PairDisagreementDeg(const OverlapPair& p, const std::vector<int>& inliers, const Rig& rig,
                           const RingModel& model, double scale_rad);

// cam_j_from_cam0 by chaining usable pairs outward from camera 0; false when a camera is not reached.
bool ChainFromCameraZero(const std::vector<RingPairEstimate>& pairs, int num_cams,
                         std::vector<Eigen::Quaterniond>* rotations);

// Angle of the product of the pair rotations around the ring (every pair usable, N >= 3); -1 otherwise.
double LoopClosureErrorDeg(const std::vector<RingPairEstimate>& pairs, int num_cams);

}  // namespace rovo::ring
