#include "eval/metrics.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "eval/body_offset.h"

namespace rovo {

UmeyamaResult AlignUmeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                           bool with_scale) {
  if (src.size() != dst.size()) {
    throw std::invalid_argument("AlignUmeyama: point sets differ in size (" + std::to_string(src.size()) + " vs " +
                                std::to_string(dst.size()) + ")");
  }
  const size_t n = src.size();
  if (n < 3) {
    throw std::invalid_argument("AlignUmeyama: need at least 3 corresponding points, got " + std::to_string(n));
  }
  Eigen::Vector3d mean_src = Eigen::Vector3d::Zero(), mean_dst = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mean_src += src[i];
    mean_dst += dst[i];
  }
  mean_src /= static_cast<double>(n);
  mean_dst /= static_cast<double>(n);

  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();    // (1/n) sum y x^T
  Eigen::Matrix3d cov_src = Eigen::Matrix3d::Zero();  // (1/n) sum x x^T
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x = src[i] - mean_src;
    const Eigen::Vector3d y = dst[i] - mean_dst;
    sigma += y * x.transpose();
    cov_src += x * x.transpose();
  }
  sigma /= static_cast<double>(n);
  cov_src /= static_cast<double>(n);

  // Degeneracy: the spread of src must span at least a plane. Eigenvalues ascending.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov_src);
  const Eigen::Vector3d& lambda = eig.eigenvalues();
  const double largest = lambda(2);
  if (!(largest > 0.0) || lambda(1) <= 1e-12 * largest) {
    std::ostringstream msg;
    msg << "AlignUmeyama: degenerate input, the " << n << " source points are "
        << (largest > 0.0 ? "collinear" : "all at one position") << " (spread eigenvalues " << lambda.transpose()
        << "); the rotation about their line is undetermined, so the trajectory cannot be aligned";
    throw std::invalid_argument(msg.str());
  }

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  Eigen::Vector3d s(1.0, 1.0, 1.0);
  if (u.determinant() * v.determinant() < 0.0) s(2) = -1.0;  // reflection -> nearest rotation

  UmeyamaResult result;
  result.rotation = u * s.asDiagonal() * v.transpose();
  if (with_scale) {
    const double var_src = cov_src.trace();
    result.scale = svd.singularValues().dot(s) / var_src;
  }
  result.translation = mean_dst - result.scale * result.rotation * mean_src;
  return result;
}

Association AssociateByTimestamp(const Trajectory& gt, const Trajectory& estimate, double tolerance_s) {
  Association out;
  // For each gt frame the nearest estimate within tolerance (each estimate matches at most its
  // nearest gt frame).
  std::map<int, std::pair<int, double>> best;  // gt index -> (estimate index, |dt|)
  std::vector<bool> used(estimate.size(), false);
  for (size_t j = 0; j < estimate.size(); ++j) {
    const double t = estimate[j].timestamp;
    const auto it = std::lower_bound(gt.begin(), gt.end(), t,
                                     [](const StampedPose& p, double value) { return p.timestamp < value; });
    int nearest = -1;
    double nearest_dt = 0.0;
    for (auto c : {it, it == gt.begin() ? gt.end() : it - 1}) {
      if (c == gt.end()) continue;
      const double dt = std::abs(c->timestamp - t);
      if (nearest < 0 || dt < nearest_dt) {
        nearest = static_cast<int>(c - gt.begin());
        nearest_dt = dt;
      }
    }
    if (nearest < 0 || nearest_dt > tolerance_s) continue;
    const auto found = best.find(nearest);
    if (found == best.end() || nearest_dt < found->second.second) best[nearest] = {static_cast<int>(j), nearest_dt};
  }
  for (const auto& [gt_index, match] : best) {
    out.pairs.emplace_back(gt_index, match.first);
    used[match.first] = true;
  }
  for (size_t i = 0, k = 0; i < gt.size(); ++i) {
    if (k < out.pairs.size() && out.pairs[k].first == static_cast<int>(i)) {
      ++k;
    } else {
      out.gt_without_estimate.push_back(static_cast<int>(i));
    }
  }
  for (size_t j = 0; j < estimate.size(); ++j) {
    if (!used[j]) out.estimate_without_gt.push_back(static_cast<int>(j));
  }
  return out;
}

