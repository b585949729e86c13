#pragma once
// Accuracy metrics of a VO run against ground truth.
//
// Trajectories hold world_from_rig. The estimate lives in its own world frame (call it `est`), the
// ground truth in `gt`; the metrics differ in how gt_from_est is chosen:
//   * SE(3) Umeyama alignment (primary): gt_from_est = argmin sum_i |p_gt_i - (R p_est_i + t)|^2 over
//     rotations R and translations t (scale fixed to 1: the rig's baseline makes the scale metric).
//   * origin alignment: gt_from_est = gt_world_from_rig_0 * est_world_from_rig_0^-1 (first pose).
// Translation RMSE = sqrt(mean_i |p_gt_i - gt_from_est * p_est_i|^2) over associated frames.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "datasets/rigid3.h"
#include "datasets/run.h"
#include "datasets/trajectory.h"

namespace rovo {

// Similarity dst ~= scale * rotation * src + translation.
struct UmeyamaResult {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
  Rigid3 DstFromSrc() const { return Rigid3(rotation, translation); }  // ignores scale
};

// Least-squares similarity (with_scale) or rigid transform between corresponding point sets
// (Umeyama 1991). With centred points x_i = src_i - mean(src), y_i = dst_i - mean(dst) and
// Sigma = (1/n) sum_i y_i x_i^T = U D V^T:
//   R = U S V^T, S = diag(1, 1, det(U) det(V))   (the sign flip keeps R a rotation, never a
//                                                  reflection, when the best orthogonal fit is one)
//   c = trace(D S) / sigma_x^2 (with_scale) else 1,  t = mean(dst) - c R mean(src).
// Throws std::invalid_argument when sizes differ, n < 3, or src is degenerate (all points within
// a line: the rotation about that line is unobservable).
UmeyamaResult AlignUmeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                           bool with_scale);

// Pairs (gt index, estimate index) whose timestamps differ by at most `tolerance_s`; each
// estimate is used at most once (the nearest gt frame in time). Both inputs sorted by time.
struct Association {
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> gt_without_estimate;  // gt indices with no estimate (lost/missing frames)
  std::vector<int> estimate_without_gt;  // estimate indices with no gt within tolerance
};
Association AssociateByTimestamp(const Trajectory& gt, const Trajectory& estimate, double tolerance_s);

// Length of the ground-truth path: the sum of the distances between consecutive positions.
double GtPathLength(const Trajectory& gt);

// Root mean square of |p_gt_i - gt_from_est * p_est_i| over the pairs.
double TranslationRmse(const Trajectory& gt, const Trajectory& estimate, const Association& association,
                       const Rigid3& gt_from_est);
// gt_from_est by SE(3) Umeyama over the associated positions.
Rigid3 AlignSe3(const Trajectory& gt, const Trajectory& estimate, const Association& association);
// gt_from_est from the first associated pair.
Rigid3 AlignOrigin(const Trajectory& gt, const Trajectory& estimate, const Association& association);

// KITTI-style relative drift. For every start frame i (step `step`) and segment length L, j is the
// first frame with gt path distance d(i, j) >= L; the error of the relative motion is
//   E = (gt_i^-1 gt_j)^-1 (est_i^-1 est_j),
// translation drift = |t(E)| / L, rotation drift = angle(E) / L. Averages over all segments.
// Segment lengths are `fractions` of the gt path length of the associated frames (KITTI uses
// 100..800 m for km-long sequences; our sequences are shorter, so the lengths scale with them).
struct DriftResult {
  double translation_pct = 0.0;        // 100 * mean |t(E)| / L
  double rotation_deg_per_100m = 0.0;  // mean angle(E) [deg] / L * 100
  int num_segments = 0;
  std::vector<double> segment_lengths_m;
};
DriftResult RelativeDrift(const Trajectory& gt, const Trajectory& estimate, const Association& association,
                          const std::vector<double>& fractions = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8},
                          int step = 1);

// Relative pose error over a fixed time interval (independent of the estimate's rate): for every
// associated pose i, j is the first associated pose with t_j >= t_i + delta_s (the pair is skipped
// when t_j - t_i > 1.5 delta_s, a gap in the estimate), and E = (gt_i^-1 gt_j)^-1 (est_i^-1 est_j):
// translation RMS |t(E)| [m], 100 * sum |t(E)| / sum d_ij [%] with d_ij the ground truth's distance
// between i and j, rotation RMS angle(E) [deg].
struct RelativePoseError {
  double delta_s = 1.0;
  int num_pairs = 0;
  double translation_rmse_m = 0.0;
  double translation_pct = 0.0;
  double rotation_rmse_deg = 0.0;
};
RelativePoseError ComputeRelativePoseError(const Trajectory& gt, const Trajectory& estimate,
                                           const Association& association, double delta_s = 1.0);

