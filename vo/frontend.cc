#include "vo/frontend.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>
#include <mutex>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "vo/opencv_threads.h"
#include "vo/stopwatch.h"

namespace rovo {

void FrontendOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("FrontendOptions.") + what);
  };
  require(target_features_per_view >= 0, "target_features_per_view must be >= 0");
  require(max_new_features_per_view >= 0, "max_new_features_per_view must be >= 0");
  require(min_feature_distance_px >= 0.0f, "min_feature_distance_px must be >= 0");
  require(fast_threshold >= 0, "fast_threshold must be >= 0");
  require(max_forward_backward_px >= 0.0f, "max_forward_backward_px must be >= 0");
  require(klt_window_px >= 3, "klt_window_px must be >= 3");
  require(klt_levels >= 0, "klt_levels must be >= 0");
  require(klt_max_iterations >= 1, "klt_max_iterations must be >= 1");
  require(klt_epsilon_px >= 0.0f, "klt_epsilon_px must be >= 0");
  require(klt_predicted_levels >= 0, "klt_predicted_levels must be >= 0");
  projection.Check();
  matching.Check();
}
namespace {

cv::Mat ToGray(const cv::Mat& image, int camera) {
  if (image.depth() != CV_8U) {
    throw std::invalid_argument("Frontend: image of camera " + std::to_string(camera) + " is not 8-bit");
  }
  if (image.channels() == 1) return image;
  cv::Mat gray;
  if (image.channels() == 3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  } else {
    throw std::invalid_argument("Frontend: image of camera " + std::to_string(camera) + " has " +
                                std::to_string(image.channels()) + " channels");
  }
  return gray;
}

}  // namespace

TrackerOptions TrackerOptionsFrom(const FrontendOptions& options) {
  TrackerOptions tracker;
  tracker.target_features = options.target_features_per_view;
  tracker.max_new_per_frame = options.max_new_features_per_view;
  tracker.min_feature_distance_px = options.min_feature_distance_px;
  tracker.fast_threshold = options.fast_threshold;
  tracker.max_forward_backward_px = options.max_forward_backward_px;
  tracker.klt_window_px = options.klt_window_px;
  tracker.klt_levels = options.klt_levels;
  tracker.klt_max_iterations = options.klt_max_iterations;
  tracker.klt_epsilon_px = options.klt_epsilon_px;
  tracker.klt_predict_flow = options.klt_predict_flow;
  tracker.klt_predicted_levels = options.klt_predicted_levels;
  tracker.upright_descriptors = options.upright_descriptors;
  return tracker;
}

struct Frontend::Impl {
  Rig rig;
  FrontendOptions options;
  std::vector<HybridLayout> layouts;          // for the current extrinsics
  std::vector<HybridProjection> projections;  // maps (rebuilt only past the threshold)
  std::vector<ViewTracker> trackers;
  std::vector<cv::Mat> warped, fisheye_gray;
  std::vector<cv::Mat> static_masks;       // fisheye, per camera; empty: none
  std::vector<cv::Mat> view_masks;         // warped: the lens' valid area and the static mask
  std::vector<std::pair<int, int>> pairs;  // (camera, its right neighbour), each overlap once
  std::vector<ViewMatch> last_matches;
  uint64_t last_id = 0;

  // Steps of Frontend::Process (bearings_in_cam: per view, the bearing of every tracked point).
  using ViewBearings = std::vector<std::vector<std::optional<Eigen::Vector3d>>>;
  void CheckImages(const std::vector<cv::Mat>& fisheye_images) const;
  cv::Mat WarpView(int i) const;
  void RunViewStages(const std::vector<cv::Mat>& fisheye_images, ViewBearings* bearings_in_cam, FrontendFrame* frame,
                     double* bearings_ms, double* bearings_cpu_ms);
  void MatchViewsAndUnifyIds(ViewBearings* bearings_in_cam, FrontendFrame* frame);
  std::vector<MatchView> MakeMatchViews(const ViewBearings& bearings_in_cam) const;
  void UnifyIds(const std::vector<std::vector<InterviewMatch>>& pair_matches, FrontendFrame* frame);
  void CollectFeatures(const ViewBearings& bearings_in_cam, FrontendFrame* frame) const;

