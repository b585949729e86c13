#include "vo/startup_calibration.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "datasets/rig_json.h"
#include "vo/opencv_threads.h"

namespace rovo {

void StartupCalibrationOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("StartupCalibrationOptions.") + what);
  };
  require(shots >= 1, "shots must be >= 1");
  require(shot_spacing >= 1, "shot_spacing must be >= 1");
  require(max_shots >= 1, "max_shots must be >= 1");
  require(min_pair_inliers >= 0, "min_pair_inliers must be >= 0");
  require(ring_passes >= 1, "ring_passes must be >= 1");
  require(later_orb_features >= 10, "later_orb_features must be >= 10");
  require(later_orb_fast_threshold >= 0, "later_orb_fast_threshold must be >= 0");
  require(later_view_focal_px >= 0.0, "later_view_focal_px must be >= 0");
  require(max_pass_change_deg >= 0.0, "max_pass_change_deg must be >= 0");
  require(placements >= 1, "placements must be >= 1");
  require(placement_jitter_deg >= 0.0, "placement_jitter_deg must be >= 0");
  require(rescue_orb_features >= 10, "rescue_orb_features must be >= 10");
  require(rescue_orb_fast_threshold >= 0, "rescue_orb_fast_threshold must be >= 0");
  ring.Check();
}
namespace {

double LargestChangeDeg(const std::vector<Rigid3>& a, const std::vector<Rigid3>& b) {
  double worst = 0.0;
  for (size_t j = 0; j < a.size(); ++j) worst = std::max(worst, RotationDistanceDeg(a[j].rotation, b[j].rotation));
  return worst;
}

void PrintRing(const RingCalibrationReport& ring) {
  std::fprintf(stderr, "vo online: start-up ring calibration over %d shot(s):", ring.frames);
  for (const RingPairEstimate& p : ring.pairs) {
    std::fprintf(stderr, " %d-%d %d/%d inliers, moved %.2f deg;", p.camera_a, p.camera_b, p.inliers, p.matches,
                 p.change_deg);
  }
  std::fprintf(stderr, " loop error %.3f deg", ring.loop_error_deg);
  if (ring.angle_scale != 1.0) std::fprintf(stderr, ", lens angle scale %.4f", ring.angle_scale);
  std::fprintf(stderr, "%s%s\n", ring.converged ? "" : ": FAILED, ", ring.reason.c_str());
}

RingCalibrationReport RunRingPass(const Rig& rig, const std::vector<Rigid3>& cam_from_rig,
                                  const std::vector<std::vector<cv::Mat>>& shots,
                                  const std::vector<cv::Mat>& static_masks, const RingCalibrationOptions& options) {
  RingCalibrator ring(rig.WithExtrinsics(cam_from_rig), static_masks, options);
  for (const auto& images : shots) ring.AddFrame(images);
  return ring.Solve();
}

// The ring options of the passes after the first (their views are placed by a previous result).
RingCalibrationOptions LaterPassOptions(const StartupCalibrationOptions& options) {
  RingCalibrationOptions aligned = options.ring;
  aligned.refine_matches = options.refine_second_pass;
  aligned.orb_features = std::max(aligned.orb_features, options.later_orb_features);
  aligned.orb_fast_threshold = std::min(aligned.orb_fast_threshold, options.later_orb_fast_threshold);
  aligned.dense_view_focal_px = std::max(aligned.dense_view_focal_px, options.later_view_focal_px);
  return aligned;
}

// Placement k's turn of camera j's view placement: placement_jitter_deg about a fixed axis.
Eigen::Quaterniond PlacementTurn(int k, int j, double angle_deg) {
  const double a = 2.399963 * (7 * k + 3 * j + 1);  // golden-angle steps: axes spread over the sphere
  const Eigen::Vector3d axis = Eigen::Vector3d(std::cos(a), std::sin(a), std::cos(1.7 * a)).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis));
}

// Rotation nearest (Frobenius) to a sum of rotation matrices: their chordal mean.
Eigen::Quaterniond ChordalMean(const Eigen::Matrix3d& sum) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0.0) u.col(2) *= -1.0;
  return Eigen::Quaterniond(u * svd.matrixV().transpose()).normalized();
}

