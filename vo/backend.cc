#include "vo/backend.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <future>
#include <stdexcept>
#include <string>

#include "vo/stopwatch.h"

namespace rovo {
namespace {

using Clock = std::chrono::steady_clock;

// Rigid motion scaled along its screw-free approximation: rotation angle and translation times s.
Rigid3 ScaleMotion(const Rigid3& motion, double s) {
  return Rigid3::FromAxisAngle(motion.AxisAngle() * s, motion.translation * s);
}

int CountFeatures(const FrontendFrame& frontend) {
  int total = 0;
  for (const auto& f : frontend.features_per_camera) total += static_cast<int>(f.size());
  return total;
}

}  // namespace

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
  std::future<void> solve;  // async_ba: the running solve
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
                               const Eigen::Vector3d in_cam =
                                   cam_from_rig_[o.camera] * (pose->second * lm.point_in_world);
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

void VoBackend::Lose(const Rigid3& predicted_rig_from_world, BackendFrameResult* result) {
  result->record.status = FrameStatus::kLost;
  initialised_ = false;
  result->world_from_rig = predicted_rig_from_world.Inverse();
  result->num_landmarks = static_cast<int>(map_.NumWithPoint());
}

void VoBackend::Reinitialise(int frame, const FrontendFrame& frontend, const Rigid3& predicted_rig_from_world,
                             BackendFrameResult* result) {
  map_.Clear();
  keyframes_.clear();
  AddObservations(frame, frontend, nullptr);
  const auto start = Clock::now();
  const bool ok = Initialise(frame, predicted_rig_from_world, result);
  result->ms_triangulate += MsSince(start);
  if (!ok) {
    Lose(predicted_rig_from_world, result);
    return;
  }
  result->record.status = FrameStatus::kInit;
  result->record.keyframe = true;
  result->world_from_rig = predicted_rig_from_world.Inverse();
}

// The 2D-3D correspondences of one frame, per camera, with the index of each one's feature.
struct VoBackend::Correspondences {
  std::vector<std::vector<BearingPointCorrespondence>> per_camera;
  std::vector<std::vector<int>> feature_index;  // into frontend.features_per_camera[camera]
  int count = 0;
};

// Features whose landmark has a point.
VoBackend::Correspondences VoBackend::CollectCorrespondences(const FrontendFrame& frontend) const {
  const int num_cams = static_cast<int>(cam_from_rig_.size());
  Correspondences corrs;
  corrs.per_camera.resize(num_cams);
  corrs.feature_index.resize(num_cams);
  for (int j = 0; j < num_cams; ++j) {
    const auto& features = frontend.features_per_camera[j];
    for (size_t i = 0; i < features.size(); ++i) {
      const Landmark* lm = map_.Find(features[i].track_id);
      if (!lm || !lm->has_point) continue;
      corrs.per_camera[j].push_back({features[i].bearing_in_cam, lm->point_in_world});
      corrs.feature_index[j].push_back(static_cast<int>(i));
    }
  }
  for (const auto& c : corrs.per_camera) corrs.count += static_cast<int>(c.size());
  return corrs;
}

// Under the refined pose: a correspondence within the RANSAC threshold is an inlier (the record's
// inlier count, ratio and mean angular error); one off by the rejection bound or more is rejected (its
// observation is not added), and its landmark loses point and observations at its second rejection
// since it was last an inlier. The bound is the RANSAC threshold, or online_max_error_deg while
// OnlineExt settles (online_settle_frames). Returns the rejected flags per camera and feature.
std::vector<std::vector<char>> VoBackend::ClassifyUnderPose(int frame, const FrontendFrame& frontend,
                                                            const Correspondences& corrs, const Rigid3& rig_from_world,
                                                            FrameRecord* record) {
  const int num_cams = static_cast<int>(cam_from_rig_.size());
  std::vector<std::vector<char>> rejected(num_cams);
  const bool settling = options_.ba.optimize_extrinsics && frame - first_frame_ < options_.online_settle_frames;
  const double reject_rad = settling ? options_.online_max_error_deg * M_PI / 180.0 : options_.ransac.tau_rad;
  double error_sum = 0.0;
  int inliers = 0;
  for (int j = 0; j < num_cams; ++j) {
    rejected[j].assign(frontend.features_per_camera[j].size(), 0);
    const Rigid3 cam_from_world = cam_from_rig_[j] * rig_from_world;
    const std::vector<BearingPointCorrespondence>& cam_corrs = corrs.per_camera[j];
    for (size_t k = 0; k < cam_corrs.size(); ++k) {
      const double angle = AngleBetween(cam_corrs[k].bearing_in_cam, cam_from_world * cam_corrs[k].point_in_world);
      const int feature = corrs.feature_index[j][k];
      Landmark* lm = map_.Find(frontend.features_per_camera[j][feature].track_id);
      if (angle < options_.ransac.tau_rad) {
        error_sum += angle;
        ++inliers;
        lm->outlier_count = 0;
      } else if (angle >= reject_rad) {
        rejected[j][feature] = 1;
        if (++lm->outlier_count >= 2) {  // persistently inconsistent (moving object, bad match)
          lm->has_point = false;
          lm->observations.clear();
          lm->outlier_count = 0;
        }
      }
    }
  }
  record->num_inliers = inliers;
  record->inlier_ratio = corrs.count > 0 ? static_cast<double>(inliers) / corrs.count : 0.0;
  record->mean_reproj_error_deg = inliers > 0 ? error_sum / inliers * 180.0 / M_PI : 0.0;
  return rejected;
}

// Keyframe policy (IsKeyframe) relative to the newest keyframe, for a frame whose pose and
// observations are in the map.
bool VoBackend::IsNewKeyframe(int frame) const {
  const int last_kf = keyframes_.back();
  KeyframeCandidate candidate;
  candidate.frames_since_keyframe = frame - last_kf;
  const Rigid3 kf_from_current = rig_from_world_.at(last_kf) * rig_from_world_.at(frame).Inverse();
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
  return IsKeyframe(candidate, options_.keyframes);
}

// The local BA of the keyframe `frame`: with async_ba solved on its own thread and applied by the next
// FinishPendingBa; otherwise solved and applied (with the frame's culling) here. Returns the
// synchronous solve time (0 with async_ba).
double VoBackend::StartLocalBa(int frame) {
  pending_ba_ = PrepareLocalBa(frame);
  PendingBa* pending = pending_ba_.get();
  if (options_.async_ba) {
    // The map and poses stay untouched until FinishPendingBa (the solve owns only `pending`).
    pending->solve = std::async(std::launch::async, [pending] {
      SolvePending(&pending->problem, pending->options, &pending->report, &pending->ms_solve);
    });
    return 0.0;
  }
  SolvePending(&pending->problem, pending->options, &pending->report, &pending->ms_solve);
  const double ms_solve = pending->ms_solve;
  FinishPendingBa();
  return ms_solve;
}

BackendFrameResult VoBackend::ProcessFrame(int frame, const FrontendFrame& frontend) {
  BackendFrameResult result;
  FinishPendingBa();  // callers that want the keyframe's refined pose call it themselves first
  FrameRecord& rec = result.record;
  rec.frame = frame;
  if (first_frame_ < 0) first_frame_ = frame;
  for (const auto& [from, into] : frontend.merged_ids) map_.Merge(from, into);
  if (!frontend.features_per_camera.empty() && frontend.features_per_camera.size() != cam_from_rig_.size()) {
    throw std::invalid_argument("VoBackend::ProcessFrame: features for " +
                                std::to_string(frontend.features_per_camera.size()) + " cameras, rig has " +
                                std::to_string(cam_from_rig_.size()));
  }
  const Rigid3 predicted = PredictRigFromWorld(frame);
  if (CountFeatures(frontend) < options_.min_features) {
    map_.Clear();
    keyframes_.clear();
    Lose(predicted, &result);
    return result;
  }
  if (!initialised_) {
    Reinitialise(frame, frontend, predicted, &result);
    return result;
  }

  const Correspondences corrs = CollectCorrespondences(frontend);
  rec.num_correspondences = corrs.count;
  if (corrs.count < options_.min_correspondences) {
    Reinitialise(frame, frontend, predicted, &result);
    return result;
  }
  auto start = Clock::now();
  MultiViewRansacOptions ransac_options = options_.ransac;
  ransac_options.seed = options_.ransac.seed + 0x9E3779B97F4A7C15ull * static_cast<uint64_t>(frame + 1);
  const MultiViewRansacReport ransac = MultiViewP3PRansac(corrs.per_camera, cam_from_rig_, ransac_options);
  result.ms_ransac = MsSince(start);
  result.ransac_hypotheses = ransac.num_hypotheses;
  if (!ransac.success || ransac.inlier_ratio < options_.min_inlier_ratio) {
    Reinitialise(frame, frontend, predicted, &result);  // keeps the RANSAC's counts and time
    return result;
  }

  start = Clock::now();
  const PoseRefinementResult refined =
      RefineRigPose(corrs.per_camera, cam_from_rig_, ransac.inliers, ransac.rig_from_world, options_.refine);
  const Rigid3 rig_from_world = refined.usable ? refined.rig_from_world : ransac.rig_from_world;
  const std::vector<std::vector<char>> rejected = ClassifyUnderPose(frame, frontend, corrs, rig_from_world, &rec);
  result.ms_refine = MsSince(start);
  rec.status = FrameStatus::kOk;
  AddObservations(frame, frontend, &rejected);
  rig_from_world_[frame] = rig_from_world;
  previous_good_frame_ = last_good_frame_;
  last_good_frame_ = frame;

  start = Clock::now();
  TriangulateNew(frame);
  result.ms_triangulate = MsSince(start);

  bool ba_started = false;
  if (IsNewKeyframe(frame)) {
    rec.keyframe = true;
    keyframes_.push_back(frame);
    while (static_cast<int>(keyframes_.size()) > options_.window_keyframes) keyframes_.erase(keyframes_.begin());
    if (options_.local_ba && keyframes_.size() >= 2) {
      result.ms_ba = StartLocalBa(frame);
      ba_started = true;
    }
  }
  if (!ba_started) Cull(frame);  // a local BA culls when it is applied
  // With async_ba on a keyframe: the pose before its BA (FinishPendingBa gives the refined one).
  result.world_from_rig = rig_from_world_.at(frame).Inverse();
  result.num_landmarks = static_cast<int>(map_.NumWithPoint());
  return result;
}

}  // namespace rovo