  // What the per-view stages change, to undo them (Frontend::Process with late extrinsics): a shallow
  // copy, whose Mats share their pixels with the live state. The stages write into new buffers, but
  // for the trackers' spare pyramids, which they rewrite whole before reading (no state).
  struct ViewState {
    std::vector<ViewTracker> trackers;
    std::vector<cv::Mat> warped, fisheye_gray;
    uint64_t last_id = 0;
  };
  ViewState SaveViews() const { return {trackers, warped, fisheye_gray, last_id}; }
  void RestoreViews(ViewState&& saved) {
    trackers = std::move(saved.trackers);
    warped = std::move(saved.warped);
    fisheye_gray = std::move(saved.fisheye_gray);
    last_id = saved.last_id;
  }
  void CheckExtrinsicsCount(const std::vector<Rigid3>& cam_from_rig) const;
  // New extrinsics, their layouts, and the views whose warp maps they rebuild (layout moved past the
  // threshold).
  struct ExtrinsicsUpdate {
    std::vector<Rigid3> cam_from_rig;
    std::vector<HybridLayout> layouts;
    std::vector<int> rebuilt;
  };
  ExtrinsicsUpdate PlanExtrinsics(std::vector<Rigid3> cam_from_rig) const;
  void ApplyExtrinsics(const ExtrinsicsUpdate& update);
  void ApplyLateExtrinsics(const std::function<std::vector<Rigid3>()>& late_cam_from_rig, ViewState&& saved,
                           const std::vector<cv::Mat>& fisheye_images, ViewBearings* bearings_in_cam,
                           FrontendFrame* frame, double* bearings_ms, double* bearings_cpu_ms);
  void RebuildView(int i, const Rigid3& cam_from_rig);

  // The detection and tracking mask of view i for its current projection.
  void UpdateViewMask(int i) {
    if (static_masks.empty()) {
      view_masks[i] = projections[i].valid_mask();
      return;
    }
    cv::Mat warped_mask, allowed;
    projections[i].Warp(static_masks[i], &warped_mask);
    cv::compare(warped_mask, 254, allowed, cv::CMP_GT);
    cv::erode(allowed, allowed, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(15, 15)));
    cv::bitwise_and(allowed, projections[i].valid_mask(), view_masks[i]);
  }

  void UpdatePairs() {
    pairs.clear();
    std::set<std::pair<int, int>> seen;
    for (int i = 0; i < rig.NumCameras(); ++i) {
      const int j = layouts[i].right_neighbour;
      if (j == i || !seen.insert({std::min(i, j), std::max(i, j)}).second) continue;
      pairs.emplace_back(i, j);
    }
  }
};

Frontend::Frontend(const Rig& rig, const FrontendOptions& options) : impl_(std::make_unique<Impl>()) {
  options.Check();
  Impl& s = *impl_;
  s.rig = rig;
  s.options = options;
  s.layouts = ComputeHybridLayouts(rig);
  s.projections.resize(rig.NumCameras());
  tbb::parallel_for(0, rig.NumCameras(), [&](int i) {
    s.projections[i] =
        HybridProjection(rig.cameras[i].camera, rig.cameras[i].cam_from_rig, s.layouts[i], options.projection);
  });
  s.trackers.assign(rig.NumCameras(), ViewTracker(TrackerOptionsFrom(s.options)));
  s.warped.resize(rig.NumCameras());
  s.fisheye_gray.resize(rig.NumCameras());
  s.view_masks.resize(rig.NumCameras());
  for (int i = 0; i < rig.NumCameras(); ++i) s.UpdateViewMask(i);
  s.UpdatePairs();
}