// The last ring pass (`last`, converged) again from options.placements - 1 view placements turned by
// placement_jitter_deg, and the converged results within max_pass_change_deg of it averaged:
// cam_j_from_cam0 by their chordal mean (camera 0 kept), the angle scale by its mean. `spread_deg`
// receives the largest angle of a placement's cam_j_from_cam0 from the mean. The pairs, loop error
// and uncertainty of the result stay those of `last`.
RingCalibrationReport AverageOverPlacements(const Rig& rig, RingCalibrationReport last,
                                            const std::vector<std::vector<cv::Mat>>& shots,
                                            const std::vector<cv::Mat>& static_masks,
                                            const StartupCalibrationOptions& options, int* averaged,
                                            double* spread_deg) {
  const RingCalibrationOptions pass_options = options.ring_passes > 1 ? LaterPassOptions(options) : options.ring;
  const size_t n = last.cam_from_rig.size();
  auto camj_from_cam0 = [](const RingCalibrationReport& r, size_t j) {
    return r.cam_from_rig[j].rotation * r.cam_from_rig[0].rotation.inverse();
  };
  std::vector<RingCalibrationReport> results = {last};
  for (int k = 1; k < options.placements; ++k) {
    std::vector<Rigid3> placed = last.cam_from_rig;
    for (size_t j = 0; j < n; ++j) {
      // Turned about the camera's own centre: the baselines stay the rig's.
      const Eigen::Quaterniond turned =
          PlacementTurn(k, static_cast<int>(j), options.placement_jitter_deg) * placed[j].rotation;
      placed[j] = Rigid3(turned, -(turned * CameraPositionInRig(placed[j])));
    }
    RingCalibrationReport r = RunRingPass(rig, placed, shots, static_masks, pass_options);
    if (!r.converged) continue;
    // Like a later pass, a placement must confirm the result (max_pass_change_deg) and its lens
    // decision (the angle scale kept or left at 1), else it is left out.
    double change = 0.0;
    for (size_t j = 1; j < n; ++j)
      change = std::max(change, RotationDistanceDeg(camj_from_cam0(r, j), camj_from_cam0(last, j)));
    const bool same_lenses = (r.angle_scale == 1.0) == (last.angle_scale == 1.0);
    if (change <= options.max_pass_change_deg && same_lenses) results.push_back(std::move(r));
  }
  double scale_sum = 0.0;
  for (const RingCalibrationReport& r : results) scale_sum += r.angle_scale;
  last.angle_scale = scale_sum / static_cast<double>(results.size());
  *spread_deg = 0.0;
  for (size_t j = 1; j < n; ++j) {
    // Each placement keeps its own (turned) camera 0 as the gauge, so only the relative poses
    // cam_j_from_cam0 are comparable: their rotations and translations are averaged and put back
    // behind `last`'s camera 0.
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    Eigen::Vector3d translation_sum = Eigen::Vector3d::Zero();
    for (const RingCalibrationReport& r : results) {
      sum += camj_from_cam0(r, j).toRotationMatrix();
      translation_sum += (r.cam_from_rig[j] * r.cam_from_rig[0].Inverse()).translation;
    }
    const Eigen::Quaterniond mean = ChordalMean(sum);
    for (const RingCalibrationReport& r : results) {
      *spread_deg = std::max(*spread_deg, RotationDistanceDeg(camj_from_cam0(r, j), mean));
    }
    const Rigid3 camj_from_cam0_mean(mean, translation_sum / static_cast<double>(results.size()));
    last.cam_from_rig[j] = camj_from_cam0_mean * last.cam_from_rig[0];
  }
  *averaged = static_cast<int>(results.size());
  return last;
}

// The ring stage, then again with the overlap views placed by the previous result: where the given
// extrinsics were far off, the first pass saw the overlaps off-centre and rotated. Each later pass
// must confirm the one before it (max_pass_change_deg), else the result depends on where the views
// were placed and is not trusted.
RingCalibrationReport RunRingPasses(const Rig& rig, const std::vector<Rigid3>& cam_from_rig,
                                    const std::vector<std::vector<cv::Mat>>& shots,
                                    const std::vector<cv::Mat>& static_masks, const StartupCalibrationOptions& options,
                                    bool quiet) {
  RingCalibrationReport last = RunRingPass(rig, cam_from_rig, shots, static_masks, options.ring);
  if (!quiet) PrintRing(last);
  const RingCalibrationOptions aligned = LaterPassOptions(options);
  for (int pass = 2; pass <= options.ring_passes && last.converged; ++pass) {
    RingCalibrationReport next = RunRingPass(rig, last.cam_from_rig, shots, static_masks, aligned);
    if (!quiet) PrintRing(next);
    if (!next.converged) return next;
    const double change = LargestChangeDeg(last.cam_from_rig, next.cam_from_rig);
    if (change > options.max_pass_change_deg) {
      next.converged = false;
      next.reason = "pass " + std::to_string(pass) +
                    ", with the overlap views placed by the pass before, moved a camera " + std::to_string(change) +
                    " deg (> " + std::to_string(options.max_pass_change_deg) +
                    "): the overlaps do not determine the extrinsics";
    }
    last = std::move(next);
  }
  return last;
}