double TranslationRmse(const Trajectory& gt, const Trajectory& estimate, const Association& association,
                       const Rigid3& gt_from_est) {
  if (association.pairs.empty()) throw std::invalid_argument("TranslationRmse: no associated frames");
  double sum = 0.0;
  for (const auto& [i, j] : association.pairs) {
    const Eigen::Vector3d aligned = gt_from_est * estimate[j].world_from_rig.translation;
    sum += (gt[i].world_from_rig.translation - aligned).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(association.pairs.size()));
}

Rigid3 AlignSe3(const Trajectory& gt, const Trajectory& estimate, const Association& association) {
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& [i, j] : association.pairs) {
    src.push_back(estimate[j].world_from_rig.translation);
    dst.push_back(gt[i].world_from_rig.translation);
  }
  return AlignUmeyama(src, dst, /*with_scale=*/false).DstFromSrc();
}

Rigid3 AlignOrigin(const Trajectory& gt, const Trajectory& estimate, const Association& association) {
  if (association.pairs.empty()) throw std::invalid_argument("AlignOrigin: no associated frames");
  const auto [i, j] = association.pairs.front();
  return gt[i].world_from_rig * estimate[j].world_from_rig.Inverse();
}

DriftResult RelativeDrift(const Trajectory& gt, const Trajectory& estimate, const Association& association,
                          const std::vector<double>& fractions, int step) {
  DriftResult result;
  const size_t n = association.pairs.size();
  if (n < 2) return result;
  std::vector<double> distance(n, 0.0);  // gt path distance from the first associated frame
  for (size_t k = 1; k < n; ++k) {
    distance[k] = distance[k - 1] + (gt[association.pairs[k].first].world_from_rig.translation -
                                     gt[association.pairs[k - 1].first].world_from_rig.translation)
                                        .norm();
  }
  const double total = distance.back();
  if (!(total > 0.0)) return result;
  for (double f : fractions) result.segment_lengths_m.push_back(f * total);

  double sum_translation = 0.0, sum_rotation = 0.0;
  for (size_t k = 0; k < n; k += static_cast<size_t>(std::max(step, 1))) {
    for (double length : result.segment_lengths_m) {
      const auto it = std::lower_bound(distance.begin() + static_cast<long>(k), distance.end(), distance[k] + length);
      if (it == distance.end()) continue;
      const size_t m = static_cast<size_t>(it - distance.begin());
      const auto [gi, ei] = association.pairs[k];
      const auto [gj, ej] = association.pairs[m];
      const Rigid3 gt_motion = gt[gi].world_from_rig.Inverse() * gt[gj].world_from_rig;
      const Rigid3 est_motion = estimate[ei].world_from_rig.Inverse() * estimate[ej].world_from_rig;
      const Rigid3 error = gt_motion.Inverse() * est_motion;
      sum_translation += error.translation.norm() / length;
      sum_rotation += RotationAngleDeg(error.rotation) / length;
      ++result.num_segments;
    }
  }
  if (result.num_segments > 0) {
    result.translation_pct = 100.0 * sum_translation / result.num_segments;
    result.rotation_deg_per_100m = 100.0 * sum_rotation / result.num_segments;
  }
  return result;
}

RelativePoseError ComputeRelativePoseError(const Trajectory& gt, const Trajectory& estimate,
                                           const Association& association, double delta_s) {
  RelativePoseError result;
  result.delta_s = delta_s;
  const size_t n = association.pairs.size();
  if (n < 2 || !(delta_s > 0.0)) return result;
  double sum_sq_translation = 0.0, sum_translation = 0.0, sum_distance = 0.0, sum_sq_rotation = 0.0;
  size_t m = 0;
  for (size_t k = 0; k < n; ++k) {
    const double t_k = gt[association.pairs[k].first].timestamp;
    m = std::max(m, k + 1);
    while (m < n && gt[association.pairs[m].first].timestamp < t_k + delta_s - 1e-9) ++m;
    if (m >= n) break;
    if (gt[association.pairs[m].first].timestamp - t_k > 1.5 * delta_s) continue;
    const auto [gi, ei] = association.pairs[k];
    const auto [gj, ej] = association.pairs[m];
    const Rigid3 gt_motion = gt[gi].world_from_rig.Inverse() * gt[gj].world_from_rig;
    const Rigid3 est_motion = estimate[ei].world_from_rig.Inverse() * estimate[ej].world_from_rig;
    const Rigid3 error = gt_motion.Inverse() * est_motion;
    const double angle = RotationAngleDeg(error.rotation);
    sum_sq_translation += error.translation.squaredNorm();
    sum_translation += error.translation.norm();
    sum_distance += gt_motion.translation.norm();
    sum_sq_rotation += angle * angle;
    ++result.num_pairs;
  }
  if (result.num_pairs > 0) {
    result.translation_rmse_m = std::sqrt(sum_sq_translation / result.num_pairs);
    result.translation_pct = sum_distance > 0.0 ? 100.0 * sum_translation / sum_distance : 0.0;
    result.rotation_rmse_deg = std::sqrt(sum_sq_rotation / result.num_pairs);
  }
  return result;
}

