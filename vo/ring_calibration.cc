#include "vo/ring_calibration.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "vo/ring_model.h"
#include "vo/ring_views.h"

namespace rovo {
namespace {

using ring::AverageRing;
using ring::ChainFromCameraZero;
using ring::FitCommonRotation;
using ring::kDeg;
using ring::LoopClosureErrorDeg;
using ring::MedianResidualDeg;
using ring::OverlapPair;
using ring::PairBaselineInRig;
using ring::PairDisagreementDeg;
using ring::RefineRing;
using ring::ReselectInliers;
using ring::RingModel;
using ring::RingResidual;
using ring::RingUncertaintyDeg;

// " (pairs: a-b inliers/matches ...)" for a failure message.
std::string PairCounts(const std::vector<RingPairEstimate>& pairs) {
  std::string out = " (pairs:";
  for (const RingPairEstimate& p : pairs) {
    out += " " + std::to_string(p.camera_a) + "-" + std::to_string(p.camera_b) + " " + std::to_string(p.inliers) + "/" +
           std::to_string(p.matches);
  }
  return out + " inliers/matches)";
}

struct JointSolution {
  RingModel model;
  std::vector<std::vector<int>> inliers;  // per pair
  int total_inliers = -1;
};

// The joint refinement (RefineRing) from `start` (cam_j_from_rig, kappa 0) on the pairs' own inliers
// (the angle scale estimated when `estimate_scale`),
// then `joint_rounds` times: inliers re-selected from every match by the joint solution, refined again.
JointSolution SolveJoint(const std::vector<OverlapPair>& pairs, const std::vector<std::vector<int>>& pair_inliers,
                         const Rig& rig, const std::vector<Eigen::Quaterniond>& start, const RingCalibrationOptions& o,
                         bool estimate_scale) {
  const double scale = o.inlier_threshold_deg * kDeg;
  const double angle_scale_sigma = estimate_scale ? o.angle_scale_sigma : 0.0;
  JointSolution s;
  s.inliers = pair_inliers;
  s.model.rotations = start;
  s.model = RefineRing(pairs, s.inliers, rig, s.model, scale, o.prior_sigma_deg, angle_scale_sigma);
  for (int round = 0; round < o.joint_rounds; ++round) {
    s.inliers = ReselectInliers(pairs, rig, s.model, scale);
    s.model = RefineRing(pairs, s.inliers, rig, s.model, scale, o.prior_sigma_deg, angle_scale_sigma);
  }
  s.inliers = ReselectInliers(pairs, rig, s.model, scale);
  s.total_inliers = 0;
  for (const auto& v : s.inliers) s.total_inliers += static_cast<int>(v.size());
  return s;
}

// The joint solution from each of `starts` (cam_j_from_rig) with the most inliers, the angle scale
// estimated when `estimate_scale`.
JointSolution BestJointSolution(const std::vector<OverlapPair>& pairs,
                                const std::vector<std::vector<int>>& pair_inliers, const Rig& rig,
                                const std::vector<std::vector<Eigen::Quaterniond>>& starts,
                                const RingCalibrationOptions& o, bool estimate_scale) {
  // The starts are solved in parallel, the first with the most inliers wins (as in order).
  std::vector<JointSolution> candidates(starts.size());
  tbb::parallel_for(size_t{0}, starts.size(), [&](size_t k) {
    candidates[k] = SolveJoint(pairs, pair_inliers, rig, starts[k], o, estimate_scale);
  });
  JointSolution best;
  for (JointSolution& candidate : candidates) {
    if (candidate.total_inliers > best.total_inliers) best = std::move(candidate);
  }
  return best;
}

// Starting points (cam_j_from_cam0) of the joint refinement: the pairs averaged around the ring
// (AverageRing from the chain `chained`) and, for a closed ring, the chain that leaves out each pair
// in turn. The pairs' own rotations are biased by the given baseline directions (off by the draw), so
// one start can fall into another minimum of the joint problem on near-field scenes.
std::vector<std::vector<Eigen::Quaterniond>> JointStarts(const std::vector<RingPairEstimate>& pairs, int num_cams,
                                                         const std::vector<Eigen::Quaterniond>& chained) {
  std::vector<std::vector<Eigen::Quaterniond>> starts = {AverageRing(pairs, num_cams, chained)};
  for (size_t left_out = 0; left_out < pairs.size(); ++left_out) {
    if (!pairs[left_out].usable) continue;
    std::vector<RingPairEstimate> others = pairs;
    others[left_out].usable = false;
    std::vector<Eigen::Quaterniond> chain;
    if (ChainFromCameraZero(others, num_cams, &chain)) starts.push_back(chain);
  }
  return starts;
}

// Set-up: every pair's own rotation from its matches (`inliers`: each pair's), the pairs chained
// from camera 0 (`chained`, cam_j_from_cam0) and the loop check. False, with report->reason, when
// the pairs cannot start the joint refinement.
bool SetUpRing(const std::vector<OverlapPair>& pairs, const Rig& rig, const RingCalibrationOptions& o,
               RingCalibrationReport* report, std::vector<std::vector<int>>* inliers,
               std::vector<Eigen::Quaterniond>* chained) {
  const int n = rig.NumCameras();
  inliers->assign(pairs.size(), {});
  for (size_t k = 0; k < pairs.size(); ++k)
    report->pairs.push_back(ring::EstimatePair(pairs[k], rig, o, &(*inliers)[k]));
  if (!ChainFromCameraZero(report->pairs, n, chained)) {
    report->reason = "too few overlap matches to connect every camera to camera 0" + PairCounts(report->pairs);
    return false;
  }
  report->loop_error_deg = LoopClosureErrorDeg(report->pairs, n);
  if (o.require_closed_ring && report->loop_error_deg < 0.0 && n >= 3 && static_cast<int>(report->pairs.size()) == n) {
    report->reason = "the ring is open (a pair has too few overlap matches), so nothing checks the chained pairs" +
                     PairCounts(report->pairs);
    return false;
  }
  if (report->loop_error_deg > o.max_loop_error_deg) {
    report->reason = "the pair rotations do not close the ring (loop error " + std::to_string(report->loop_error_deg) +
                     " deg > " + std::to_string(o.max_loop_error_deg) + ")";
    return false;
  }
  return true;
}

// Solve: the joint solution with the most inliers over the starts (JointStarts from `chained`), the
// lenses as given; with the angle scale free instead when a closed ring's estimate of it matters.
JointSolution SolveRing(const std::vector<OverlapPair>& pairs, const std::vector<std::vector<int>>& inliers,
                        const Rig& rig, const RingCalibrationOptions& o, const RingCalibrationReport& report,
                        const std::vector<Eigen::Quaterniond>& chained) {
  const Eigen::Quaterniond cam0_from_rig = rig.cameras[0].cam_from_rig.rotation;
  std::vector<std::vector<Eigen::Quaterniond>> starts = JointStarts(report.pairs, rig.NumCameras(), chained);
  for (auto& start : starts) {
    for (auto& q : start) q = (q * cam0_from_rig).normalized();  // cam_j_from_rig
  }
  JointSolution best = BestJointSolution(pairs, inliers, rig, starts, o, false);  // the lenses as given
  if (o.angle_scale_sigma > 0.0 && report.loop_error_deg >= 0.0) {                // an open ring does not see the scale
    // The scale refined from that solution says whether it matters; only then are all starts solved
    // again with it free (refined from one solution alone, the draws of real shots agree less).
    const JointSolution probe = SolveJoint(pairs, inliers, rig, best.model.rotations, o, true);
    if (std::abs(probe.model.kappa) >= o.min_angle_scale_change) {
      JointSolution scaled = BestJointSolution(pairs, inliers, rig, starts, o, true);
      if (std::abs(scaled.model.kappa) >= o.min_angle_scale_change) best = std::move(scaled);
    }
  }
  return best;
}

// Assessment of the joint solution `best`: its uncertainty, each pair's residuals under the given
// extrinsics and under the result, and the pairs' disagreement with it. False, with report->reason,
// when it does not converge.
bool AssessRing(const std::vector<OverlapPair>& pairs, const Rig& rig, const RingCalibrationOptions& o,
                const JointSolution& best, RingCalibrationReport* report) {
  const RingModel& model = best.model;
  const std::vector<std::vector<int>>& inliers = best.inliers;
  report->angle_scale = 1.0 + model.kappa;
  const double scale = o.inlier_threshold_deg * kDeg;
  RingModel given;
  for (const RigCamera& c : rig.cameras) given.rotations.push_back(c.cam_from_rig.rotation);
  report->uncertainty_deg = RingUncertaintyDeg(pairs, inliers, rig, model, model.kappa != 0.0);
  for (size_t k = 0; k < pairs.size(); ++k) {
    RingPairEstimate& p = report->pairs[k];
    if (!p.usable) continue;
    p.inliers = static_cast<int>(inliers[k].size());
    p.median_residual_deg_given = MedianResidualDeg(pairs[k], inliers[k], rig, given);
    p.median_residual_deg_result = MedianResidualDeg(pairs[k], inliers[k], rig, model);
    report->max_pair_disagreement_deg =
        std::max(report->max_pair_disagreement_deg, PairDisagreementDeg(pairs[k], inliers[k], rig, model, scale));
  }
  if (report->uncertainty_deg < 0.0 || report->uncertainty_deg > o.max_uncertainty_deg) {
    report->reason = "the overlaps leave a camera's rotation uncertain (one sigma " +
                     std::to_string(report->uncertainty_deg) + " deg > " + std::to_string(o.max_uncertainty_deg) + ")";
    return false;
  }
  if (report->max_pair_disagreement_deg > o.max_pair_disagreement_deg) {
    report->reason = "a pair's own rotation is " + std::to_string(report->max_pair_disagreement_deg) +
                     " deg from the ring solution (> " + std::to_string(o.max_pair_disagreement_deg) + ")";
    return false;
  }
  return true;
}

// Write-back of the converged solution `best` into report->cam_from_rig. Camera 0 stays the gauge.
// The joint solution also turned the cameras together against their centres (model.rotations[0]
// against cam0_from_rig); with camera 0 kept, the centres turn by the inverse about camera 0's centre
// instead, so that every baseline keeps the direction the solution gives it in each camera
// (turn_centres; false: the centres stay the given ones).
void WriteBackRing(const std::vector<OverlapPair>& pairs, const Rig& rig, const RingCalibrationOptions& o,
                   const JointSolution& best, RingCalibrationReport* report) {
  const RingModel& model = best.model;
  const int n = rig.NumCameras();
  const Eigen::Quaterniond cam0_from_rig = rig.cameras[0].cam_from_rig.rotation;
  report->common_turn_deg = RotationDistanceDeg(model.rotations[0], cam0_from_rig);
  report->common_turn_sigma_deg = RingUncertaintyDeg(pairs, best.inliers, rig, model, model.kappa != 0.0, true);
  report->centres_turned = o.turn_centres;
  report->centres_known = o.turn_centres && report->common_turn_sigma_deg >= 0.0 &&
                          report->common_turn_sigma_deg <= o.max_common_turn_sigma_deg;
  const Eigen::Quaterniond rig_turn = report->centres_turned
                                          ? (cam0_from_rig.inverse() * model.rotations[0]).normalized()
                                          : Eigen::Quaterniond::Identity();
  const Eigen::Vector3d centre0 = CameraPositionInRig(rig.cameras[0].cam_from_rig);
  for (int j = 1; j < n; ++j) {
    const Eigen::Vector3d centre = centre0 + rig_turn * (CameraPositionInRig(rig.cameras[j].cam_from_rig) - centre0);
    const Eigen::Quaterniond camj_from_rig =
        (model.rotations[j] * model.rotations[0].inverse() * cam0_from_rig).normalized();
    report->cam_from_rig[j] = Rigid3(camj_from_rig, -(camj_from_rig * centre));
  }
}

}  // namespace

void RingCalibrationOptions::Check() const {
  if (!(view_half_width_deg > 0.0 && view_half_width_deg < 90.0) ||
      !(view_half_height_deg > 0.0 && view_half_height_deg < 90.0)) {
    throw std::invalid_argument("RingCalibrationOptions: view extents must be in (0, 90) deg");
  }
  if (!(max_ratio > 0.0 && max_ratio <= 1.0))
    throw std::invalid_argument("RingCalibrationOptions: max_ratio in (0, 1]");
  if (!(inlier_threshold_deg > 0.0) || ransac_iterations < 1 || min_inliers < 5 || orb_features < 10) {
    throw std::invalid_argument(
        "RingCalibrationOptions: threshold, iterations, min_inliers or orb_features out of range");
  }
}

struct RingCalibrator::Impl {
  Rig rig;
  RingCalibrationOptions options;
  std::vector<OverlapPair> pairs;
  int frames = 0;
};

RingCalibrator::RingCalibrator(const Rig& rig, const std::vector<cv::Mat>& static_masks,
                               const RingCalibrationOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  if (!static_masks.empty() && static_cast<int>(static_masks.size()) != rig.NumCameras()) {
    throw std::invalid_argument("ring calibration: " + std::to_string(static_masks.size()) + " masks for " +
                                std::to_string(rig.NumCameras()) + " cameras");
  }
  impl_->rig = rig;
  impl_->options = options;
  const std::vector<std::pair<int, int>> ring_pairs = RingPairs(rig);
  std::vector<std::optional<OverlapPair>> made(ring_pairs.size());  // the pairs' views in parallel
  tbb::parallel_for(size_t{0}, ring_pairs.size(), [&](size_t k) {
    made[k].emplace(ring::MakeOverlapPair(rig, ring_pairs[k].first, ring_pairs[k].second, static_masks, options));
  });
  for (std::optional<OverlapPair>& p : made) impl_->pairs.push_back(std::move(*p));
}

RingCalibrator::~RingCalibrator() = default;

const cv::Mat& RingCalibrator::overlap_view(int pair_index, int side) const {
  return impl_->pairs.at(pair_index).last_view[side];
}

void RingCalibrator::AddFrame(const std::vector<cv::Mat>& images) {
  const Rig& rig = impl_->rig;
  const RingCalibrationOptions& o = impl_->options;
  if (static_cast<int>(images.size()) != rig.NumCameras()) {
    throw std::invalid_argument("ring calibration: " + std::to_string(images.size()) + " images for " +
                                std::to_string(rig.NumCameras()) + " cameras");
  }
  std::vector<cv::Mat> gray(images.size());
  for (size_t j = 0; j < images.size(); ++j) gray[j] = ring::Gray(images[j]);
  // The pairs in parallel, each with a detector of its own (each pools into its own bearings).
  tbb::parallel_for(size_t{0}, impl_->pairs.size(), [&](size_t k) {
    auto orb = cv::ORB::create(o.orb_features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, o.orb_fast_threshold);
    ring::MatchOverlap(gray, *orb, o, &impl_->pairs[k]);
  });
  ++impl_->frames;
}

std::vector<RingPairFit> RingCalibrator::Fit(const std::vector<Rigid3>& cam_from_rig, double angle_scale) const {
  const Rig& rig = impl_->rig;
  if (static_cast<int>(cam_from_rig.size()) != rig.NumCameras()) {
    throw std::invalid_argument("RingCalibrator::Fit: " + std::to_string(cam_from_rig.size()) + " extrinsics for " +
                                std::to_string(rig.NumCameras()) + " cameras");
  }
  RingModel model;
  for (const Rigid3& t : cam_from_rig) model.rotations.push_back(t.rotation.normalized());
  model.kappa = angle_scale - 1.0;
  model = FitCommonRotation(impl_->pairs, rig, model, impl_->options.inlier_threshold_deg * kDeg);
  const std::vector<std::vector<int>> inliers =
      ReselectInliers(impl_->pairs, rig, model, impl_->options.inlier_threshold_deg * kDeg);
  std::vector<RingPairFit> fits;
  for (size_t k = 0; k < impl_->pairs.size(); ++k) {
    const OverlapPair& p = impl_->pairs[k];
    RingPairFit f;
    f.camera_a = p.a;
    f.camera_b = p.b;
    f.matches = static_cast<int>(p.bearings_a.size());
    f.inliers = static_cast<int>(inliers[k].size());
    f.median_residual_deg = MedianResidualDeg(p, inliers[k], rig, model);
    const Eigen::Vector3d baseline_in_rig = PairBaselineInRig(p, rig);
    for (size_t i = 0; i < p.bearings_a.size(); ++i) {
      const double r = RingResidual(p, static_cast<int>(i), baseline_in_rig, model);
      f.residuals_deg.push_back(std::asin(std::min(1.0, r)) / kDeg);
    }
    fits.push_back(f);
  }
  return fits;
}

// Set-up (the pairs and their chain), solve (the joint refinement) and write-back (the extrinsics),
// as a bundle adjuster does; the report says how far it got and why it stopped.
RingCalibrationReport RingCalibrator::Solve() const {
  const Rig& rig = impl_->rig;
  const RingCalibrationOptions& o = impl_->options;
  RingCalibrationReport report;
  report.frames = impl_->frames;
  report.cam_from_rig = rig.Extrinsics();
  std::vector<std::vector<int>> inliers;
  std::vector<Eigen::Quaterniond> chained;
  if (!SetUpRing(impl_->pairs, rig, o, &report, &inliers, &chained)) return report;
  const JointSolution best = SolveRing(impl_->pairs, inliers, rig, o, report, chained);
  if (!AssessRing(impl_->pairs, rig, o, best, &report)) return report;
  WriteBackRing(impl_->pairs, rig, o, best, &report);
  report.converged = true;
  return report;
}

}  // namespace rovo
