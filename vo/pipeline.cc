#include "vo/pipeline.h"

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "vo/image_loader.h"
#include "vo/startup_calibration.h"
#include "rovo/version.h"

#include <opencv2/imgcodecs.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <chrono>
#include <cmath>
#include <future>
#include <stdexcept>

namespace rovo {
namespace {

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Rigid motion scaled along its screw-free approximation: rotation angle and translation times s.
Rigid3 ScaleMotion(const Rigid3& motion, double s) {
  return Rigid3::FromAxisAngle(motion.AxisAngle() * s, motion.translation * s);
}

}  // namespace

ExtrinsicsMode ExtrinsicsModeFromName(const std::string& name) {
  if (name == "gt") return ExtrinsicsMode::kGroundTruth;
  if (name == "noisy") return ExtrinsicsMode::kNoisy;
  if (name == "online") return ExtrinsicsMode::kOnline;
  throw std::invalid_argument("extrinsics mode: expected 'gt', 'noisy' or 'online', got '" + name + "'");
}

std::string ExtrinsicsModeName(ExtrinsicsMode mode) {
  switch (mode) {
    case ExtrinsicsMode::kGroundTruth: return "gt";
    case ExtrinsicsMode::kNoisy: return "noisy";
    case ExtrinsicsMode::kOnline: return "online";
  }
  return "gt";
}

void BackendOptions::Check() const {
  ransac.Check();
  refine.Check();
  ba.Check();
  keyframes.Check();
  if (window_keyframes < 2) throw std::invalid_argument("BackendOptions.window_keyframes must be >= 2");
  if (min_correspondences < 3) throw std::invalid_argument("BackendOptions.min_correspondences must be >= 3");
  if (max_unseen_frames < 0) throw std::invalid_argument("BackendOptions.max_unseen_frames must be >= 0");
  if (!(online_max_error_deg > 0.0)) throw std::invalid_argument("BackendOptions.online_max_error_deg must be > 0");
  if (online_settle_frames < 0) throw std::invalid_argument("BackendOptions.online_settle_frames must be >= 0");
}

VoBackend::VoBackend(const std::vector<Rigid3>& initial_cam_from_rig, const Rigid3& initial_world_from_rig,
                     const BackendOptions& options)
    : options_(options),
      cam_from_rig_(initial_cam_from_rig),
      baseline_lengths_(RingBaselineLengths(initial_cam_from_rig)),
      initial_rig_from_world_(initial_world_from_rig.Inverse()) {
  options_.Check();
  if (cam_from_rig_.empty()) throw std::invalid_argument("VoBackend: the rig has no cameras");
}

std::vector<Rigid3> VoBackend::WorldFromCam(const Rigid3& rig_from_world) const {
  std::vector<Rigid3> out;
  const Rigid3 world_from_rig = rig_from_world.Inverse();
  for (const Rigid3& c : cam_from_rig_) out.push_back(world_from_rig * c.Inverse());
  return out;
}

Rigid3 VoBackend::PredictRigFromWorld(int frame) const {
  if (last_good_frame_ < 0) return initial_rig_from_world_;
  const Rigid3 world_from_last = rig_from_world_.at(last_good_frame_).Inverse();
  if (previous_good_frame_ < 0 || !rig_from_world_.count(previous_good_frame_)) return world_from_last.Inverse();
  const Rigid3 world_from_prev = rig_from_world_.at(previous_good_frame_).Inverse();
  // Constant velocity in the rig frame: per-frame motion prev_from_last / gap, applied forward.
  const Rigid3 prev_from_last = world_from_prev.Inverse() * world_from_last;
  const double gap = last_good_frame_ - previous_good_frame_;
  const Rigid3 per_frame = ScaleMotion(prev_from_last, 1.0 / gap);
  const Rigid3 world_from_pred = world_from_last * ScaleMotion(per_frame, frame - last_good_frame_);
  return world_from_pred.Inverse();
}

void VoBackend::AddObservations(int frame, const FrontendFrame& frontend,
                                const std::vector<std::vector<char>>* rejected) {
  for (size_t j = 0; j < frontend.features_per_camera.size(); ++j) {
    const auto& features = frontend.features_per_camera[j];
    for (size_t i = 0; i < features.size(); ++i) {
      if (rejected && (*rejected)[j][i]) continue;
      map_.AddObservation(features[i].track_id, {frame, static_cast<int>(j), features[i].bearing_in_cam});
    }
  }
}

bool VoBackend::Initialise(int frame, const Rigid3& rig_from_world, BackendFrameResult* result) {
  const std::vector<Rigid3> world_from_cam = WorldFromCam(rig_from_world);
  int created = 0;
  for (auto& [id, lm] : map_.landmarks()) {
    if (lm.NumCamerasAtFrame(frame) < 2) continue;
    std::vector<Ray> rays;
    for (const Observation& o : lm.observations) {
      if (o.frame != frame) continue;
      rays.push_back({world_from_cam[o.camera].translation, world_from_cam[o.camera].rotation * o.bearing_in_cam});
    }
    if (auto point = TriangulateRays(rays, options_.interview_triangulation)) {
      lm.has_point = true;
      lm.point_in_world = point->point_in_world;
      lm.triangulated_frame = frame;
      ++created;
    }
  }
  result->num_landmarks = created;
  if (created < options_.min_init_landmarks) {
    for (auto& [id, lm] : map_.landmarks()) lm.has_point = false;
    return false;
  }
  rig_from_world_[frame] = rig_from_world;
  keyframes_.assign(1, frame);
  initialised_ = true;
  if (last_good_frame_ != frame) {
    previous_good_frame_ = last_good_frame_;
    last_good_frame_ = frame;
  }
  return true;
}

int VoBackend::TriangulateNew(int frame) {
  int created = 0;
  std::map<int, std::vector<Rigid3>> world_from_cam_cache;
  for (auto& [id, lm] : map_.landmarks()) {
    if (lm.has_point || lm.last_seen_frame != frame || lm.observations.size() < 2) continue;
    std::vector<Ray> rays;
    bool multi_frame = false;
    for (const Observation& o : lm.observations) {
      auto pose = rig_from_world_.find(o.frame);
      if (pose == rig_from_world_.end()) continue;
      auto cached = world_from_cam_cache.find(o.frame);
      if (cached == world_from_cam_cache.end()) {
        cached = world_from_cam_cache.emplace(o.frame, WorldFromCam(pose->second)).first;
      }
      const Rigid3& world_from_cam = cached->second[o.camera];
      rays.push_back({world_from_cam.translation, world_from_cam.rotation * o.bearing_in_cam});
      if (o.frame != frame) multi_frame = true;
    }
    if (rays.size() < 2) continue;
    const TriangulationOptions& topt =
        multi_frame ? options_.multiframe_triangulation : options_.interview_triangulation;
    if (auto point = TriangulateRays(rays, topt)) {
      lm.has_point = true;
      lm.point_in_world = point->point_in_world;
      lm.triangulated_frame = frame;
      ++created;
    }
  }
  return created;
}

struct VoBackend::PendingBa {
  int frame = 0;
  LocalBaProblem problem;
  LocalBaOptions options;
  std::map<int, int> pose_index;  // keyframe -> index in problem.rig_from_world
  std::vector<uint64_t> ids;      // landmark of each problem point
  LocalBaReport report;
  double ms_solve = 0;
  std::future<void> solve;        // async_ba: the running solve
};

VoBackend::~VoBackend() {
  if (pending_ba_ && pending_ba_->solve.valid()) pending_ba_->solve.wait();
}

std::unique_ptr<VoBackend::PendingBa> VoBackend::PrepareLocalBa(int frame) const {
  auto pending = std::make_unique<PendingBa>();
  pending->frame = frame;
  LocalBaProblem& problem = pending->problem;
  for (int kf : keyframes_) {
    pending->pose_index[kf] = static_cast<int>(problem.rig_from_world.size());
    problem.rig_from_world.push_back(rig_from_world_.at(kf));
  }
  problem.cam_from_rig = cam_from_rig_;
  problem.baseline_lengths = baseline_lengths_;
  // Landmarks with >= 2 observations at window keyframes; the best-observed first, bounded.
  std::vector<std::pair<int, uint64_t>> candidates;
  for (const auto& [id, lm] : map_.landmarks()) {
    if (!lm.has_point) continue;
    int n = 0;
    for (const Observation& o : lm.observations) n += pending->pose_index.count(o.frame) ? 1 : 0;
    if (n >= 2) candidates.push_back({-n, id});
  }
  std::sort(candidates.begin(), candidates.end());
  if (static_cast<int>(candidates.size()) > options_.max_ba_landmarks) candidates.resize(options_.max_ba_landmarks);
  for (const auto& [neg_n, id] : candidates) {
    const Landmark& lm = *map_.Find(id);
    const int point_index = static_cast<int>(problem.points_in_world.size());
    problem.points_in_world.push_back(lm.point_in_world);
    problem.point_num_cameras.push_back(lm.NumCameras());
    pending->ids.push_back(id);
    for (const Observation& o : lm.observations) {
      auto it = pending->pose_index.find(o.frame);
      if (it == pending->pose_index.end()) continue;
      problem.observations.push_back({it->second, o.camera, point_index, o.bearing_in_cam});
    }
  }
  pending->options = options_.ba;
  if (keyframes_.size() < 3) pending->options.optimize_extrinsics = false;  // too little motion to calibrate
  return pending;
}

namespace {
void SolvePending(LocalBaProblem* problem, const LocalBaOptions& options, LocalBaReport* report, double* ms) {
  const auto start = Clock::now();
  if (!problem->observations.empty()) *report = SolveLocalBa(*problem, options);
  *ms = MsSince(start);
}
}  // namespace

void VoBackend::ApplyLocalBa(PendingBa& pending) {
  const int frame = pending.frame;
  const LocalBaProblem& problem = pending.problem;
  if (!pending.report.usable) return;
  for (const auto& [kf, index] : pending.pose_index) rig_from_world_[kf] = problem.rig_from_world[index];
  if (pending.options.optimize_extrinsics) cam_from_rig_ = problem.cam_from_rig;
  const double max_error_rad =
      (options_.ba.optimize_extrinsics ? std::max(options_.max_landmark_error_deg, options_.online_max_error_deg)
                                       : options_.max_landmark_error_deg) *
      M_PI / 180.0;
  for (size_t k = 0; k < pending.ids.size(); ++k) {
    Landmark& lm = *map_.Find(pending.ids[k]);
    lm.point_in_world = problem.points_in_world[k];
    // Drop observations that BA could not explain; a point left with a bad current observation is
    // re-triangulated later.
    auto& obs = lm.observations;
    obs.erase(std::remove_if(obs.begin(), obs.end(),
                             [&](const Observation& o) {
                               auto pose = rig_from_world_.find(o.frame);
                               if (pose == rig_from_world_.end()) return false;
                               const Eigen::Vector3d in_cam = cam_from_rig_[o.camera] * (pose->second * lm.point_in_world);
                               return AngleBetween(o.bearing_in_cam, in_cam) > max_error_rad;
                             }),
              obs.end());
    if (lm.NumCamerasAtFrame(frame) == 0 && lm.last_seen_frame == frame) lm.has_point = false;
  }
}

// Culling: landmarks not seen recently; observations and poses older than the window.
void VoBackend::Cull(int frame) {
  const int oldest = std::min(keyframes_.front(), previous_good_frame_ < 0 ? frame : previous_good_frame_);
  map_.Cull(frame - options_.max_unseen_frames, keyframes_.front());
  for (auto it = rig_from_world_.begin(); it != rig_from_world_.end();) {
    it = it->first < oldest ? rig_from_world_.erase(it) : std::next(it);
  }
}

std::optional<VoBackend::BaUpdate> VoBackend::FinishPendingBa() {
  if (!pending_ba_) return std::nullopt;
  const auto start = Clock::now();
  if (pending_ba_->solve.valid()) pending_ba_->solve.get();  // rethrows a solver exception
  BaUpdate update;
  update.ms_wait = MsSince(start);
  update.frame = pending_ba_->frame;
  update.ms_solve = pending_ba_->ms_solve;
  ApplyLocalBa(*pending_ba_);
  Cull(pending_ba_->frame);
  update.world_from_rig = rig_from_world_.at(pending_ba_->frame).Inverse();
  pending_ba_.reset();
  return update;
}

BackendFrameResult VoBackend::ProcessFrame(int frame, const FrontendFrame& frontend) {
  BackendFrameResult result;
  FinishPendingBa();  // callers that want the keyframe's refined pose call it themselves first
  FrameRecord& rec = result.record;
  rec.frame = frame;
  if (first_frame_ < 0) first_frame_ = frame;
  for (const auto& [from, into] : frontend.merged_ids) map_.Merge(from, into);
  int total_features = 0;
  for (const auto& f : frontend.features_per_camera) total_features += static_cast<int>(f.size());
  if (!frontend.features_per_camera.empty() &&
      frontend.features_per_camera.size() != cam_from_rig_.size()) {
    throw std::invalid_argument("VoBackend::ProcessFrame: features for " +
                                std::to_string(frontend.features_per_camera.size()) + " cameras, rig has " +
                                std::to_string(cam_from_rig_.size()));
  }
  const Rigid3 predicted = PredictRigFromWorld(frame);

  auto lose = [&]() {
    rec.status = "lost";
    initialised_ = false;
    result.world_from_rig = predicted.Inverse();
    result.num_landmarks = static_cast<int>(map_.NumWithPoint());
    return result;
  };
  // (Re)initialisation from inter-view triangulation at the predicted pose.
  auto reinitialise = [&]() {
    map_.Clear();
    keyframes_.clear();
    AddObservations(frame, frontend, nullptr);
    const auto start = Clock::now();
    const bool ok = Initialise(frame, predicted, &result);
    result.ms_triangulate += MsSince(start);
    if (!ok) return lose();
    rec.status = "init";
    rec.keyframe = true;
    result.world_from_rig = predicted.Inverse();
    return result;
  };

  if (total_features < options_.min_features) {
    map_.Clear();
    keyframes_.clear();
    return lose();
  }
  if (!initialised_) return reinitialise();

  // 2D-3D correspondences of landmarks with a point.
  const int num_cams = static_cast<int>(cam_from_rig_.size());
  std::vector<std::vector<BearingPointCorrespondence>> corrs(num_cams);
  std::vector<std::vector<int>> feature_index(num_cams);
  for (int j = 0; j < num_cams; ++j) {
    const auto& features = frontend.features_per_camera[j];
    for (size_t i = 0; i < features.size(); ++i) {
      const Landmark* lm = map_.Find(features[i].track_id);
      if (!lm || !lm->has_point) continue;
      corrs[j].push_back({features[i].bearing_in_cam, lm->point_in_world});
      feature_index[j].push_back(static_cast<int>(i));
    }
  }
  int num_corrs = 0;
  for (const auto& c : corrs) num_corrs += static_cast<int>(c.size());
  rec.num_correspondences = num_corrs;
  if (num_corrs < options_.min_correspondences) return reinitialise();

  auto start = Clock::now();
  MultiViewRansacOptions ransac_options = options_.ransac;
  ransac_options.seed = options_.ransac.seed + 0x9E3779B97F4A7C15ull * static_cast<uint64_t>(frame + 1);
  const MultiViewRansacReport ransac = MultiViewP3PRansac(corrs, cam_from_rig_, ransac_options);
  result.ms_ransac = MsSince(start);
  result.ransac_hypotheses = ransac.num_hypotheses;
  if (!ransac.success || ransac.inlier_ratio < options_.min_inlier_ratio) {
    FrameRecord saved = rec;
    reinitialise();
    result.record.num_correspondences = saved.num_correspondences;
    return result;
  }

  start = Clock::now();
  const PoseRefinementResult refined =
      RefineRigPose(corrs, cam_from_rig_, ransac.inliers, ransac.rig_from_world, options_.refine);
  Rigid3 rig_from_world = refined.usable ? refined.rig_from_world : ransac.rig_from_world;
  // Inliers and their mean angular error under the refined pose.
  std::vector<std::vector<char>> rejected(num_cams);
  const bool settling = options_.ba.optimize_extrinsics && frame - first_frame_ < options_.online_settle_frames;
  const double reject_rad = settling ? options_.online_max_error_deg * M_PI / 180.0 : options_.ransac.tau_rad;
  double error_sum = 0.0;
  int inliers = 0;
  for (int j = 0; j < num_cams; ++j) {
    rejected[j].assign(frontend.features_per_camera[j].size(), 0);
    const Rigid3 cam_from_world = cam_from_rig_[j] * rig_from_world;
    for (size_t k = 0; k < corrs[j].size(); ++k) {
      const double angle = AngleBetween(corrs[j][k].bearing_in_cam, cam_from_world * corrs[j][k].point_in_world);
      Landmark* lm = map_.Find(frontend.features_per_camera[j][feature_index[j][k]].track_id);
      if (angle < options_.ransac.tau_rad) {
        error_sum += angle;
        ++inliers;
        lm->outlier_count = 0;
      } else if (angle >= reject_rad) {
        rejected[j][feature_index[j][k]] = 1;
        if (++lm->outlier_count >= 2) {  // persistently inconsistent (moving object, bad match)
          lm->has_point = false;
          lm->observations.clear();
          lm->outlier_count = 0;
        }
      }
    }
  }
  result.ms_refine = MsSince(start);
  rec.num_inliers = inliers;
  rec.inlier_ratio = num_corrs > 0 ? static_cast<double>(inliers) / num_corrs : 0.0;
  rec.mean_reproj_error_deg = inliers > 0 ? error_sum / inliers * 180.0 / M_PI : 0.0;
  rec.status = "ok";

  AddObservations(frame, frontend, &rejected);
  rig_from_world_[frame] = rig_from_world;
  previous_good_frame_ = last_good_frame_;
  last_good_frame_ = frame;

  start = Clock::now();
  TriangulateNew(frame);
  result.ms_triangulate = MsSince(start);

  // Keyframe policy relative to the newest keyframe.
  const int last_kf = keyframes_.back();
  KeyframeCandidate candidate;
  candidate.frames_since_keyframe = frame - last_kf;
  const Rigid3 kf_from_current = rig_from_world_.at(last_kf) * rig_from_world.Inverse();
  candidate.translation_m = kf_from_current.translation.norm();
  candidate.rotation_deg = RotationAngleDeg(kf_from_current.rotation);
  int kf_points = 0, still_seen = 0;
  for (const auto& [id, lm] : map_.landmarks()) {
    if (!lm.has_point) continue;
    bool at_kf = false, now = false;
    for (const Observation& o : lm.observations) {
      at_kf |= o.frame == last_kf;
      now |= o.frame == frame;
    }
    kf_points += at_kf;
    still_seen += at_kf && now;
  }
  candidate.tracked_fraction = kf_points > 0 ? static_cast<double>(still_seen) / kf_points : 0.0;
  if (IsKeyframe(candidate, options_.keyframes)) {
    rec.keyframe = true;
    keyframes_.push_back(frame);
    while (static_cast<int>(keyframes_.size()) > options_.window_keyframes) keyframes_.erase(keyframes_.begin());
    if (options_.local_ba && keyframes_.size() >= 2) {
      pending_ba_ = PrepareLocalBa(frame);
      PendingBa* pending = pending_ba_.get();
      if (options_.async_ba) {
        // The map and poses stay untouched until FinishPendingBa (the solve owns only `pending`).
        pending->solve = std::async(std::launch::async, [pending] {
          SolvePending(&pending->problem, pending->options, &pending->report, &pending->ms_solve);
        });
        result.world_from_rig = rig_from_world.Inverse();  // before BA: see FinishPendingBa
        result.num_landmarks = static_cast<int>(map_.NumWithPoint());
        return result;
      }
      SolvePending(&pending->problem, pending->options, &pending->report, &pending->ms_solve);
      result.ms_ba = pending->ms_solve;
      FinishPendingBa();
      result.world_from_rig = rig_from_world_.at(frame).Inverse();
      result.num_landmarks = static_cast<int>(map_.NumWithPoint());
      return result;
    }
  }

  Cull(frame);
  result.world_from_rig = rig_from_world.Inverse();
  result.num_landmarks = static_cast<int>(map_.NumWithPoint());
  return result;
}

namespace {

nlohmann::json PoseJson(const Rigid3& x) {
  return {{"translation", {x.translation.x(), x.translation.y(), x.translation.z()}},
          {"rotation_xyzw", {x.rotation.x(), x.rotation.y(), x.rotation.z(), x.rotation.w()}}};
}

// The frame range and the camera folders: a missing folder is an input error, not lost frames.
void CheckRangeAndFolders(const VoOptions& options, const DatasetInfo& info, int begin, int end) {
  if (begin < 0 || end > info.frame_count || begin >= end) {
    throw std::invalid_argument("vo: --frames " + std::to_string(begin) + ":" + std::to_string(end) +
                                " is not a non-empty range within the dataset's " + std::to_string(info.frame_count) +
                                " frames (" + DatasetJsonPath(options.dataset_dir) + ": frame_count)");
  }
  for (const RigCamera& cam : info.rig.cameras) {
    const std::string folder = (std::filesystem::path(options.dataset_dir) / cam.name).string();
    if (!std::filesystem::is_directory(folder)) {
      throw std::runtime_error(folder + ": image folder of camera " + cam.name + " (dataset.json rig.cameras) is missing");
    }
  }
}

// GTExt: the rig's; NoisyExt/OnlineExt: a fresh draw (--draw-seed) or a stored perturbed set.
std::vector<Rigid3> StartingExtrinsics(const VoOptions& options, const DatasetInfo& info) {
  std::vector<Rigid3> cam_from_rig = info.rig.Extrinsics();
  if (options.mode != ExtrinsicsMode::kGroundTruth && options.draw_seed >= 0) {
    if (!(options.draw_sigma_deg >= 0.0)) {
      throw std::invalid_argument("vo: --draw-sigma must be non-negative (degrees), got " +
                                  std::to_string(options.draw_sigma_deg));
    }
    cam_from_rig =
        PerturbExtrinsics(info.rig, options.draw_sigma_deg, 0.0, static_cast<uint64_t>(options.draw_seed)).cam_from_rig;
  } else if (options.mode != ExtrinsicsMode::kGroundTruth) {
    if (options.noise_set < 0 || options.noise_set >= static_cast<int>(info.perturbed.size())) {
      throw std::invalid_argument(DatasetJsonPath(options.dataset_dir) + ": perturbed[" +
                                  std::to_string(options.noise_set) + "] does not exist (the dataset has " +
                                  std::to_string(info.perturbed.size()) + " perturbed extrinsic sets)");
    }
    cam_from_rig = info.perturbed[options.noise_set].cam_from_rig;
    if (static_cast<int>(cam_from_rig.size()) != info.rig.NumCameras()) {
      throw std::runtime_error(DatasetJsonPath(options.dataset_dir) + ": perturbed[" +
                               std::to_string(options.noise_set) + "].cam_from_rig has the wrong camera count");
    }
  }
  return cam_from_rig;
}

BackendOptions MakeBackendOptions(const VoOptions& options) {
  BackendOptions backend_options;
  backend_options.ransac.seed = options.seed;
  backend_options.ransac.sampling = ViewSamplingFromName(options.sampling);
  backend_options.ransac.views = RansacViewsFromName(options.ransac);
  backend_options.ba.optimize_extrinsics = options.mode == ExtrinsicsMode::kOnline;
  backend_options.async_ba = options.async_ba;
  backend_options.ransac.tau_rad = options.ransac_tau_deg * M_PI / 180.0;
  if (options.keyframe_distance_m > 0.0) backend_options.keyframes.min_translation_m = options.keyframe_distance_m;
  if (options.online_settle_frames >= 0) backend_options.online_settle_frames = options.online_settle_frames;
  // Online: each keyframe BA may move an extrinsic by about this much (random-walk prior, local_ba.h):
  // measured on cloudy_urban quick, it halves the wander of the estimate between windows.
  backend_options.ba.extrinsic_prior_deg = 0.005;
  return backend_options;
}

bool RunsStartupCalibration(const VoOptions& options) {
  return options.mode == ExtrinsicsMode::kOnline && options.online_prior_deg > 0.0;
}

StartupCalibrationReport RunStartupCalibration(const VoOptions& options, const DatasetInfo& info, int begin, int end,
                                               const std::vector<Rigid3>& cam_from_rig) {
  StartupCalibrationOptions sopt;
  sopt.shots = options.online_startup_shots;
  sopt.fallback_prior_deg = options.online_prior_deg;
  sopt.refine_rounds = options.online_bootstrap_rounds;
  auto load = [&](int frame) { return LoadFrameImages(options.dataset_dir, info.rig, frame); };
  StartupCalibrationReport startup =
      CalibrateAtStartup(info.rig, cam_from_rig, load, begin, end,
                         LoadStaticMasks(options.dataset_dir, info.rig, info.has_static_masks), sopt, options.quiet);
  if (!startup.converged) {
    std::fprintf(stderr, "vo online: WARNING: start-up calibration not converged: %s\n", startup.status.c_str());
  }
  return startup;
}

// Sums of per-frame stage times -> means per frame.
void AverageStageTimes(int frames, int total_hypotheses, VoStageTimes* ms) {
  const double n = std::max(1, frames);
  for (double* v : {&ms->warp, &ms->detect, &ms->track, &ms->match, &ms->cpu_warp, &ms->cpu_detect, &ms->cpu_track,
                    &ms->cpu_match, &ms->load, &ms->ransac, &ms->refine, &ms->triangulate, &ms->ba, &ms->ba_wait,
                    &ms->backend_total, &ms->total}) {
    *v /= n;
  }
  ms->ransac_us_per_hypothesis = total_hypotheses > 0 ? ms->ransac * n * 1000.0 / total_hypotheses : 0.0;
}

// Adds a frame's front-end and back-end stage times to the sums.
void AddStageTimes(const FrontendFrame& features, const BackendFrameResult& result, VoStageTimes* ms) {
  ms->warp += features.ms_warp;
  ms->detect += features.ms_detect;
  ms->track += features.ms_track;
  ms->match += features.ms_match;
  ms->cpu_warp += features.cpu_ms_warp;
  ms->cpu_detect += features.cpu_ms_detect;
  ms->cpu_track += features.cpu_ms_track;
  ms->cpu_match += features.cpu_ms_match;
  ms->ransac += result.ms_ransac;
  ms->refine += result.ms_refine;
  ms->triangulate += result.ms_triangulate;
  ms->ba += result.ms_ba;  // synchronous BA; async BA is counted when it is joined
}

// run.json: every setting, seeds, the start-up calibration and the summary.
nlohmann::json RunInfoJson(const VoOptions& options, const DatasetInfo& info, const BackendOptions& backend_options,
                           const VoSummary& summary, const StartupCalibrationReport& startup, int begin, int end,
                           const Rigid3& world_from_rig0) {
  const std::string dataset_json = ReadFile(DatasetJsonPath(options.dataset_dir));
  const VoStageTimes& ms = summary.stage_ms;
  nlohmann::json j;
  j["mode"] = ExtrinsicsModeName(options.mode);
  j["dataset"] = std::filesystem::absolute(options.dataset_dir).lexically_normal().string();
  j["dataset_json_hash"] = HashHex(dataset_json.data(), dataset_json.size());
  j["scene_hash"] = info.scene_hash;
  j["dataset_seed"] = info.seed;
  j["seed"] = options.seed;
  j["noise_set"] = options.noise_set;
  j["draw_seed"] = options.draw_seed;
  j["draw_sigma_deg"] = options.draw_sigma_deg;
  j["frames"] = {begin, end};
  j["threads"] = options.threads;
  j["sampling"] = options.sampling;
  j["ransac"] = options.ransac;
  j["generator"] = "rovo vo";
  j["version"] = ROVO_VERSION;
  j["initial_world_from_rig"] = PoseJson(world_from_rig0);
  j["online_prior_deg"] = options.online_prior_deg;
  j["max_new_features"] = options.max_new_features;
  j["warp_below_deg"] = options.warp_below_deg;
  if (RunsStartupCalibration(options)) j["startup_calibration"] = startup.ToJson();
  j["backend"] = {{"ransac_tau_deg", backend_options.ransac.tau_rad * 180.0 / M_PI},
                  {"ransac_max_iterations", backend_options.ransac.max_iterations},
                  {"ransac_confidence", backend_options.ransac.confidence},
                  {"refine_cauchy_scale_deg", backend_options.refine.cauchy_scale_rad * 180.0 / M_PI},
                  {"ba_cauchy_scale_deg", backend_options.ba.cauchy_scale_rad * 180.0 / M_PI},
                  {"ba_max_iterations", backend_options.ba.max_iterations},
                  {"ba_online_extrinsics", backend_options.ba.optimize_extrinsics},
                  {"ba_extrinsic_prior_deg", backend_options.ba.extrinsic_prior_deg},
                  {"window_keyframes", backend_options.window_keyframes},
                  {"async_ba", backend_options.async_ba},
                  {"keyframe_distance_m", backend_options.keyframes.min_translation_m},
                  {"keyframe_max_frame_gap", backend_options.keyframes.max_frame_gap},
                  {"online_max_error_deg", backend_options.online_max_error_deg},
                  {"online_settle_frames", backend_options.online_settle_frames}};
  j["summary"] = {{"frames", summary.frames},
                  {"frames_ok", summary.frames_ok},
                  {"frames_init", summary.frames_init},
                  {"frames_lost", summary.frames_lost},
                  {"frames_with_missing_images", summary.frames_with_missing_images},
                  {"missing_images", summary.missing_images},
                  {"mean_inlier_ratio", summary.mean_inlier_ratio},
                  {"mean_reproj_error_deg", summary.mean_reproj_error_deg},
                  {"seconds", summary.seconds},
                  {"ms_per_frame", ms.total},
                  {"ms_backend_per_frame", ms.backend_total}};
  return j;
}

}  // namespace

VoSummary RunVo(const VoOptions& options) {
  const auto run_start = Clock::now();
  if (options.dataset_dir.empty()) throw std::invalid_argument("vo: no dataset folder given");
  if (options.out_dir.empty()) throw std::invalid_argument("vo: no output (run) folder given");
  if (!(options.ransac_tau_deg > 0.0)) {
    throw std::invalid_argument("vo: the RANSAC inlier threshold must be positive (--tau, degrees), got " +
                                std::to_string(options.ransac_tau_deg));
  }
  const DatasetInfo info = ReadDatasetInfo(options.dataset_dir);
  const int num_cams = info.rig.NumCameras();
  const int begin = options.frame_begin;
  const int end = options.frame_end < 0 ? info.frame_count : options.frame_end;
  CheckRangeAndFolders(options, info, begin, end);
  std::vector<Rigid3> cam_from_rig = StartingExtrinsics(options, info);
  // Ground truth: the first pose (metric start) and time stamps.
  Trajectory ground_truth;
  if (std::filesystem::exists(GroundTruthPath(options.dataset_dir))) ground_truth = ReadTum(GroundTruthPath(options.dataset_dir));
  auto timestamp_of = [&](int frame) {
    return frame < static_cast<int>(ground_truth.size()) ? ground_truth[frame].timestamp : frame / info.frame_rate;
  };
  const Rigid3 world_from_rig0 =
      begin < static_cast<int>(ground_truth.size()) ? ground_truth[begin].world_from_rig : Rigid3::Identity();

  std::unique_ptr<tbb::global_control> threads;
  if (options.threads > 0) {
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, options.threads);
  }
  EnsureWritableDir(options.out_dir);

