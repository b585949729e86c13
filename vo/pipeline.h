#pragma once
// The whole ROVO pipeline over a dataset, writing a run folder (datasets/run.h). Entry point of
// `rovo vo`.
//
// RunVo: the starting extrinsics (ground truth, a stored perturbed set or a fresh draw), in OnlineExt
// the start-up calibration (startup_calibration.h), then per frame the images (image_loader.h, read
// ahead on a second thread) -> Frontend (frontend.h) -> VoBackend (backend.h), starting at the
// ground-truth first pose (identity without ground truth); the run folder is written at the end.

#include <cstdint>
#include <string>

#include "vo/backend.h"

namespace rovo {

enum class ExtrinsicsMode { kGroundTruth, kNoisy, kOnline };  // GTExt, NoisyExt, OnlineExt
// "gt" | "noisy" | "online"
ExtrinsicsMode ExtrinsicsModeFromName(const std::string& name);
std::string ExtrinsicsModeName(ExtrinsicsMode mode);

struct VoOptions {
  std::string dataset_dir;
  std::string out_dir;  // run folder
  ExtrinsicsMode mode = ExtrinsicsMode::kGroundTruth;
  int noise_set = 0;  // which perturbed set of dataset.json (noisy/online)
  // A fresh perturbation draw instead of a stored set (noisy/online): when draw_seed >= 0 the starting
  // extrinsics are PerturbExtrinsics(ground-truth rig, draw_sigma_deg, 0, draw_seed) (datasets/rig.h),
  // the paper's protocol (roll, pitch, yaw of every camera, camera 0 included; centres kept).
  int64_t draw_seed = -1;
  double draw_sigma_deg = 5.0;
  uint64_t seed = 0;  // RANSAC seed
  int threads = 0;    // 0 = all cores
  int frame_begin = 0;
  int frame_end = -1;                // -1 = to the end
  std::string sampling = "pps";      // "pps" | "uniform" (ablation)
  std::string ransac = "multiview";  // "multiview" | "single-view" (ablation)
  bool quiet = false;
  // OnlineExt: a bound on the starting extrinsics' rotation error between cameras (degrees). It
  // loosens the inter-view filters for the start-up calibration (extrinsic_bootstrap.h); 0 = none.
  double online_prior_deg = 15.0;
  int online_bootstrap_rounds = 6;
  // OnlineExt: synchronous shots pooled by the start-up calibration's ring stage (startup_calibration.h),
  // every StartupCalibrationOptions::shot_spacing frames from the first.
  // Three shots pooled: quick canyon_multifov's start-up error (20 draws) from median 0.115 / worst
  // 0.168 deg with one shot to all below 0.075 deg.
  int online_startup_shots = 3;
  int online_startup_spacing = 10;  // frames between two of those shots
  // OnlineExt: every keyframe BA pulls the extrinsics towards a converged start-up calibration's result
  // with this rotation sigma in degrees (LocalBaOptions::extrinsic_anchor_deg); 0: no anchor.
  double online_anchor_deg = 0.02;
  // With it, the centres' sigma in millimetres (LocalBaOptions::extrinsic_anchor_m); 0: not held.
  double online_anchor_mm = 3.0;
  // OnlineExt: the VO sees through lenses whose off-axis angles are scaled by the start-up's estimate
  // (RingCalibrationReport::angle_scale, datasets/lens_angle_scale.h) when it converged with one;
  // false: the dataset's lenses (the scale is only reported).
  bool online_apply_lens_scale = true;
  // RANSAC inlier threshold (MultiViewRansacOptions::tau_rad) in degrees: one angle for every rig,
  // as the paper's cost is angular (max(0, tau - angle)). Until 2026-11-21 it was 2 pixels at the
  // image centre: 0.29 deg on the full-size rovo4 lenses but 0.60 deg on canyon_multifov's, whose
  // drifted tracks then counted as inliers (reprojection error 0.18 deg). With 0.2 deg, whole
  // sequences: canyon_multifov reprojection 0.178 -> 0.086 deg (GTExt), relative RMSE within the
  // run-to-run spread on all five presets (docs/design-notes.md), inlier ratios lower (canyon_multifov OnlineExt
  // 82 -> 49 %, back to 78 % with BackendOptions::online_settle_frames).
  double ransac_tau_deg = 0.2;
  // Back-end settings exposed on the command line; <= 0 keeps BackendOptions' default.
  double keyframe_distance_m = 0.0;  // KeyframeOptions::min_translation_m
  int online_settle_frames = -1;     // BackendOptions::online_settle_frames (< 0: its default)
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
  bool async_ba = true;         // BackendOptions::async_ba (same trajectory in GTExt/NoisyExt)
  bool preload_images = false;  // decode all frames before the loop (timing without PNG decoding)
};

// Mean wall time per processed frame, by stage, in milliseconds.
struct VoStageTimes {
  double warp = 0, detect = 0, track = 0, match = 0;                  // front-end (FrontendFrame::ms_*)
  double cpu_warp = 0, cpu_detect = 0, cpu_track = 0, cpu_match = 0;  // front-end CPU, all threads (cpu_ms_*)
  double load = 0;  // waiting for the images (read on a second thread while the previous frame runs)
  double ransac = 0, refine = 0, triangulate = 0, backend_total = 0;
  double ba = 0;       // keyframe BA solve (on its own thread with async BA)
  double ba_wait = 0;  // time the pipeline waited for an async BA to finish
  double ransac_us_per_hypothesis = 0;
  double total = 0;  // whole frame incl. loading
};

struct VoSummary {
  int frames = 0;
  int frames_ok = 0;
  int frames_lost = 0;
  double seconds = 0.0;
  int frames_init = 0;
  int frames_with_missing_images = 0;  // frames where some camera's image was missing or unreadable
  int missing_images = 0;              // (frame, camera) images missing or unreadable
  double mean_inlier_ratio = 0.0;      // over "ok" frames
  double mean_reproj_error_deg = 0.0;  // over "ok" frames
  double lens_angle_scale = 1.0;       // applied to the dataset's lenses (VoOptions::online_apply_lens_scale)
  VoStageTimes stage_ms;
};

VoSummary RunVo(const VoOptions& options);

}  // namespace rovo