void Frontend::SetStaticMasks(const std::vector<cv::Mat>& fisheye_masks) {
  Impl& s = *impl_;
  if (!fisheye_masks.empty() && static_cast<int>(fisheye_masks.size()) != s.rig.NumCameras()) {
    throw std::invalid_argument("Frontend::SetStaticMasks: " + std::to_string(fisheye_masks.size()) + " masks for " +
                                std::to_string(s.rig.NumCameras()) + " cameras");
  }
  for (size_t i = 0; i < fisheye_masks.size(); ++i) {
    const Camera& camera = s.rig.cameras[i].camera;
    if (fisheye_masks[i].type() != CV_8UC1 || fisheye_masks[i].cols != camera.width ||
        fisheye_masks[i].rows != camera.height) {
      throw std::invalid_argument("Frontend::SetStaticMasks: the mask of camera " + std::to_string(i) +
                                  " is not 8-bit single-channel of the camera's size");
    }
  }
  s.static_masks = fisheye_masks;
  for (int i = 0; i < s.rig.NumCameras(); ++i) s.UpdateViewMask(i);
}

Frontend::~Frontend() = default;

int Frontend::NumCameras() const { return impl_->rig.NumCameras(); }
const HybridProjection& Frontend::projection(int camera) const { return impl_->projections.at(camera); }
const cv::Mat& Frontend::warped_image(int camera) const { return impl_->warped.at(camera); }
const ViewTracker& Frontend::tracker(int camera) const { return impl_->trackers.at(camera); }
const std::vector<Frontend::ViewMatch>& Frontend::last_matches() const { return impl_->last_matches; }
const FrontendOptions& Frontend::options() const { return impl_->options; }

void Frontend::SetExtrinsics(const std::vector<Rigid3>& cam_from_rig) {
  Impl& s = *impl_;
  s.CheckExtrinsicsCount(cam_from_rig);
  const ScopedOpenCvThreads serial_opencv;
  s.ApplyExtrinsics(s.PlanExtrinsics(cam_from_rig));
}

// Frontend::Process's late extrinsics, after the per-view stages ran on the state `saved` holds: applied
// as they are where they rebuild no view's warp maps; otherwise the stages are undone, the extrinsics
// applied and the stages run again (their times add up). An exception from `late_cam_from_rig` or a
// wrong count leaves the state as before the stages.
void Frontend::Impl::ApplyLateExtrinsics(const std::function<std::vector<Rigid3>()>& late_cam_from_rig,
                                         ViewState&& saved, const std::vector<cv::Mat>& fisheye_images,
                                         ViewBearings* bearings_in_cam, FrontendFrame* frame, double* bearings_ms,
                                         double* bearings_cpu_ms) {
  ExtrinsicsUpdate update;
  try {
    std::vector<Rigid3> cam_from_rig = late_cam_from_rig();
    CheckExtrinsicsCount(cam_from_rig);
    update = PlanExtrinsics(std::move(cam_from_rig));
  } catch (...) {
    RestoreViews(std::move(saved));
    throw;
  }
  if (update.rebuilt.empty()) {
    ApplyExtrinsics(update);
    return;
  }
  RestoreViews(std::move(saved));
  ApplyExtrinsics(update);
  RunViewStages(fisheye_images, bearings_in_cam, frame, bearings_ms, bearings_cpu_ms);
}

void Frontend::Impl::CheckExtrinsicsCount(const std::vector<Rigid3>& cam_from_rig) const {
  if (static_cast<int>(cam_from_rig.size()) != rig.NumCameras()) {
    throw std::invalid_argument("Frontend::SetExtrinsics: " + std::to_string(cam_from_rig.size()) + " extrinsics for " +
                                std::to_string(rig.NumCameras()) + " cameras");
  }
}