  const BackendOptions backend_options = MakeBackendOptions(options);
  StartupCalibrationReport startup;
  if (RunsStartupCalibration(options)) {
    startup = RunStartupCalibration(options, info, begin, end, cam_from_rig);
    cam_from_rig = startup.cam_from_rig;
  }
  FrontendOptions frontend_options;
  frontend_options.max_new_features_per_view = options.max_new_features;
  frontend_options.projection.vertical_fov_below_deg = options.warp_below_deg;
  Frontend frontend(info.rig.WithExtrinsics(cam_from_rig), frontend_options);
  frontend.SetStaticMasks(LoadStaticMasks(options.dataset_dir, info.rig, info.has_static_masks));
  VoBackend backend(cam_from_rig, world_from_rig0, backend_options);

  RunData run;
  VoSummary summary;
  VoStageTimes& ms = summary.stage_ms;
  int total_hypotheses = 0;
  double ok_ratio_sum = 0.0, ok_error_sum = 0.0;
  Progress progress("vo " + ExtrinsicsModeName(options.mode), end - begin, "frames", options.quiet);
  // --preload (bench): every frame decoded before the clock starts, as a live rig delivers images.
  std::vector<LoadedFrame> preloaded;
  if (options.preload_images) {
    Progress load_progress("vo: decoding images", end - begin, "frames", options.quiet);
    for (int frame = begin; frame < end; ++frame) {
      preloaded.push_back(LoadFrameImages(options.dataset_dir, info.rig, frame));
      load_progress.Add();
    }
    load_progress.Finish();
  }
  ImagePrefetcher prefetcher(options.dataset_dir, info.rig, begin, options.preload_images ? begin : end);
  // Async BA: the records of a keyframe get its BA-refined pose and extrinsics when the BA is joined.
  auto apply_ba_update = [&](const VoBackend::BaUpdate& update) {
    ms.ba += update.ms_solve;
    ms.ba_wait += update.ms_wait;
    for (size_t i = run.frames.size(); i-- > 0;) {
      if (run.frames[i].frame != update.frame) continue;
      run.trajectory[i].world_from_rig = update.world_from_rig;
      for (int j = 0; j < num_cams; ++j) run.extrinsics[i * num_cams + j].cam_from_rig = backend.cam_from_rig()[j];
      break;
    }
  };
  for (int frame = begin; frame < end; ++frame) {
    const auto frame_start = Clock::now();
    const LoadedFrame loaded = options.preload_images ? std::move(preloaded[frame - begin]) : prefetcher.Get(frame);
    const std::vector<cv::Mat>& images = loaded.images;
    const std::string& problems = loaded.problems;
    ms.load += MsSince(frame_start);
    if (!problems.empty() && !options.quiet) std::fprintf(stderr, "vo: frame %d: %s\n", frame, problems.c_str());
    const FrontendFrame features = frontend.Process(images);  // beside the previous keyframe's BA
    const auto backend_start = Clock::now();
    if (auto update = backend.FinishPendingBa()) apply_ba_update(*update);
    BackendFrameResult result = backend.ProcessFrame(frame, features);
    ms.backend_total += MsSince(backend_start);
    if (options.mode == ExtrinsicsMode::kOnline) frontend.SetExtrinsics(backend.cam_from_rig());
    AddStageTimes(features, result, &ms);
    total_hypotheses += result.ransac_hypotheses;

    FrameRecord rec = result.record;
    for (int cam : loaded.missing_cameras) {
      rec.missing_cameras += (rec.missing_cameras.empty() ? "" : ";") + std::to_string(cam);
    }
    summary.missing_images += static_cast<int>(loaded.missing_cameras.size());
    summary.frames_with_missing_images += loaded.missing_cameras.empty() ? 0 : 1;
    rec.frame = frame;
    rec.timestamp = timestamp_of(frame);
    rec.time_ms = MsSince(frame_start);
    ms.total += rec.time_ms;
    ++summary.frames;
    if (rec.status == "ok") {
      ++summary.frames_ok;
      ok_ratio_sum += rec.inlier_ratio;
      ok_error_sum += rec.mean_reproj_error_deg;
    } else if (rec.status == "init") {
      ++summary.frames_init;
    } else {
      ++summary.frames_lost;
    }
    run.frames.push_back(rec);
    run.trajectory.push_back({rec.timestamp, result.world_from_rig});
    for (int j = 0; j < num_cams; ++j) run.extrinsics.push_back({frame, rec.timestamp, j, backend.cam_from_rig()[j]});
    progress.Add();
  }
  if (auto update = backend.FinishPendingBa()) apply_ba_update(*update);
  progress.Finish();
  AverageStageTimes(summary.frames, total_hypotheses, &ms);
  summary.mean_inlier_ratio = summary.frames_ok > 0 ? ok_ratio_sum / summary.frames_ok : 0.0;
  summary.mean_reproj_error_deg = summary.frames_ok > 0 ? ok_error_sum / summary.frames_ok : 0.0;
  summary.seconds = std::chrono::duration<double>(Clock::now() - run_start).count();
  run.info = RunInfoJson(options, info, backend_options, summary, startup, begin, end, world_from_rig0);
  WriteRun(options.out_dir, run);
  return summary;
}

}  // namespace rovo
