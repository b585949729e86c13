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
  // KLT forward-backward round-trip error. 0.3 px instead of 1: drops the tracks that slide over the
  // texture (occlusion edges, strong perspective change). Measured 2026-11-21, full size, first 300
  // frames, GTExt (with refine_matches): relative RMSE cloudy 0.026 -> 0.021 %, sunset 0.028 -> 0.025 %,
  // static 0.046 -> 0.019 %, dynamic 0.077 -> 0.050 %, canyon_multifov 0.140 -> 0.103 %; inlier ratio
  // +3..5 points. Why sliding tracks shorten the trajectory: README, known limitations.
  float max_forward_backward_px = 0.3f;
  // KLT: window 15 with <= 20 iterations down to 0.03 px costs ~60 % of the former 21 / 30 / 0.01
  // px. Measured 2026-11-21 on the quick cloudy/sunset datasets (GTExt and OnlineExt of both):
  // inlier ratio +1.2..2.1 points (mean of RANSAC seeds 0-3) and reprojection error -0.011..-0.016
  // deg (seed 0) in all four; mean relative RMSE over seeds 0-3: GTExt cloudy 0.073 -> 0.053 %,
  // OnlineExt cloudy 0.107 -> 0.073 %, OnlineExt sunset 0.104 -> 0.050 %, GTExt sunset 0.090 -> 0.116 %.
  int klt_window_px = 15;        // KLT window side (warped pixels)
  int klt_levels = 3;            // KLT pyramid levels above the base
  int klt_max_iterations = 20;   // KLT iterations per pyramid level (at most)
  float klt_epsilon_px = 0.03f;  // KLT convergence: update below this (warped pixels)
  // Forward pass from the last displacement (TrackerOptions explains). With the independent
  // backward check (tracking.h), measured 2026-11-21 on full-size datasets, first 300 frames,
  // GTExt, against a forward pass from zero flow without it: relative RMSE dynamic_urban 0.051 -> 0.046 %,
  // canyon_multifov 0.245 -> 0.071 %, cloudy_urban 0.022 -> 0.016 %, sunset_urban 0.029 -> 0.021 %;
  // inlier ratio +0.4..2.0 points.
  bool klt_predict_flow = true;
  int klt_predicted_levels = 0;  // levels of a predicted forward pass
  // ORB descriptors upright (TrackerOptions::upright_descriptors): the hybrid views agree on "up", so
  // rotation invariance only adds the intensity-centroid angle's noise. `rovo study projection`, half-size
  // cloudy_urban, 100 frames: descriptor distance along tracks 76.6 -> 53.6 (frame to frame 41.7 -> 22.8),
  // correct matches of the front-end 10634 -> 14487 (precision 94.2 -> 92.9 %). Whole sequences in the
  // docs/results.md; canyon_multifov GTExt 0.050 -> 0.038 %. The start-up calibration keeps oriented descriptors
  // (its views are rotated against each other by the extrinsic errors).
  bool upright_descriptors = true;
  HybridProjectionOptions projection;  // warp geometry (focal, extents, rebuild threshold)
  InterviewMatchOptions matching;      // inter-view filters
  bool match_between_views = true;     // inter-view matching on/off (ablation)
  // Sub-pixel refinement of new inter-view matches (RefineMatchPositions, interview_matching.h).
  // Measured on dynamic_urban full size, first 300 frames, GTExt: relative RMSE 0.077 -> 0.070 %,
  // inlier ratio 89.4 -> 89.9 %, reprojection error 0.078 -> 0.075 deg.
  bool refine_matches = true;
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
  // Per-camera static masks of the fisheye images (8-bit, the camera's size, 0 = invalid: rig body,
  // vehicle, operator), or none. No feature is detected or tracked where a mask is 0: they are
  // warped with each view and eroded by half an ORB patch.
  void SetStaticMasks(const std::vector<cv::Mat>& fisheye_masks);
  // Inter-view filter thresholds from the next Process call on (the back-end loosens the epipolar
  // and y filters while online calibration has not converged).
  void SetMatchingOptions(const InterviewMatchOptions& matching);
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