Frontend::Impl::ExtrinsicsUpdate Frontend::Impl::PlanExtrinsics(std::vector<Rigid3> cam_from_rig) const {
  ExtrinsicsUpdate update;
  update.layouts = ComputeHybridLayouts(rig.WithExtrinsics(cam_from_rig));
  for (int i = 0; i < rig.NumCameras(); ++i) {
    if (HybridLayoutChangeDeg(projections[i].layout(), projections[i].cam_from_rig(), update.layouts[i],
                              cam_from_rig[i]) > options.projection.rebuild_threshold_deg) {
      update.rebuilt.push_back(i);
    }
  }
  update.cam_from_rig = std::move(cam_from_rig);
  return update;
}

// The epipolar/y filters at once; the warp maps of the views the update rebuilds.
void Frontend::Impl::ApplyExtrinsics(const ExtrinsicsUpdate& update) {
  rig = rig.WithExtrinsics(update.cam_from_rig);
  layouts = update.layouts;
  UpdatePairs();
  tbb::parallel_for(0, static_cast<int>(update.rebuilt.size()), [&](int k) {
    const int i = update.rebuilt[k];
    RebuildView(i, update.cam_from_rig[i]);
  });
}

// View i's warp maps for its new layout; its tracked features are carried over through their bearings
// and the last image is warped again, so that KLT continues between images of the same warp.
void Frontend::Impl::RebuildView(int i, const Rigid3& cam_from_rig) {
  const HybridProjection& old = projections[i];
  HybridProjection rebuilt(rig.cameras[i].camera, cam_from_rig, layouts[i], options.projection);
  std::vector<TrackedPoint> carried;
  for (const TrackedPoint& p : trackers[i].points()) {
    const auto bearing = old.BearingFromWarped(Eigen::Vector2d(p.px.x, p.px.y));
    if (!bearing) continue;
    const auto px = rebuilt.WarpedInImageFromBearing(*bearing);
    if (!px) continue;
    TrackedPoint q = p;
    q.px = cv::Point2f(static_cast<float>(px->x()), static_cast<float>(px->y()));
    carried.push_back(std::move(q));
  }
  projections[i] = std::move(rebuilt);
  UpdateViewMask(i);
  if (!fisheye_gray[i].empty()) {
    projections[i].Warp(fisheye_gray[i], &warped[i]);
    trackers[i].ResetImage(warped[i], view_masks[i], std::move(carried));
  } else {
    trackers[i].Clear();
  }
}

namespace {

// A matched point to move to a sub-pixel position (RefineMatchPositions).
struct Refinement {
  int camera, index;
  cv::Point2f px;
};

// The new matches of a pair whose one side is a fresh detection (age 0; the a side only when b is
// not fresh too) and the other a different track: the fresh side moves to where KLT from the other
// side's patch lands. Matches of one id (re-matched tracks) and of two older tracks are kept as they
// are: moving a tracked point would put a jump into its track.
std::vector<Refinement> RefineNewMatches(const ViewTracker& tracker_a, const ViewTracker& tracker_b, int a, int b,
                                         const std::vector<InterviewMatch>& matches, int window_px) {
  std::vector<Refinement> out;
  const auto& points_a = tracker_a.points();
  const auto& points_b = tracker_b.points();
  for (const bool move_b : {true, false}) {
    std::vector<cv::Point2f> from, to;
    std::vector<int> moving;
    for (const InterviewMatch& match : matches) {
      const TrackedPoint& pa = points_a[match.index_a];
      const TrackedPoint& pb = points_b[match.index_b];
      if (pa.track_id == pb.track_id) continue;
      const bool fresh = move_b ? pb.age == 0 : (pa.age == 0 && pb.age != 0);
      if (!fresh) continue;
      from.push_back(move_b ? pa.px : pb.px);
      to.push_back(move_b ? pb.px : pa.px);
      moving.push_back(move_b ? match.index_b : match.index_a);
    }
    const ViewTracker& source = move_b ? tracker_a : tracker_b;
    const ViewTracker& target = move_b ? tracker_b : tracker_a;
    SubpixelMatchOptions options;
    options.window_px = window_px;
    const auto refined = RefineMatchPositions(source.image(), target.image(), from, to, options);
    for (size_t k = 0; k < refined.size(); ++k) {
      if (refined[k]) out.push_back({move_b ? b : a, moving[k], *refined[k]});
    }
  }
  return out;
}

}  // namespace

