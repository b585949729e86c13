#pragma once
// The whole ROVO pipeline over a dataset, writing a run folder (datasets/run.h). Entry point of
// `rovo vo`.
//
// Per frame (paper Sec. IV): front-end features -> 2D-3D correspondences of tracked landmarks ->
// multi-view P3P RANSAC (ransac.h) -> Cauchy pose refinement (pose_refinement.h) -> new landmarks by
// inter-view and multi-frame triangulation (triangulation.h) -> on keyframes, local BA over a
// sliding window, with online extrinsic calibration in OnlineExt mode (local_ba.h).
// Start: the ground-truth first pose; metric scale from inter-view triangulation (rig baselines).
// Failure handling: a frame with too few correspondences, no RANSAC consensus, or a black/missing
// image gets status "lost" and the pose of a constant-velocity prediction; the map is then rebuilt
// from inter-view triangulation at the predicted pose (status "init").

#include "datasets/rigid3.h"
#include "datasets/run.h"
#include "vo/extrinsic_bootstrap.h"
#include "vo/frontend.h"
#include "vo/local_ba.h"
#include "vo/map.h"
#include "vo/pose_refinement.h"
#include "vo/ransac.h"
#include "vo/triangulation.h"

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace rovo {

enum class ExtrinsicsMode { kGroundTruth, kNoisy, kOnline };  // GTExt, NoisyExt, OnlineExt
// "gt" | "noisy" | "online"
ExtrinsicsMode ExtrinsicsModeFromName(const std::string& name);
std::string ExtrinsicsModeName(ExtrinsicsMode mode);

struct VoOptions {
  std::string dataset_dir;
  std::string out_dir;             // run folder
  ExtrinsicsMode mode = ExtrinsicsMode::kGroundTruth;
  int noise_set = 0;               // which perturbed set of dataset.json (noisy/online)
  // A fresh perturbation draw instead of a stored set (noisy/online): when draw_seed >= 0 the starting
  // extrinsics are PerturbExtrinsics(ground-truth rig, draw_sigma_deg, 0, draw_seed) (datasets/rig.h),
  // the paper's protocol (roll, pitch, yaw of every camera, camera 0 included; centres kept).
  int64_t draw_seed = -1;
  double draw_sigma_deg = 5.0;
  uint64_t seed = 0;               // RANSAC seed
  int threads = 0;                 // 0 = all cores
  int frame_begin = 0;
  int frame_end = -1;              // -1 = to the end
  std::string sampling = "pps";    // "pps" | "uniform" (ablation)
  std::string ransac = "multiview";  // "multiview" | "single-view" (ablation)
  bool quiet = false;
  // OnlineExt: a bound on the starting extrinsics' rotation error between cameras (degrees). It
  // loosens the inter-view filters for the start-up calibration (extrinsic_bootstrap.h); 0 = none.
  double online_prior_deg = 15.0;
  int online_bootstrap_rounds = 6;
  // OnlineExt: synchronous shots pooled by the start-up calibration's ring stage (startup_calibration.h),
  // every StartupCalibrationOptions::shot_spacing frames from the first.
  int online_startup_shots = 1;
  // RANSAC inlier threshold (MultiViewRansacOptions::tau_rad) in degrees: one angle for every rig,
  // as the paper's cost is angular (max(0, tau - angle)). Until 2026-11-21 it was 2 pixels at the
  // image centre: 0.29 deg on the full-size rovo4 lenses but 0.60 deg on canyon_multifov's, whose
  // drifted tracks then counted as inliers (reprojection error 0.18 deg). With 0.2 deg, whole
  // sequences: canyon_multifov reprojection 0.178 -> 0.086 deg (GTExt), relative RMSE within the
  // run-to-run spread on all five presets (docs/design-notes.md), inlier ratios lower (canyon_multifov OnlineExt
  // 82 -> 49 %, back to 78 % with BackendOptions::online_settle_frames).
  double ransac_tau_deg = 0.2;
  // Back-end settings exposed on the command line; <= 0 keeps BackendOptions' default.
  double keyframe_distance_m = 0.0;      // KeyframeOptions::min_translation_m
  int online_settle_frames = -1;         // BackendOptions::online_settle_frames (< 0: its default)
  // FrontendOptions::max_new_features_per_view (0: no limit). 150 saves about a fifth of the front-end's
  // CPU (206 -> 162 CPU-ms per full-size frame) at some accuracy: measured 2026-11-22 on whole
  // sequences, OnlineExt relative RMSE worse on all five presets (mean 0.018 -> 0.024 %), GTExt 3 better
  // and 2 worse; quick cloudy_urban GTExt 0.018 -> 0.038 %. So it is a setting, not the default.
  int max_new_features = 0;
  // HybridProjectionOptions::vertical_fov_below_deg: how far below the rig plane the warp reaches
  // (the start-up calibration always uses the full default warp). 25 is a real-time setting, not the
  // default (docs/design-notes.md): fresh detections more than 25 deg below the rig plane (the road beside
  // the vehicle) survived their first KLT step 3 % of the time at full size (cloudy_urban, 40 frames:
  // 18485 of 49772 fresh detections, against 12-41 % above), so cutting the warp there makes the
  // full-size front-end about 18 % cheaper with neutral accuracy over 300 frames, but at the quick
  // forms' half size those features track and matter (quick cloudy_urban OnlineExt 0.052 -> 0.086 %).
  double warp_below_deg = 50.0;
  bool async_ba = true;                  // BackendOptions::async_ba (same trajectory in GTExt/NoisyExt)
  bool preload_images = false;           // decode all frames before the loop (timing without PNG decoding)
};

// Mean wall time per processed frame, by stage, in milliseconds.
struct VoStageTimes {
  double warp = 0, detect = 0, track = 0, match = 0;  // front-end (FrontendFrame::ms_*)
  double cpu_warp = 0, cpu_detect = 0, cpu_track = 0, cpu_match = 0;  // front-end CPU, all threads (cpu_ms_*)
  double load = 0;  // waiting for the images (read on a second thread while the previous frame runs)
  double ransac = 0, refine = 0, triangulate = 0, backend_total = 0;
  double ba = 0;       // keyframe BA solve (on its own thread with async BA)
  double ba_wait = 0;  // time the pipeline waited for an async BA to finish
  double ransac_us_per_hypothesis = 0;
  double total = 0;                                     // whole frame incl. loading
};

struct VoSummary {
  int frames = 0;
  int frames_ok = 0;
  int frames_lost = 0;
  double seconds = 0.0;
  int frames_init = 0;
  int frames_with_missing_images = 0;    // frames where some camera's image was missing or unreadable
  int missing_images = 0;                // (frame, camera) images missing or unreadable
  double mean_inlier_ratio = 0.0;        // over "ok" frames
  double mean_reproj_error_deg = 0.0;    // over "ok" frames
  VoStageTimes stage_ms;
};

VoSummary RunVo(const VoOptions& options);

// ---------------------------------------------------------------------------------------------
// The back-end alone (everything after the front-end), usable on synthetic FrontendFrames.

struct BackendOptions {
  MultiViewRansacOptions ransac;
  PoseRefinementOptions refine;
  TriangulationOptions interview_triangulation;   // same frame, >= 2 cameras
  TriangulationOptions multiframe_triangulation;  // several frames
  LocalBaOptions ba;                              // ba.optimize_extrinsics = OnlineExt
  KeyframeOptions keyframes;
  bool local_ba = true;
  int window_keyframes = 6;          // sliding window size
  int max_ba_landmarks = 800;        // bound on BA size (landmarks with most observations)
  int min_features = 20;             // fewer features in all views: frame lost (e.g. black image)
  int min_correspondences = 15;      // fewer 2D-3D correspondences: frame lost
  double min_inlier_ratio = 0.15;    // below: no consensus
  int min_init_landmarks = 15;       // inter-view points needed to (re)initialise
  int max_unseen_frames = 2;         // landmarks unseen for longer are dropped
  // Keyframe BA on a second thread, beside the caller's work on the next frame (its front-end): the
  // solve starts at the end of ProcessFrame(k) and is joined and applied by FinishPendingBa, which
  // ProcessFrame(k + 1) calls first. Results equal the synchronous order exactly; the caller sees the
  // BA-refined pose and extrinsics of frame k only after FinishPendingBa.
  bool async_ba = false;
  double max_landmark_error_deg = 2.0;  // BA observations above are dropped
  // Online calibration settles over the first `online_settle_frames` frames after the first one: in
  // them, an observation off its landmark by less than online_max_error_deg is kept (BA sees it), as
  // the extrinsics are still moving; afterwards one off by more than the RANSAC threshold is
  // rejected, as in GTExt. Keeping the 0.2-2 deg observations for the whole run (as before
  // 2026-11-21) let them into the map: canyon_multifov OnlineExt counted 1730 correspondences per
  // frame against GTExt's 1480, and 49 % inliers against 79 %, even when started at the true
  // extrinsics. The start-up calibration (extrinsic_bootstrap.h) leaves ~0.1 deg. Without it
  // (--online-prior 0) the BA alone does not correct degree-sized errors at all, whatever these two
  // are: its random-walk prior (LocalBaOptions::extrinsic_prior_deg, 0.005 deg per solve) holds them
  // (quick cloudy_urban: 14 deg at the end, with a 2 or a 12 deg bound).
  double online_max_error_deg = 2.0;
  int online_settle_frames = 50;
  void Check() const;
};

struct BackendFrameResult {
  Rigid3 world_from_rig;     // with async_ba on a keyframe: before its BA (FinishPendingBa gives the refined one)
  FrameRecord record;        // status, counts, errors (frame and timestamp filled by the caller)
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
  struct PendingBa;
  bool Initialise(int frame, const Rigid3& rig_from_world, BackendFrameResult* result);
  void AddObservations(int frame, const FrontendFrame& frontend, const std::vector<std::vector<char>>* rejected);
  int TriangulateNew(int frame);
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