// The ring passes, and when they fail and options.rescue is set, the rescue passes; a converged last
// pass is averaged over options.placements view placements.
RingCalibrationReport RunRingStage(const Rig& rig, const std::vector<Rigid3>& cam_from_rig,
                                   const std::vector<std::vector<cv::Mat>>& shots,
                                   const std::vector<cv::Mat>& static_masks, const StartupCalibrationOptions& options,
                                   bool quiet, StartupCalibrationReport* report) {
  StartupCalibrationOptions used = options;
  RingCalibrationReport ring = RunRingPasses(rig, cam_from_rig, shots, static_masks, used, quiet);
  if (!ring.converged && options.rescue) {
    if (!quiet)
      std::fprintf(stderr, "vo online: start-up ring calibration failed; rescue with more and weaker features\n");
    used.ring.orb_features = options.rescue_orb_features;
    used.ring.orb_fast_threshold = options.rescue_orb_fast_threshold;
    report->rescued = true;
    report->ring_failure = ring.reason;
    ring = RunRingPasses(rig, cam_from_rig, shots, static_masks, used, quiet);
  }
  if (ring.converged && options.placements > 1) {
    ring = AverageOverPlacements(rig, std::move(ring), shots, static_masks, used, &report->placements_averaged,
                                 &report->placement_spread_deg);
    if (!quiet) {
      std::fprintf(stderr, "vo online: start-up ring calibration averaged over %d view placements (spread %.3f deg)\n",
                   report->placements_averaged, report->placement_spread_deg);
    }
  }
  return ring;
}

}  // namespace

nlohmann::json StartupCalibrationReport::ToJson() const {
  nlohmann::json pairs = nlohmann::json::array();
  for (const RingPairEstimate& p : ring.pairs) {
    pairs.push_back({{"cameras", {p.camera_a, p.camera_b}},
                     {"matches", p.matches},
                     {"inliers", p.inliers},
                     {"usable", p.usable},
                     {"change_deg", p.change_deg},
                     {"median_residual_deg_given", p.median_residual_deg_given},
                     {"median_residual_deg_result", p.median_residual_deg_result}});
  }
  nlohmann::json extrinsics = nlohmann::json::array();
  for (const Rigid3& x : cam_from_rig) extrinsics.push_back(Rigid3ToJson(x));
  return {{"converged", converged},
          {"status", status},
          {"shots", shots},
          {"first_shots", first_shots},
          {"more_shots_reason", more_shots_reason},
          {"ring",
           {{"converged", ring.converged},
            {"reason", ring.reason},
            {"loop_error_deg", ring.loop_error_deg},
            {"angle_scale", ring.angle_scale},
            {"common_turn_deg", ring.common_turn_deg},
            {"common_turn_sigma_deg", ring.common_turn_sigma_deg},
            {"centres_turned", ring.centres_turned},
            {"centres_known", ring.centres_known},
            {"uncertainty_deg", ring.uncertainty_deg},
            {"rescued", rescued},
            {"failure_before_rescue", ring_failure},
            {"placements_averaged", placements_averaged},
            {"placement_spread_deg", placement_spread_deg},
            {"pairs", pairs}}},
          {"refinement_rounds", nlohmann::json::array()},  // kept in the format: always empty
          {"cam_from_rig", extrinsics}};
}