void Frontend::Impl::CheckImages(const std::vector<cv::Mat>& fisheye_images) const {
  const int n = rig.NumCameras();
  if (static_cast<int>(fisheye_images.size()) != n) {
    throw std::invalid_argument("Frontend::Process: " + std::to_string(fisheye_images.size()) + " images for " +
                                std::to_string(n) + " cameras");
  }
  for (int i = 0; i < n; ++i) {
    const Camera& camera = rig.cameras[i].camera;
    if (fisheye_images[i].cols != camera.width || fisheye_images[i].rows != camera.height) {
      throw std::invalid_argument("Frontend::Process: image of camera " + std::to_string(i) + " is " +
                                  std::to_string(fisheye_images[i].cols) + "x" +
                                  std::to_string(fisheye_images[i].rows) + ", expected " +
                                  std::to_string(camera.width) + "x" + std::to_string(camera.height));
    }
  }
}

// The warp of view i's gray fisheye image, into a new buffer (the tracker still holds the previous
// warped image), in bands of rows (cheaper, HybridProjection::kWarpBandRows), which a worker done with
// its own views can take part in (isolated: this thread takes no other view's work while it waits).
cv::Mat Frontend::Impl::WarpView(int i) const {
  const HybridProjection& projection = projections[i];
  cv::Mat image(projection.height(), projection.width(), fisheye_gray[i].type());
  const int band = HybridProjection::kWarpBandRows;
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(0, (image.rows + band - 1) / band, [&](int b) {
      projection.WarpRows(fisheye_gray[i], b * band, std::min((b + 1) * band, image.rows), &image);
    });
  });
  return image;
}

// The per-view stages (warp, track, detect + describe, bearings) run fused in one parallel loop
// over the views, without a barrier between stages. Stage times are the section's wall and CPU
// time apportioned by each stage's share of the per-view wall durations summed over the views, added
// to the frame's; the bearings' share is added to *bearings_ms (*bearings_cpu_ms) for the matching time. On more than
// one thread the split is approximate: idle workers help with a view's warp and KLT, which shortens their wall more
// than their CPU.
void Frontend::Impl::RunViewStages(const std::vector<cv::Mat>& fisheye_images, ViewBearings* bearings_in_cam,
                                   FrontendFrame* frame, double* bearings_ms, double* bearings_cpu_ms) {
  const int n = rig.NumCameras();
  enum { kWarp, kTrack, kDetect, kBearings, kStages };
  std::vector<std::array<double, kStages>> view_ms(n);
  bearings_in_cam->assign(n, {});
  const auto section_start = std::chrono::steady_clock::now();
  const double section_cpu_start = CpuMs();
  tbb::parallel_for(0, n, [&](int i) {
    auto start = std::chrono::steady_clock::now();
    const auto lap = [&](int stage) {
      const auto now = std::chrono::steady_clock::now();
      view_ms[i][stage] = std::chrono::duration<double, std::milli>(now - start).count();
      start = now;
    };
    fisheye_gray[i] = ToGray(fisheye_images[i], i);
    warped[i] = WarpView(i);
    lap(kWarp);
    trackers[i].Track(warped[i], view_masks[i]);
    lap(kTrack);
    trackers[i].DetectAndDescribe([] { return uint64_t{0}; });  // ids below
    lap(kDetect);
    const auto& points = trackers[i].points();
    (*bearings_in_cam)[i].reserve(points.size());
    for (const TrackedPoint& p : points) {
      (*bearings_in_cam)[i].push_back(projections[i].BearingFromWarped(Eigen::Vector2d(p.px.x, p.px.y)));
    }
    lap(kBearings);
  });
  // New points got id 0 in parallel; ids in camera order (deterministic).
  for (int i = 0; i < n; ++i) {
    for (TrackedPoint& p : trackers[i].points()) {
      if (p.track_id == 0) p.track_id = ++last_id;
    }
  }
  const double section_ms = MsSince(section_start), section_cpu_ms = CpuMs() - section_cpu_start;
  std::array<double, kStages> stage_sum{};
  for (const auto& times : view_ms) {
    for (int k = 0; k < kStages; ++k) stage_sum[k] += times[k];
  }
  double all_stages = 0;
  for (double t : stage_sum) all_stages += t;
  const auto share = [&](int stage) { return all_stages > 0 ? stage_sum[stage] / all_stages : 0.25; };
  frame->ms_warp += section_ms * share(kWarp);
  frame->ms_track += section_ms * share(kTrack);
  frame->ms_detect += section_ms * share(kDetect);
  frame->cpu_ms_warp += section_cpu_ms * share(kWarp);
  frame->cpu_ms_track += section_cpu_ms * share(kTrack);
  frame->cpu_ms_detect += section_cpu_ms * share(kDetect);
  *bearings_ms += section_ms * share(kBearings);
  *bearings_cpu_ms += section_cpu_ms * share(kBearings);
}

