#pragma once
// The whole ROVO pipeline over a dataset, writing a run folder (datasets/run.h). Entry point of
// `rovo vo`.
//
// RunVo: the starting extrinsics (ground truth, a stored perturbed set or a fresh draw), in OnlineExt
// the start-up calibration (startup_calibration.h), then per frame the images (image_loader.h, read
// ahead on a second thread) -> Frontend (frontend.h) -> VoBackend (backend.h), starting at the
// ground-truth first pose (identity without ground truth); the run folder is written at the end.

#include "vo/vo_options.h"

namespace rovo {

// Mean wall time per frame, by stage, in milliseconds: over the frames from VoIoOptions::timed_from on.
struct VoStageTimes {
  double warp = 0, detect = 0, track = 0, match = 0;                  // front-end (FrontendFrame::ms_*)
  double cpu_warp = 0, cpu_detect = 0, cpu_track = 0, cpu_match = 0;  // front-end CPU, all threads (cpu_ms_*)
  double load = 0;  // waiting for the images (read on a second thread while the previous frame runs)
  double ransac = 0, refine = 0, triangulate = 0, backend_total = 0;
  double ba = 0;       // keyframe BA solve (on its own thread with async BA)
  double ba_wait = 0;  // time the pipeline waited for an async BA to finish
  double ransac_us_per_hypothesis = 0;
  double total = 0;  // whole frame: the loop's time per frame (a front-end runs beside the previous back-end)
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
  double lens_angle_scale = 1.0;       // applied to the dataset's lenses (VoStartupOptions::apply_lens_scale)
  // OnlineExt's start-up calibration, before the first frame: wall and process CPU time (0 without it).
  double startup_ms = 0.0;
  double startup_cpu_ms = 0.0;
  VoStageTimes stage_ms;
};

VoSummary RunVo(const VoOptions& options);  // calls options.Check()

}  // namespace rovo