void CheckEvalOptions(const EvalOptions& options) {
  if (options.association != "auto" && options.association != "nearest" && options.association != "interpolate") {
    throw std::invalid_argument("eval options: association `" + options.association +
                                "` is not one of auto, nearest, interpolate");
  }
  if (options.align != "se3" && options.align != "sim3") {
    throw std::invalid_argument("eval options: align `" + options.align + "` is not one of se3, sim3");
  }
  if (!(options.rpe_delta_s > 0.0)) throw std::invalid_argument("eval options: rpe_delta_s must be positive");
}

std::vector<ExtrinsicError> ExtrinsicErrors(const std::vector<ExtrinsicsRecord>& extrinsics,
                                            const std::vector<Rigid3>& gt_cam_from_rig) {
  std::vector<ExtrinsicError> errors;
  if (gt_cam_from_rig.empty()) return errors;
  // Group records by frame (records of one frame are contiguous or not; do not assume).
  std::map<int, std::map<int, const ExtrinsicsRecord*>> by_frame;
  for (const ExtrinsicsRecord& r : extrinsics) {
    if (r.camera < 0 || r.camera >= static_cast<int>(gt_cam_from_rig.size())) {
      throw std::invalid_argument("extrinsics: frame " + std::to_string(r.frame) + " names camera " +
                                  std::to_string(r.camera) + " but the rig has " +
                                  std::to_string(gt_cam_from_rig.size()) + " cameras");
    }
    by_frame[r.frame][r.camera] = &r;
  }
  const Rigid3 gt_rig_from_cam0 = gt_cam_from_rig[0].Inverse();
  for (const auto& [frame, cameras] : by_frame) {
    const auto cam0 = cameras.find(0);
    if (cam0 == cameras.end()) {
      throw std::invalid_argument("extrinsics: frame " + std::to_string(frame) +
                                  " has no camera 0 (the reference of relative extrinsics)");
    }
    const Rigid3 est_rig_from_cam0 = cam0->second->cam_from_rig.Inverse();
    for (const auto& [camera, record] : cameras) {
      if (camera == 0) continue;
      const Rigid3 est = record->cam_from_rig * est_rig_from_cam0;  // cam_i_from_cam0
      const Rigid3 gt = gt_cam_from_rig[camera] * gt_rig_from_cam0;
      ExtrinsicError e;
      e.frame = frame;
      e.timestamp = record->timestamp;
      e.camera = camera;
      e.rotation_error_deg = RotationDistanceDeg(gt.rotation, est.rotation);
      e.translation_error_m = (est.translation - gt.translation).norm();
      // Orientation of camera i relative to camera 0 in rig axes: C R_cam0_from_cami C^T with C the
      // ground-truth rig_from_cam0 rotation (a horizontal ring of cameras reads as yaw offsets, far
      // from the pitch = +-90 deg singularity that OpenCV camera axes would hit).
      const Eigen::Quaterniond c = gt_rig_from_cam0.rotation;
      e.rpy_est_deg = RollPitchYawDegFromQuaternion(c * est.rotation.conjugate() * c.conjugate());
      e.rpy_gt_deg = RollPitchYawDegFromQuaternion(c * gt.rotation.conjugate() * c.conjugate());
      errors.push_back(e);
    }
  }
  return errors;
}

double GtPathLength(const Trajectory& gt) {
  double length = 0.0;
  for (size_t i = 1; i < gt.size(); ++i) {
    length += (gt[i].world_from_rig.translation - gt[i - 1].world_from_rig.translation).norm();
  }
  return length;
}