// Extrinsic error of camera i relative to camera 0 at one frame (the gauge of online calibration):
//   cam_i_from_cam0 = cam_i_from_rig * cam0_from_rig^-1, estimated vs ground truth;
//   rotation error = angle(gt^-1 est) in degrees, translation error = |t_est - t_gt| in metres.
// For Fig. 8, roll/pitch/yaw (degrees, datasets/rigid3.h convention) of camera i's orientation
// relative to camera 0 expressed in rig axes, C R_cam0_from_cami C^T with C = gt rig_from_cam0
// rotation (estimated and ground truth use the same C, so their difference is the error).
struct ExtrinsicError {
  int frame = 0;
  double timestamp = 0.0;
  int camera = 0;
  double rotation_error_deg = 0.0;
  double translation_error_m = 0.0;
  Eigen::Vector3d rpy_est_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_gt_deg = Eigen::Vector3d::Zero();
};
// One entry per (frame, camera >= 1) of the run's extrinsics; gt_cam_from_rig indexed by camera.
// Throws std::invalid_argument when a frame lacks camera 0 or names a camera the rig does not have.
std::vector<ExtrinsicError> ExtrinsicErrors(const std::vector<ExtrinsicsRecord>& extrinsics,
                                            const std::vector<Rigid3>& gt_cam_from_rig);

// The metrics that depend on the reported body, recomputed after removing the fixed body offset
// that the hand-eye calibration of eval/body_offset.h finds ("body-aligned"; the raw figures count
// the offset as error).
struct BodyAlignedMetrics {
  bool available = false;
  std::string note;                  // why unavailable, or which offset directions the motion leaves free
  double offset_rotation_deg = 0.0;  // angle of rig_from_body's rotation
  Eigen::Vector3d offset_translation_m = Eigen::Vector3d::Zero();  // rig_from_body's translation
  int offset_translation_rank = 0;  // directions of the translation the motion determines (0..3)
  double offset_rotation_residual_deg = 0.0;
  std::optional<double> rmse_origin_m;
  DriftResult drift;
  RelativePoseError rpe;
};

// Everything `rovo eval` reports for one run.
struct RunMetrics {
  std::string label;
  std::string mode;    // gt | noisy | online
  int noise_set = -1;  // -1 for GTExt or when run.json does not say
  int gt_frames = 0;   // of the span the run covers (run.json "frames"), else all
  int estimated_frames = 0;
  int associated_frames = 0;
  int missing_frames = 0;            // gt frames without an estimate
  int lost_frames = 0;               // frames.csv status "lost"
  double path_length_m = 0.0;        // gt path length over the span the run covers
  std::optional<double> rmse_se3_m;  // empty when alignment is impossible (too few/degenerate)
  std::optional<double> rmse_origin_m;
  std::optional<double> relative_rmse_pct;  // 100 * rmse_se3 / path length
  DriftResult drift;
  RelativePoseError rpe;
  BodyAlignedMetrics body;              // drift, RPE and origin error after removing the body offset
  std::string align = "se3";            // se3 | sim3 (EvalOptions::align)
  double scale = 1.0;                   // sim3: the estimate's positions were multiplied by it first
  std::string association = "nearest";  // nearest | interpolate (EvalOptions::association)
  double mean_inlier_ratio = 0.0;       // over frames with status ok
  double mean_reproj_error_deg = 0.0;   // over frames with status ok
  double mean_time_ms = 0.0;            // over all frames
  // Per camera i >= 1 (index i-1): error at the last frame, and mean over frames.
  std::vector<double> final_ext_rotation_deg, final_ext_translation_m;
  std::vector<double> mean_ext_rotation_deg, mean_ext_translation_m;
  double max_final_ext_rotation_deg = 0.0;
  double max_final_ext_translation_m = 0.0;
  std::string alignment_note;  // why rmse is empty, if it is
};

// Per-frame error along the path (after SE(3) alignment, or origin alignment as fallback).
struct FrameError {
  int gt_index = 0;
  int estimate_index = 0;
  double timestamp = 0.0;
  Eigen::Vector3d gt_position = Eigen::Vector3d::Zero();
  Eigen::Vector3d aligned_position = Eigen::Vector3d::Zero();
  double error_m = 0.0;
  Rigid3 gt_world_from_rig;  // the ground truth at `timestamp` (interpolated with association interpolate)
};

struct RunEvaluation {
  RunMetrics metrics;
  Rigid3 gt_from_est;
  std::vector<FrameError> frame_errors;
  std::vector<ExtrinsicError> extrinsic_errors;
};

struct EvalOptions {
  double time_tolerance_s = 0.0;  // 0 = a quarter of the gt frame interval
  // nearest: each ground-truth frame pairs with the nearest estimate within the tolerance;
  // interpolate: the ground truth is interpolated (slerp + linear, only inside its time range) at
  // every estimate's time, for estimates at any rate; auto: nearest unless more than 10 % of the
  // estimates are not within the tolerance of a ground-truth frame (e.g. VIO output at 200 Hz).
  std::string association = "auto";
  // se3: rigid alignment (metric systems); sim3: the scale too (Umeyama), for monocular systems:
  // the estimate's positions are scaled by it before every metric.
  std::string align = "se3";
  double rpe_delta_s = 1.0;  // interval of the relative pose error
};

// Throws std::invalid_argument naming the field when association or align is not a known value.
void CheckEvalOptions(const EvalOptions& options);

// Scores one run; `gt_cam_from_rig` is the dataset's ground-truth rig extrinsics.
RunEvaluation EvaluateRun(const Trajectory& gt, const std::vector<Rigid3>& gt_cam_from_rig, const RunData& run,
                          const std::string& label, const EvalOptions& options = {});

}  // namespace rovo