namespace {

// Loads shots k_begin .. k_end - 1 (frame first_frame + k * spacing, below end_frame) into `shots`
// and their frames into `frames`, skipping a frame without every camera's image.
void LoadShots(const std::function<LoadedFrame(int)>& load, int first_frame, int end_frame, int spacing, int k_begin,
               int k_end, bool quiet, std::vector<std::vector<cv::Mat>>* shots, std::vector<int>* frames) {
  for (int k = k_begin; k < k_end; ++k) {
    const int frame = first_frame + k * std::max(1, spacing);
    if (frame >= end_frame) break;
    LoadedFrame loaded = load(frame);
    if (!loaded.missing_cameras.empty()) {
      if (!quiet)
        std::fprintf(stderr, "vo online: start-up calibration skips frame %d: %s\n", frame, loaded.problems.c_str());
      continue;
    }
    shots->push_back(std::move(loaded.images));
    frames->push_back(frame);
  }
}

// Why a ring stage's result asks for more shots (StartupCalibrationOptions::min_pair_inliers), or "".
std::string PoorOverlaps(const RingCalibrationReport& ring, int min_pair_inliers) {
  if (!ring.converged) return "the ring stage failed (" + ring.reason + ")";
  const RingPairEstimate* weakest = nullptr;
  for (const RingPairEstimate& p : ring.pairs) {
    if (weakest == nullptr || p.inliers < weakest->inliers) weakest = &p;
  }
  if (weakest == nullptr || weakest->inliers >= min_pair_inliers) return "";
  return "pair " + std::to_string(weakest->camera_a) + "-" + std::to_string(weakest->camera_b) + " kept " +
         std::to_string(weakest->inliers) + " inliers (< " + std::to_string(min_pair_inliers) + ")";
}

// The ring stage on `shots` (frames `frames`), written into a fresh report.
StartupCalibrationReport RingStageReport(const Rig& rig, const std::vector<Rigid3>& cam_from_rig,
                                         const std::vector<std::vector<cv::Mat>>& shots, std::vector<int> frames,
                                         const std::vector<cv::Mat>& static_masks,
                                         const StartupCalibrationOptions& options, bool quiet) {
  StartupCalibrationReport report;
  report.cam_from_rig = cam_from_rig;
  report.shots = std::move(frames);
  report.ring = RunRingStage(rig, cam_from_rig, shots, static_masks, options, quiet, &report);
  if (!report.ring.converged) {
    report.status = "ring stage failed (" + report.ring.reason + "); starting extrinsics kept";
    return report;
  }
  report.cam_from_rig = report.ring.cam_from_rig;
  report.converged = true;
  report.status = "converged";
  return report;
}

}  // namespace

StartupCalibrationReport CalibrateAtStartup(const Rig& rig, const std::vector<Rigid3>& cam_from_rig,
                                            const std::function<LoadedFrame(int)>& load, int first_frame, int end_frame,
                                            const std::vector<cv::Mat>& static_masks,
                                            const StartupCalibrationOptions& options, bool quiet) {
  options.Check();
  const ScopedOpenCvThreads serial_opencv;  // another run's front-end may be in the same process
  std::vector<std::vector<cv::Mat>> shots;
  std::vector<int> frames;
  LoadShots(load, first_frame, end_frame, options.shot_spacing, 0, options.shots, quiet, &shots, &frames);
  if (frames.empty()) {
    StartupCalibrationReport report;
    report.cam_from_rig = cam_from_rig;
    report.status = "no shot with every camera's image";
    return report;
  }
  StartupCalibrationReport report = RingStageReport(rig, cam_from_rig, shots, frames, static_masks, options, quiet);
  const std::string poor = PoorOverlaps(report.ring, options.min_pair_inliers);
  if (poor.empty() || options.max_shots <= options.shots) return report;
  const size_t first_count = frames.size();
  LoadShots(load, first_frame, end_frame, options.shot_spacing, options.shots, options.max_shots, quiet, &shots,
            &frames);
  if (frames.size() == first_count) {
    report.more_shots_reason = poor + "; no frame left for another shot";
    return report;
  }
  if (!quiet) std::fprintf(stderr, "vo online: start-up: %s; again on %zu shots\n", poor.c_str(), frames.size());
  StartupCalibrationReport more = RingStageReport(rig, cam_from_rig, shots, frames, static_masks, options, quiet);
  more.first_shots = report.shots;
  more.more_shots_reason = poor;
  if (more.converged || !report.converged) return more;
  // The first attempt converged and the one on more shots did not: the first result stands.
  report.more_shots_reason = poor + "; on " + std::to_string(frames.size()) + " shots the ring stage failed (" +
                             more.ring.reason + "), so the first attempt's result stands";
  return report;
}

}  // namespace rovo
