#pragma once
// The ROVO back-end: everything after the front-end (frontend.h), one FrontendFrame at a time; RunVo
// (pipeline.h) drives it over a dataset, and tests drive it on synthetic FrontendFrames.
//
// Per frame (paper Sec. IV): 2D-3D correspondences of tracked landmarks -> multi-view P3P RANSAC
// (ransac.h) -> Cauchy pose refinement (pose_refinement.h) -> new landmarks by inter-view and
// multi-frame triangulation (triangulation.h) -> on keyframes, local BA over a sliding window, with
// online extrinsic calibration in OnlineExt mode (local_ba.h).
// Start: the given first pose (RunVo: the ground-truth one); metric scale from inter-view
// triangulation (rig baselines).
// Failure handling: a frame with too few features (black or missing images) gets status "lost" and
// the pose of a constant-velocity prediction; a frame with too few correspondences or no RANSAC
// consensus, and the first frame after a lost one, rebuild the map from inter-view triangulation at
// the predicted pose (status "init", or "lost" when too few points triangulate).

#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "datasets/rigid3.h"
#include "datasets/run.h"
#include "vo/frontend.h"
#include "vo/local_ba.h"
#include "vo/map.h"
#include "vo/pose_refinement.h"
#include "vo/ransac.h"
#include "vo/triangulation.h"

namespace rovo {

struct BackendOptions {
  MultiViewRansacOptions ransac;
  PoseRefinementOptions refine;
  TriangulationOptions interview_triangulation;   // same frame, >= 2 cameras
  TriangulationOptions multiframe_triangulation;  // several frames
  LocalBaOptions ba;                              // ba.optimize_extrinsics = OnlineExt
  KeyframeOptions keyframes;
  bool local_ba = true;
  int window_keyframes = 6;        // sliding window size
  int max_ba_landmarks = 800;      // bound on BA size (landmarks with most observations)
  int min_features = 20;           // fewer features in all views: frame lost (e.g. black image)
  int min_correspondences = 15;    // fewer 2D-3D correspondences: frame lost
  double min_inlier_ratio = 0.15;  // below: no consensus
  int min_init_landmarks = 15;     // inter-view points needed to (re)initialise
  int max_unseen_frames = 2;       // landmarks unseen for longer are dropped
  // Keyframe BA on a second thread, beside the caller's work on the next frame (its front-end): the
  // solve starts at the end of ProcessFrame(k) and is joined and applied by FinishPendingBa, which
  // ProcessFrame(k + 1) calls first. Results equal the synchronous order exactly; the caller sees the
  // BA-refined pose and extrinsics of frame k only after FinishPendingBa.
  bool async_ba = true;
  double max_landmark_error_deg = 2.0;  // BA observations above are dropped
  // Online calibration settles over the first `online_settle_frames` frames after the first one: in
  // them, an observation off its landmark by less than online_max_error_deg is kept, as the extrinsics
  // are still moving; afterwards the RANSAC threshold rejects it, as in GTExt (docs/design-notes.md).
  double online_max_error_deg = 2.0;
  int online_settle_frames = 50;
  void Check() const;
};

struct BackendFrameResult {
  Rigid3 world_from_rig;  // with async_ba on a keyframe: before its BA (FinishPendingBa gives the refined one)
  FrameRecord record;     // status, counts, errors (frame and timestamp filled by the caller)
  double ms_ransac = 0, ms_refine = 0, ms_triangulate = 0, ms_ba = 0;  // ms_ba: synchronous BA only
  int ransac_hypotheses = 0;
  int num_landmarks = 0;
};

class VoBackend {
 public:
  VoBackend(const std::vector<Rigid3>& initial_cam_from_rig, const Rigid3& initial_world_from_rig,
            const BackendOptions& options);

  // `frame` must increase between calls (gaps allowed). `frontend` may be empty (unreadable image).
  BackendFrameResult ProcessFrame(int frame, const FrontendFrame& frontend);

  // Joins a keyframe BA still running (async_ba) and applies it. Returns the frame it belonged to with
  // that frame's BA-refined world_from_rig (the caller's record of the frame should be updated), or
  // nothing when no BA was pending. Call before reading cam_from_rig() or map() in async mode.
  struct BaUpdate {
    int frame = 0;
    Rigid3 world_from_rig;
    double ms_solve = 0;  // BA time on its thread
    double ms_wait = 0;   // time this call waited for it
  };
  std::optional<BaUpdate> FinishPendingBa();

  const std::vector<Rigid3>& cam_from_rig() const { return cam_from_rig_; }
  const LandmarkMap& map() const { return map_; }

  ~VoBackend();
  VoBackend(const VoBackend&) = delete;
  VoBackend& operator=(const VoBackend&) = delete;

 private:
  struct Correspondences;
  struct PendingBa;
  // Failure steps of ProcessFrame: status "lost" at the predicted pose, or the map rebuilt there from
  // this frame's inter-view points (Initialise; status "init", "lost" when too few).
  void Lose(const Rigid3& predicted_rig_from_world, BackendFrameResult* result);
  void Reinitialise(int frame, const FrontendFrame& frontend, const Rigid3& predicted_rig_from_world,
                    BackendFrameResult* result);
  bool Initialise(int frame, const Rigid3& rig_from_world, BackendFrameResult* result);
  // Tracking steps of ProcessFrame: the frame's 2D-3D correspondences, then inliers and rejections
  // under the refined pose.
  Correspondences CollectCorrespondences(const FrontendFrame& frontend) const;
  std::vector<std::vector<char>> ClassifyUnderPose(int frame, const FrontendFrame& frontend,
                                                   const Correspondences& corrs, const Rigid3& rig_from_world,
                                                   FrameRecord* record);
  void AddObservations(int frame, const FrontendFrame& frontend, const std::vector<std::vector<char>>* rejected);
  int TriangulateNew(int frame);
  bool IsNewKeyframe(int frame) const;
  double StartLocalBa(int frame);
  // Local BA in three steps: the problem from the map (window keyframes, best-observed landmarks),
  // the solve (touches only the PendingBa), the write-back plus the frame's culling.
  std::unique_ptr<PendingBa> PrepareLocalBa(int frame) const;
  void ApplyLocalBa(PendingBa& pending);
  void Cull(int frame);
  Rigid3 PredictRigFromWorld(int frame) const;
  std::vector<Rigid3> WorldFromCam(const Rigid3& rig_from_world) const;

  BackendOptions options_;
  std::vector<Rigid3> cam_from_rig_;
  std::vector<double> baseline_lengths_;
  Rigid3 initial_rig_from_world_;
  LandmarkMap map_;
  std::map<int, Rigid3> rig_from_world_;  // estimated poses of recent frames
  std::vector<int> keyframes_;            // window, oldest first
  bool initialised_ = false;
  int first_frame_ = -1;  // of the run (online_settle_frames)
  int last_good_frame_ = -1;
  int previous_good_frame_ = -1;
  std::unique_ptr<PendingBa> pending_ba_;
};

}  // namespace rovo
