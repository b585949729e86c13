#pragma once
// The seam between the ROVO front-end (paper IV-A, IV-B: hybrid projection, intra-view tracking,
// inter-view matching) and the back-end (IV-C, IV-D: pose estimation, mapping, local BA).
//
// Identity: a feature's `track_id` names a scene point, not a 2D track. KLT keeps the id from frame
// to frame within a view; an accepted inter-view match gives both features one id, so a point seen
// in two views at the same frame carries the same id in both, and a point that leaves one view and
// continues in the next keeps its id. The back-end keys landmarks by track_id.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "datasets/rig.h"
#include "vo/hybrid_projection.h"
#include "vo/interview_matching.h"
#include "vo/tracking.h"

namespace rovo {

struct Feature {
  uint64_t track_id = 0;
  int camera = 0;
  Eigen::Vector2f warped_px;       // in the camera's hybrid-projection image
  Eigen::Vector3d bearing_in_cam;  // unit, exact (from the warped pixel through the model)
  int age = 0;                     // frames this id has been tracked in this view
};

struct FrontendFrame {
  std::vector<std::vector<Feature>> features_per_camera;  // index = camera
  // (from, into): ids the front-end unified this frame because an inter-view match joined two
  // existing tracks; the back-end merges landmark `from` into `into`.
  std::vector<std::pair<uint64_t, uint64_t>> merged_ids;
  // Wall time per stage in milliseconds: warp, detect, track, match. Warp, track and detect run
  // fused per view in one parallel loop; their times are that section's wall (and CPU) time split
  // by each stage's share of the per-view durations summed over views. Match includes the bearings.
  double ms_warp = 0, ms_detect = 0, ms_track = 0, ms_match = 0;
  // Process CPU time (all threads) per stage in milliseconds: the cost on a loaded machine.
  double cpu_ms_warp = 0, cpu_ms_detect = 0, cpu_ms_track = 0, cpu_ms_match = 0;
};

struct FrontendOptions {
  int target_features_per_view = 600;  // KLT tracks + new detections per view
  int max_new_features_per_view = 0;   // TrackerOptions::max_new_per_frame (0: no limit)
  float min_feature_distance_px = 12;  // between features of one view (warped pixels)
  int fast_threshold = 12;             // FAST-9 threshold of the detector
  // KLT forward-backward round trip: drops tracks that slide over the texture (docs/design-notes.md).
  float max_forward_backward_px = 0.3f;
  // KLT settings: cheaper and more accurate than larger windows (docs/design-notes.md).
  int klt_window_px = 15;        // KLT window side (warped pixels)
  int klt_levels = 3;            // KLT pyramid levels above the base
  int klt_max_iterations = 20;   // KLT iterations per pyramid level (at most)
  float klt_epsilon_px = 0.03f;  // KLT convergence: update below this (warped pixels)
  // Forward pass from the last displacement (TrackerOptions explains; figures in docs/design-notes.md).
  bool klt_predict_flow = true;
  int klt_predicted_levels = 0;  // levels of a predicted forward pass
  // ORB descriptors upright (TrackerOptions::upright_descriptors): the hybrid views agree on "up", so
  // rotation invariance only adds noise (docs/design-notes.md).
  bool upright_descriptors = true;
  HybridProjectionOptions projection;  // warp geometry (focal, extents, rebuild threshold)
  InterviewMatchOptions matching;      // inter-view filters
  bool match_between_views = true;     // inter-view matching on/off (ablation)
  // Sub-pixel refinement of new inter-view matches (RefineMatchPositions, interview_matching.h).
  bool refine_matches = true;
  void Check() const;  // throws std::invalid_argument naming the field
};

// The tracker settings of a front-end configuration (its per-view target and KLT/detector fields).
TrackerOptions TrackerOptionsFrom(const FrontendOptions& options);

// The front-end: per frame, warps each fisheye image with its camera's hybrid projection, tracks
// (KLT) and re-detects features per view, attaches ORB descriptors, matches neighbouring views in
// their overlaps and unifies track ids (identity rules above). Views run in parallel (TBB).
//
// Threads: views run in parallel under TBB (the caller's tbb::global_control bounds them); Process
// and SetExtrinsics set OpenCV's own thread count to 1 while they run (cv::setNumThreads is
// process-wide; restored on return), so other OpenCV work must not run concurrently with them.
//
// Extrinsics: the rig passed in is the current (possibly noisy) calibration. SetExtrinsics updates
// the epipolar/y filters at once; a camera's warp maps are rebuilt only when its hybrid layout moves
// by more than options.projection.rebuild_threshold_deg (hybrid_projection.h), and its tracked
// features are then carried over through their bearings.
class Frontend {
 public:
  Frontend(const Rig& rig, const FrontendOptions& options = {});
  ~Frontend();

  // One image per camera, 8-bit gray or BGR, each of its camera's size. Throws std::invalid_argument
  // on a wrong count, size or type.
  FrontendFrame Process(const std::vector<cv::Mat>& fisheye_images);
  void SetExtrinsics(const std::vector<Rigid3>& cam_from_rig);
  // The same as SetExtrinsics(late_cam_from_rig()) then Process(fisheye_images), for extrinsics that
  // arrive while the frame is processed (OnlineExt's local BA): the per-view stages (warp, KLT,
  // detection) run first, then `late_cam_from_rig` is called (it may wait). Where those extrinsics
  // rebuild no view's warp maps, the per-view stages did not depend on them; where they do, the stages
  // are undone and run again after them. Throws what both calls would throw; an exception from
  // `late_cam_from_rig` or a wrong count of extrinsics leaves the front-end as before the call.
  FrontendFrame Process(const std::vector<cv::Mat>& fisheye_images,
                        const std::function<std::vector<Rigid3>()>& late_cam_from_rig);
  // Per-camera static masks of the fisheye images (8-bit, the camera's size, 0 = invalid: rig body,
  // vehicle, operator), or none. No feature is detected or tracked where a mask is 0: they are
  // warped with each view and eroded by half an ORB patch.
  void SetStaticMasks(const std::vector<cv::Mat>& fisheye_masks);
  const FrontendOptions& options() const;

  const HybridProjection& projection(int camera) const;
  int NumCameras() const;
  // Warped gray image of a camera at the last Process call (for drawing and studies).
  const cv::Mat& warped_image(int camera) const;
  // The tracker state of a camera (points with descriptors after the last Process call).
  const ViewTracker& tracker(int camera) const;
  // Inter-view matches accepted at the last Process call: (camera a, camera b, index in a, index in b).
  struct ViewMatch {
    int camera_a, camera_b, index_a, index_b;
  };
  const std::vector<ViewMatch>& last_matches() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rovo