std::vector<MatchView> Frontend::Impl::MakeMatchViews(const ViewBearings& bearings_in_cam) const {
  const int n = rig.NumCameras();
  std::vector<MatchView> views(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d rig_from_cam = rig.cameras[i].cam_from_rig.RotationMatrix().transpose();
    views[i].points = &trackers[i].points();
    views[i].centre_in_rig = rig.cameras[i].cam_from_rig.Inverse().translation;
    views[i].image = &warped[i];
    const HybridProjection* projection = &projections[i];
    const Eigen::Matrix3d cam_from_rig = rig_from_cam.transpose();
    views[i].pixel_from_direction_in_rig = [projection, cam_from_rig](const Eigen::Vector3d& d) {
      return projection->WarpedInImageFromBearing(cam_from_rig * d);
    };
    views[i].bearings_in_rig.reserve(bearings_in_cam[i].size());
    for (const auto& bearing : bearings_in_cam[i]) {
      views[i].bearings_in_rig.push_back(bearing ? Eigen::Vector3d(rig_from_cam * *bearing) : Eigen::Vector3d::Zero());
    }
  }
  return views;
}

// Unify ids sequentially: `from` = the younger (larger) id, `into` = the older one. A merge that
// would put one id twice into a view is refused. Fills last_matches and frame->merged_ids.
void Frontend::Impl::UnifyIds(const std::vector<std::vector<InterviewMatch>>& pair_matches, FrontendFrame* frame) {
  const int n = rig.NumCameras();
  std::vector<std::unordered_map<uint64_t, int>> index_of(n);
  for (int i = 0; i < n; ++i) {
    const auto& points = trackers[i].points();
    for (int k = 0; k < static_cast<int>(points.size()); ++k) index_of[i][points[k].track_id] = k;
  }
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [a, b] = pairs[k];
    for (const InterviewMatch& m : pair_matches[k]) {
      auto& pa = trackers[a].points()[m.index_a];
      auto& pb = trackers[b].points()[m.index_b];
      if (pa.track_id != pb.track_id) {
        const uint64_t into = std::min(pa.track_id, pb.track_id);
        const uint64_t from = std::max(pa.track_id, pb.track_id);
        bool conflict = false;
        for (int i = 0; i < n && !conflict; ++i) conflict = index_of[i].count(from) && index_of[i].count(into);
        if (conflict) continue;
        for (int i = 0; i < n; ++i) {
          const auto it = index_of[i].find(from);
          if (it == index_of[i].end()) continue;
          const int index = it->second;
          trackers[i].points()[index].track_id = into;
          index_of[i].erase(it);
          index_of[i][into] = index;
        }
        frame->merged_ids.emplace_back(from, into);
      }
      last_matches.push_back({a, b, m.index_a, m.index_b});
    }
  }
}