namespace {

double MedianInterval(const Trajectory& trajectory) {
  std::vector<double> dt;
  for (size_t i = 1; i < trajectory.size(); ++i) dt.push_back(trajectory[i].timestamp - trajectory[i - 1].timestamp);
  if (dt.empty()) return 0.0;
  std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
  return dt[dt.size() / 2];
}

// A run over frames [a, b) of the dataset (run.json "frames") is scored against that span of the
// ground truth: its path length, missing frames and drift segments. Returns [begin, end) in `gt_size` frames.
std::pair<size_t, size_t> RunSpan(const RunData& run, size_t gt_size) {
  size_t span_begin = 0, span_end = gt_size;
  if (run.info.contains("frames") && run.info["frames"].is_array() && run.info["frames"].size() == 2 &&
      run.info["frames"][0].is_number_integer() && run.info["frames"][1].is_number_integer()) {
    const long a = run.info["frames"][0].get<long>(), b = run.info["frames"][1].get<long>();
    if (a >= 0 && a < b && b <= static_cast<long>(gt_size)) {
      span_begin = static_cast<size_t>(a);
      span_end = static_cast<size_t>(b);
    }
  }
  return {span_begin, span_end};
}

// The poses the metrics compare: the ground truth (at the estimate's times when interpolated), the
// estimate (scaled with sim3) and their pairing.
struct ScoredPoses {
  Trajectory gt;
  Trajectory estimate;
  Association association;
  std::vector<int> gt_index;  // per pose of `gt`: index of the (nearest) frame in the run's span
};

double AssociationTolerance(const Trajectory& gt, const EvalOptions& options) {
  if (options.time_tolerance_s > 0.0) return options.time_tolerance_s;
  const double interval = MedianInterval(gt);
  return interval > 0.0 ? 0.25 * interval : 1e-3;
}

size_t NearestIndex(const Trajectory& trajectory, double t) {
  const auto it = std::lower_bound(trajectory.begin(), trajectory.end(), t,
                                   [](const StampedPose& p, double value) { return p.timestamp < value; });
  if (it == trajectory.end()) return trajectory.size() - 1;
  if (it == trajectory.begin()) return 0;
  return (t - (it - 1)->timestamp <= it->timestamp - t) ? static_cast<size_t>(it - 1 - trajectory.begin())
                                                        : static_cast<size_t>(it - trajectory.begin());
}

// Ground truth interpolated at every estimate inside its time range; missing = ground-truth frames
// farther than max(tolerance, 0.75 x the estimate's median interval) from every estimate.
ScoredPoses InterpolatedPoses(const Trajectory& gt, const Trajectory& estimate, double tolerance, int* missing) {
  ScoredPoses out;
  for (size_t j = 0; j < estimate.size(); ++j) {
    const double t = estimate[j].timestamp;
    if (t < gt.front().timestamp - 1e-9 || t > gt.back().timestamp + 1e-9) continue;
    out.association.pairs.emplace_back(static_cast<int>(out.gt.size()), static_cast<int>(j));
    out.gt.push_back({t, InterpolatePose(gt, t)});
    out.gt_index.push_back(static_cast<int>(NearestIndex(gt, t)));
  }
  out.estimate = estimate;
  const double reach = std::max(tolerance, 0.75 * MedianInterval(estimate));
  *missing = 0;
  for (const StampedPose& p : gt) {
    if (estimate.empty() || std::abs(estimate[NearestIndex(estimate, p.timestamp)].timestamp - p.timestamp) > reach) {
      ++*missing;
    }
  }
  return out;
}

// Pairs the run's poses with the ground truth as options.association says (m: association, missing).
ScoredPoses AssociatePoses(const Trajectory& gt, const Trajectory& estimate, const EvalOptions& options,
                           RunMetrics* m) {
  const double tolerance = AssociationTolerance(gt, options);
  Association nearest = AssociateByTimestamp(gt, estimate, tolerance);
  const bool interpolate =
      options.association == "interpolate" ||
      (options.association == "auto" && !estimate.empty() &&
       static_cast<double>(nearest.estimate_without_gt.size()) > 0.1 * static_cast<double>(estimate.size()));
  if (interpolate && !gt.empty()) {
    m->association = "interpolate";
    return InterpolatedPoses(gt, estimate, tolerance, &m->missing_frames);
  }
  m->association = "nearest";
  m->missing_frames = static_cast<int>(nearest.gt_without_estimate.size());
  ScoredPoses out{gt, estimate, std::move(nearest), {}};
  for (const auto& pair : out.association.pairs) out.gt_index.push_back(pair.first);
  return out;
}

// sim3: the Umeyama scale over the associated positions, applied to the estimate's positions.
void ApplySim3Scale(ScoredPoses* poses, RunMetrics* m) {
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& [i, j] : poses->association.pairs) {
    src.push_back(poses->estimate[j].world_from_rig.translation);
    dst.push_back(poses->gt[i].world_from_rig.translation);
  }
  try {
    m->scale = AlignUmeyama(src, dst, /*with_scale=*/true).scale;
  } catch (const std::invalid_argument& e) {
    m->alignment_note = std::string("Sim(3) scale impossible (kept 1): ") + e.what();
    return;
  }
  for (StampedPose& p : poses->estimate) p.world_from_rig.translation *= m->scale;
}

