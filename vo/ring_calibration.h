#pragma once
// Extrinsic calibration of a ring of wide-FOV cameras without an extrinsic prior (the first stage of
// OnlineExt's start-up calibration, startup_calibration.h).
//
// The start-up calibration must work from any sigma = 5 deg perturbation draw, where neighbouring
// cameras are off by up to 25-30 deg relative to each other, so the given (nominal) extrinsics may
// only choose where to look, never which match to keep. Per ring pair (a, b) of neighbouring cameras:
//   1. Overlap views. Each camera's image is resampled onto one longitude/latitude grid around the
//      pair's overlap direction m (the horizontal bisector of the two nominal optical axes; latitude
//      about the rig's up axis), through that camera's nominal rotation. Both views then show the
//      overlap with the same mapping, rotated against each other only by the extrinsic error, and the
//      bearing of a view pixel in its camera is exact whatever that error is.
//   2. Oriented ORB in both views (inside the lens and the optional static mask), brute-force Hamming
//      matching with the ratio test and a mutual check. A match whose two nominal rig-frame bearings
//      differ by more than max_prior_angle_deg is dropped: a gross-outlier bound, above any error of
//      a sigma = 5 deg draw.
//   3. The matches of every frame given (AddFrame) are pooled: the cameras' relative pose is the
//      same in every synchronous shot. A rotation-only RANSAC on the bearings (OpenGV) removes gross
//      mismatches, and the epipolar residuals with the baseline direction held at its nominal value
//      refine
//          R_ba = rotation of cam_b_from_cam_a   (x_in_b = R_ba x_in_a + t_ba).
// Ring: with R_j = rotation of cam_j_from_cam0 (camera 0 is the gauge, R_0 = I), the pair rotations
// are averaged by
//     min over R_1..R_{N-1} of  sum_(a,b) w_ab |Log(R_b R_a^T R_ba^T)|^2,   w_ab = inliers of (a, b)
// (Ceres), started by chaining the pairs from camera 0, then refined jointly on every pair's epipolar
// residuals, each baseline direction following its camera, with one angle scale of every lens's
// off-axis angle (angle_scale_sigma). Loop closure, |Log(prod of R_ba around the ring)|, checks the
// pairs' consistency. Camera 0 stays the gauge (its cam_from_rig is kept); the joint solution's
// common turn of the cameras against their centres (camera 0's own error, seen through the
// baselines' directions) turns the other centres about camera 0's instead (turn_centres).
//
// Code: the overlap views in ring_views.h, the pair and joint model in ring_model.h, the policy (passes,
// starts, convergence, what is reported) in ring_calibration.cc.

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "datasets/rig.h"
#include "datasets/rigid3.h"