// Inter-view matching of every pair (in parallel), sub-pixel refinement of new matches (their
// bearings updated), then id unification.
void Frontend::Impl::MatchViewsAndUnifyIds(ViewBearings* bearings_in_cam, FrontendFrame* frame) {
  const std::vector<MatchView> views = MakeMatchViews(*bearings_in_cam);
  std::vector<std::vector<InterviewMatch>> pair_matches(pairs.size());
  std::vector<std::vector<Refinement>> refinements(pairs.size());
  tbb::parallel_for(0, static_cast<int>(pairs.size()), [&](int k) {
    const auto [a, b] = pairs[k];
    PairGeometry geometry;
    geometry.up_in_rig = layouts[a].up_in_rig;
    geometry.plane_normal_in_rig = layouts[a].right_normal_in_rig;
    geometry.focal_px = 0.5 * (projections[a].focal_px() + projections[b].focal_px());
    pair_matches[k] = MatchViews(geometry, views[a], views[b], options.matching);
    if (options.refine_matches) {
      refinements[k] = RefineNewMatches(trackers[a], trackers[b], a, b, pair_matches[k], options.klt_window_px);
    }
  });
  for (const auto& list : refinements) {
    for (const Refinement& r : list) {
      TrackedPoint& p = trackers[r.camera].points()[r.index];
      p.px = r.px;
      (*bearings_in_cam)[r.camera][r.index] = projections[r.camera].BearingFromWarped(Eigen::Vector2d(r.px.x, r.px.y));
    }
  }
  UnifyIds(pair_matches, frame);
}

// The output features: every tracked point with a bearing.
void Frontend::Impl::CollectFeatures(const ViewBearings& bearings_in_cam, FrontendFrame* frame) const {
  const int n = rig.NumCameras();
  frame->features_per_camera.resize(n);
  for (int i = 0; i < n; ++i) {
    auto& out = frame->features_per_camera[i];
    const auto& points = trackers[i].points();
    for (size_t k = 0; k < points.size(); ++k) {
      const TrackedPoint& p = points[k];
      const auto& bearing = bearings_in_cam[i][k];
      if (!bearing) continue;
      Feature f;
      f.track_id = p.track_id;
      f.camera = i;
      f.warped_px = Eigen::Vector2f(p.px.x, p.px.y);
      f.bearing_in_cam = *bearing;
      f.age = p.age;
      out.push_back(f);
    }
  }
}

FrontendFrame Frontend::Process(const std::vector<cv::Mat>& fisheye_images) { return Process(fisheye_images, nullptr); }

FrontendFrame Frontend::Process(const std::vector<cv::Mat>& fisheye_images,
                                const std::function<std::vector<Rigid3>()>& late_cam_from_rig) {
  Impl& s = *impl_;
  s.CheckImages(fisheye_images);
  FrontendFrame frame;
  const ScopedOpenCvThreads serial_opencv;
  // Bearings of all points (exact, from the warped pixels), shared by matching and the output.
  Impl::ViewBearings bearings_in_cam;
  double bearings_ms = 0, bearings_cpu_ms = 0;
  Impl::ViewState saved;
  if (late_cam_from_rig) saved = s.SaveViews();
  s.RunViewStages(fisheye_images, &bearings_in_cam, &frame, &bearings_ms, &bearings_cpu_ms);
  if (late_cam_from_rig)
    s.ApplyLateExtrinsics(late_cam_from_rig, std::move(saved), fisheye_images, &bearings_in_cam, &frame, &bearings_ms,
                          &bearings_cpu_ms);

  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = CpuMs();
  s.last_matches.clear();
  if (s.options.match_between_views && !s.pairs.empty()) s.MatchViewsAndUnifyIds(&bearings_in_cam, &frame);
  frame.ms_match = MsSince(start) + bearings_ms;
  frame.cpu_ms_match = CpuMs() - cpu_start + bearings_cpu_ms;

  s.CollectFeatures(bearings_in_cam, &frame);
  return frame;
}

}  // namespace rovo