// Drift, RPE and origin error of the estimate after the hand-eye body offset is removed.
void ScoreBodyAligned(const ScoredPoses& poses, const EvalOptions& options, BodyAlignedMetrics* body) {
  const BodyOffset offset = EstimateBodyOffset(poses.gt, poses.estimate, poses.association);
  body->note = offset.note;
  if (!offset.valid) return;
  body->available = true;
  body->offset_rotation_deg = RotationAngleDeg(offset.rig_from_body.rotation);
  body->offset_translation_m = offset.rig_from_body.translation;
  body->offset_translation_rank = offset.translation_rank;
  body->offset_rotation_residual_deg = offset.rotation_residual_deg;
  const Trajectory aligned = RemoveBodyOffset(poses.estimate, offset.rig_from_body);
  body->rmse_origin_m =
      TranslationRmse(poses.gt, aligned, poses.association, AlignOrigin(poses.gt, aligned, poses.association));
  body->drift = RelativeDrift(poses.gt, aligned, poses.association);
  body->rpe = ComputeRelativePoseError(poses.gt, aligned, poses.association, options.rpe_delta_s);
}

// Associates the run's poses with `gt` (the run's span, starting at `span_begin` of the full ground
// truth), aligns them and fills the trajectory metrics, gt_from_est and the per-frame errors.
void ScoreTrajectory(const Trajectory& span_gt, const RunData& run, size_t span_begin, const EvalOptions& options,
                     RunEvaluation* out) {
  RunMetrics& m = out->metrics;
  m.align = options.align;
  ScoredPoses poses = AssociatePoses(span_gt, run.trajectory, options, &m);
  const Trajectory& gt = poses.gt;
  const Association& association = poses.association;
  m.associated_frames = static_cast<int>(association.pairs.size());
  if (association.pairs.empty()) {
    m.alignment_note = "no estimated pose matches a ground-truth timestamp";
    return;
  }
  if (options.align == "sim3") ApplySim3Scale(&poses, &m);
  const Trajectory& estimate = poses.estimate;
  const Rigid3 origin = AlignOrigin(gt, estimate, association);
  m.rmse_origin_m = TranslationRmse(gt, estimate, association, origin);
  out->gt_from_est = origin;
  try {
    out->gt_from_est = AlignSe3(gt, estimate, association);
    m.rmse_se3_m = TranslationRmse(gt, estimate, association, out->gt_from_est);
    if (m.path_length_m > 0.0) m.relative_rmse_pct = 100.0 * *m.rmse_se3_m / m.path_length_m;
  } catch (const std::invalid_argument& e) {
    m.alignment_note += std::string(m.alignment_note.empty() ? "" : "; ") + "SE(3) alignment impossible: " + e.what() +
                        "; error along path uses origin alignment";
  }
  for (size_t k = 0; k < association.pairs.size(); ++k) {
    const auto [i, j] = association.pairs[k];
    FrameError fe;
    fe.gt_index = static_cast<int>(static_cast<size_t>(poses.gt_index[k]) + span_begin);  // in the full gt
    fe.estimate_index = j;
    fe.timestamp = gt[i].timestamp;
    fe.gt_world_from_rig = gt[i].world_from_rig;
    fe.gt_position = gt[i].world_from_rig.translation;
    fe.aligned_position = out->gt_from_est * estimate[j].world_from_rig.translation;
    fe.error_m = (fe.gt_position - fe.aligned_position).norm();
    out->frame_errors.push_back(fe);
  }
  m.drift = RelativeDrift(gt, estimate, association);
  m.rpe = ComputeRelativePoseError(gt, estimate, association, options.rpe_delta_s);
  ScoreBodyAligned(poses, options, &m.body);
}