namespace rovo {

struct RingCalibrationOptions {
  double view_half_width_deg = 65.0;   // longitude extent of an overlap view (each side of m)
  double view_half_height_deg = 60.0;  // latitude extent (each side of the horizon)
  double min_view_focal_px = 300.0;    // overlap views sample at least this density (pixels per radian)
  // > 0: denser views still, up to this density but at most dense_view_max_upsampling times the
  // lenses' own (the start-up's later passes: more corners where the lens holds them).
  double dense_view_focal_px = 0.0;
  double dense_view_max_upsampling = 1.25;
  int orb_features = 3000;  // per overlap view
  int orb_fast_threshold = 10;
  bool refine_matches = false;           // KLT sub-pixel refinement of the matches (aligned views only)
  double klt_normalize_sigma_px = 10.0;  // KLT on locally contrast-normalised views (window sigma); 0: raw
  double max_ratio = 0.8;                // best / second-best Hamming distance
  int max_descriptor_distance = 80;
  double max_prior_angle_deg = 40.0;  // gross-outlier bound on the nominal rig-frame bearings
  double max_parallax_deg = 5.0;      // rotation-only RANSAC threshold (parallax of near points)
  bool reselect_all = true;           // final inliers from every match, not only the RANSAC's
  double inlier_threshold_deg = 0.4;  // epipolar residual of an inlier (and the Cauchy scale)
  int ransac_iterations = 2000;
  int min_inliers = 25;                    // fewer: the pair is not estimated
  double max_loop_error_deg = 12.0;        // larger loop-closure error of the pairs: not converged
  double max_pair_disagreement_deg = 0.5;  // a pair further from the joint ring solution: not converged
  bool require_closed_ring = true;         // every ring pair estimated (the loop checks them), else not converged
  double max_uncertainty_deg = 0.25;       // one sigma of the worst camera (RingUncertaintyDeg) above: not converged
  int joint_rounds = 2;                    // inliers re-selected by the joint solution, then refined again
  double prior_sigma_deg = 5.0;            // joint refinement: camera 0's prior (the common rotation)
  // > 0: the joint refinement also estimates one angle scale 1 + kappa of every lens's off-axis angle
  // around a closed ring, kappa with this prior standard deviation (a real lens calibration that
  // understates angles near the rim leaves the ring open by degrees); 0: the lenses as given.
  double angle_scale_sigma = 0.03;
  double min_angle_scale_change = 0.005;  // a smaller estimate of |kappa|: the lenses stay as given
  // The joint solution's common rotation of the cameras against their centres is given to the centres
  // (turned about camera 0's), so each baseline's direction in its cameras is the solution's; false:
  // the centres stay the given ones (and the baselines keep camera 0's given error).
  bool turn_centres = true;
  // The turned centres count as known (RingCalibrationReport::centres_known) when the matches alone
  // know the turn within this one sigma. A less certain turn is still given to the centres: the
  // solution's estimate, held near the given camera 0 by its prior, beats the draw's error.
  double max_common_turn_sigma_deg = 0.5;
  void Check() const;
};

struct RingPairEstimate {
  int camera_a = 0, camera_b = 0;
  int matches = 0;  // pooled over frames, after the ratio, mutual and prior checks
  int inliers = 0;
  bool usable = false;
  Eigen::Quaterniond camb_from_cama = Eigen::Quaterniond::Identity();  // R_ba
  double change_deg = 0.0;                                             // angle between R_ba and the nominal one
  // Median |epipolar residual| of the final inliers under the given extrinsics and under the result
  // (degrees; -1 when the ring did not converge): how much better the result explains the overlaps.
  double median_residual_deg_given = -1.0, median_residual_deg_result = -1.0;
};

struct RingCalibrationReport {
  bool converged = false;
  std::string reason;  // why not, when not converged
  int frames = 0;
  std::vector<RingPairEstimate> pairs;
  double loop_error_deg = -1.0;            // < 0: the ring is not closed (a pair missing, or N < 3)
  double max_pair_disagreement_deg = 0.0;  // largest angle between a pair's own and the joint rotation
  double uncertainty_deg = -1.0;           // one sigma of the worst-determined camera (RingUncertaintyDeg)
  double angle_scale = 1.0;                // the lenses' off-axis angle scale of the joint solution
  double common_turn_deg = 0.0;            // the joint solution's common turn of the cameras against their centres
  double common_turn_sigma_deg = -1.0;     // its one sigma from the matches alone (no prior); < 0: not computed
  bool centres_turned = false;             // the centres took that turn (turn_centres)
  bool centres_known = false;              // ... and the matches know it (max_common_turn_sigma_deg)
  std::vector<Rigid3> cam_from_rig;        // calibrated (camera 0 unchanged; the centres turned about it)
};

// How well one calibration explains a ring pair's overlap matches (RingCalibrator::Fit).
struct RingPairFit {
  int camera_a = 0, camera_b = 0;
  int matches = 0;                    // pooled over frames, after the ratio, mutual and prior checks
  int inliers = 0;                    // epipolar residual below the inlier threshold, in front of both
  double median_residual_deg = -1.0;  // median |epipolar residual| of those inliers; -1: none
  std::vector<double> residuals_deg;  // |epipolar residual| of every match
};

// Ring neighbours: the cameras sorted by the yaw of their nominal optical axis, each paired with the
// next (and the last with the first when N >= 3). Pairs whose axes are further apart than the
// lenses' field of view allows an overlap are left out.
std::vector<std::pair<int, int>> RingPairs(const Rig& rig);

class RingCalibrator {
 public:
  // `rig`: the lenses and the nominal extrinsics (only used to choose the overlap views).
  // `static_masks`: empty, or one 8-bit mask per camera of its image size (0 = invalid pixel).
  RingCalibrator(const Rig& rig, const std::vector<cv::Mat>& static_masks = {},
                 const RingCalibrationOptions& options = {});
  ~RingCalibrator();

  // One synchronous shot (8-bit gray or BGR, one image per camera): its overlap matches are pooled.
  void AddFrame(const std::vector<cv::Mat>& images);
  RingCalibrationReport Solve() const;
  // The pooled overlap matches judged by a given calibration: `cam_from_rig` (rotations used; every
  // centre stays the rig's) and the lenses' off-axis angle scale (RingCalibrationReport::angle_scale).
  // The cameras' common rotation against their centres is first fitted to the matches (Cauchy at the
  // inlier threshold), so only the relative rotations and the lenses are judged. Two calibrations
  // compared on the same matches: the one that explains more of them, with smaller residuals, fits
  // the images better.
  std::vector<RingPairFit> Fit(const std::vector<Rigid3>& cam_from_rig, double angle_scale = 1.0) const;

  // The overlap view of pair `pair_index` for camera `side` (0 = a, 1 = b) at the last AddFrame, for
  // drawing and tests.
  const cv::Mat& overlap_view(int pair_index, int side) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rovo