// Lost frames, mean inlier ratio and reprojection error over ok frames, mean time over all frames.
void ScoreFrameRecords(const std::vector<FrameRecord>& frames, RunMetrics* m) {
  int ok = 0;
  double inlier_sum = 0.0, reproj_sum = 0.0, time_sum = 0.0;
  for (const FrameRecord& f : frames) {
    time_sum += f.time_ms;
    if (f.status == FrameStatus::kLost) ++m->lost_frames;
    if (f.status != FrameStatus::kOk) continue;
    ++ok;
    inlier_sum += f.inlier_ratio;
    reproj_sum += f.mean_reproj_error_deg;
  }
  if (ok > 0) {
    m->mean_inlier_ratio = inlier_sum / ok;
    m->mean_reproj_error_deg = reproj_sum / ok;
  }
  if (!frames.empty()) m->mean_time_ms = time_sum / static_cast<double>(frames.size());
}

// Per camera i >= 1: final (latest frame) and mean extrinsic errors, and the largest final ones.
void ScoreExtrinsics(const std::vector<ExtrinsicError>& errors, int num_cameras, RunMetrics* m) {
  if (num_cameras <= 1) return;
  const size_t k = static_cast<size_t>(num_cameras - 1);
  m->final_ext_rotation_deg.assign(k, 0.0);
  m->final_ext_translation_m.assign(k, 0.0);
  m->mean_ext_rotation_deg.assign(k, 0.0);
  m->mean_ext_translation_m.assign(k, 0.0);
  std::vector<int> count(k, 0), last_frame(k, -1);
  for (const ExtrinsicError& e : errors) {
    const size_t c = static_cast<size_t>(e.camera - 1);
    m->mean_ext_rotation_deg[c] += e.rotation_error_deg;
    m->mean_ext_translation_m[c] += e.translation_error_m;
    ++count[c];
    if (e.frame >= last_frame[c]) {
      last_frame[c] = e.frame;
      m->final_ext_rotation_deg[c] = e.rotation_error_deg;
      m->final_ext_translation_m[c] = e.translation_error_m;
    }
  }
  for (size_t c = 0; c < k; ++c) {
    if (count[c] > 0) {
      m->mean_ext_rotation_deg[c] /= count[c];
      m->mean_ext_translation_m[c] /= count[c];
    }
    m->max_final_ext_rotation_deg = std::max(m->max_final_ext_rotation_deg, m->final_ext_rotation_deg[c]);
    m->max_final_ext_translation_m = std::max(m->max_final_ext_translation_m, m->final_ext_translation_m[c]);
  }
}

}  // namespace

RunEvaluation EvaluateRun(const Trajectory& full_gt, const std::vector<Rigid3>& gt_cam_from_rig, const RunData& run,
                          const std::string& label, const EvalOptions& options) {
  const auto [span_begin, span_end] = RunSpan(run, full_gt.size());
  const Trajectory gt(full_gt.begin() + static_cast<long>(span_begin), full_gt.begin() + static_cast<long>(span_end));
  CheckEvalOptions(options);
  RunEvaluation out;
  RunMetrics& m = out.metrics;
  m.label = label;
  m.mode = run.info.value("mode", std::string());
  // GTExt uses no noise set, whatever run.json says.
  if (m.mode != "gt" && run.info.contains("noise_set") && run.info["noise_set"].is_number_integer()) {
    m.noise_set = run.info["noise_set"].get<int>();
  }
  m.gt_frames = static_cast<int>(gt.size());
  m.estimated_frames = static_cast<int>(run.trajectory.size());
  m.path_length_m = GtPathLength(gt);

  ScoreTrajectory(gt, run, span_begin, options, &out);
  ScoreFrameRecords(run.frames, &m);
  out.extrinsic_errors = ExtrinsicErrors(run.extrinsics, gt_cam_from_rig);
  ScoreExtrinsics(out.extrinsic_errors, static_cast<int>(gt_cam_from_rig.size()), &m);
  return out;
}

}  // namespace rovo
