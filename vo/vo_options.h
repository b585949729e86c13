#pragma once
// The options of a VO run (RunVo, pipeline.h) as one tree, and the registry of the fields a user sets.
// Each such field is declared once, in ForEachVoOption: the command-line flags, run.json's record of
// the settings and the suite's reuse check all come from there (COLMAP's OptionManager is the model).
// Enums inside; their names only at the file and command-line boundary (the name tables below).

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "vo/backend.h"
#include "vo/frontend.h"

namespace rovo {

enum class ExtrinsicsMode { kGroundTruth, kNoisy, kOnline };  // GTExt, NoisyExt, OnlineExt
// "gt" | "noisy" | "online"
ExtrinsicsMode ExtrinsicsModeFromName(const std::string& name);
std::string ExtrinsicsModeName(ExtrinsicsMode mode);

struct FrameRange {
  int begin = 0;
  int end = -1;  // exclusive; -1: to the dataset's end
};

// Where the run reads and writes, and how it runs.
struct VoIoOptions {
  std::string dataset_dir;
  std::string out_dir;  // run folder
  FrameRange frames;
  int threads = 0;       // 0: all cores
  bool quiet = false;    // no progress output
  bool preload = false;  // decode all frames before the loop (timing without PNG decoding)
  int timed_from = 0;    // VoSummary::stage_ms over the frames from this index of the range on
  // The dataset cameras the VO uses: "auto" (the cameras whose lens sees more than 180 degrees, the
  // fisheye ring ROVO is made for, when the rig has any; else all), "all", or indices "0,1,2,3"
  // (increasing, with camera 0, the gauge of the extrinsics). run.json "vo_cameras" lists them.
  std::string cameras = "auto";
  // Undo the lens's lateral colour that dataset.json "optics" states before colour images become
  // gray (image_loader.h, lateral_colour.h); false: gray as decoded.
  bool undo_lateral_colour = true;
  // Undo its relative illumination (flat_field.h); false: the images' brightness as decoded.
  bool flat_field = true;
  void Check() const;  // throws std::invalid_argument naming the flag
};

// The starting extrinsics: the rig's (GTExt), a stored perturbed set or a fresh draw (NoisyExt, OnlineExt).
struct VoStartOptions {
  ExtrinsicsMode mode = ExtrinsicsMode::kGroundTruth;
  int noise_set = 0;  // which perturbed set of dataset.json
  // >= 0: PerturbExtrinsics(ground-truth rig, draw_sigma_deg, 0, draw_seed) (datasets/rig.h) instead of
  // a stored set, the paper's protocol (roll, pitch, yaw of every camera; centres kept).
  int64_t draw_seed = -1;
  double draw_sigma_deg = 5.0;
  void Check() const;
};

// OnlineExt's start-up calibration (startup_calibration.h) and what the local BA keeps of it.
struct VoStartupOptions {
  bool enabled = true;  // false: the local BA alone (an ablation)
  int shots = 3;        // synchronous shots pooled (StartupCalibrationOptions::shots)
  int spacing = 10;     // frames between two shots
  // Up to this many shots where the first attempt's overlaps are poor: its weakest ring pair keeps
  // fewer than min_pair_inliers inliers, or it fails (StartupCalibrationOptions::max_shots).
  int max_shots = 6;
  int min_pair_inliers = 300;
  // Every keyframe BA pulls the extrinsics towards a converged result with these sigmas
  // (LocalBaOptions::extrinsic_anchor_deg, extrinsic_anchor_m); 0: not held.
  double anchor_deg = 0.02;
  double anchor_mm = 3.0;
  // The VO sees through lenses scaled by a converged angle scale (datasets/lens_angle_scale.h);
  // false: the dataset's lenses, the scale only reported.
  bool apply_lens_scale = true;
  void Check() const;
};

struct VoOptions {
  VoIoOptions io;
  VoStartOptions start;
  VoStartupOptions startup;
  FrontendOptions frontend;
  BackendOptions backend;  // backend.ba.optimize_extrinsics is set by RunVo from start.mode
  void Check() const;      // every part's; throws std::invalid_argument naming the flag or field
};

// The dataset cameras the VO uses (VoIoOptions::cameras) for `rig`; throws std::invalid_argument
// naming --cameras.
std::vector<int> VoCameraIndices(const std::string& cameras, const Rig& rig);

// ---- The registry ----

// How a field takes part in the suite's reuse check (VoRunSettingsMatch).
enum class Reuse {
  kNo,
  kYes,                  // the recorded value must equal the wanted one
  kYesMissingIsDefault,  // likewise; a run.json without the key recorded the field's default
  kYesWhenDrawn,         // likewise, only for runs from a fresh draw (start.draw_seed >= 0)
};

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

struct OptionSpec {
  const char* flag;      // "--seed"; without dashes: a required positional argument
  const char* json_key;  // run.json key ("backend.async_ba": in its "backend" object); nullptr: not recorded
  const char* help;
  double min = -kUnbounded;  // accepted values on the command line
  double max = kUnbounded;
  bool show_default = true;  // the help shows the default
  Reuse reuse = Reuse::kNo;
};

// An enum (or a bool) set and recorded by name.
template <typename T>
struct Named {
  T* value;
  std::vector<std::pair<T, const char*>> names;
};
struct DegreesOfRadians {  // a field kept in radians, set and recorded in degrees
  double* radians;
};
struct InvertedFlag {  // a flag that sets the field to false
  bool* value;
};

// The registry, one function per group of VoOptions. Each calls visitor(OptionSpec, field) for its
// fields; a group whose flags lie apart on the command line is visited in parts (`part`, in order).
// Field types: double, int, int64_t, uint64_t, bool (a flag), std::string, FrameRange, Named<E>,
// Named<bool>, DegreesOfRadians, InvertedFlag.
namespace vo_option_groups {

// The dataset (part 0); the frame range and threads (1); progress output (2).
template <typename Visitor>
void VisitIo(VoIoOptions& io, Visitor& visitor, int part) {
  if (part == 0) {
    visitor(OptionSpec{"dataset", nullptr, "Dataset folder (datasets/FORMAT.md)", -kUnbounded, kUnbounded, false},
            io.dataset_dir);
  } else if (part == 1) {
    visitor(OptionSpec{"--frames", nullptr, "Frame range A:B (B exclusive; default: all frames)", -kUnbounded,
                       kUnbounded, false},
            io.frames);
    visitor(OptionSpec{"--threads", "threads", "Worker threads of the front-end (0: all cores)"}, io.threads);
    visitor(OptionSpec{"--cameras", "cameras",
                       "Dataset cameras the VO uses: auto (those whose lens sees more than 180 deg, e.g. the fisheye "
                       "ring of rovo4_stereo without its forward pair; else all), all, or indices 0,1,2,3 "
                       "(increasing, with camera 0)",
                       -kUnbounded, kUnbounded, true, Reuse::kYesMissingIsDefault},
            io.cameras);
    visitor(OptionSpec{"--lateral-colour", "lateral_colour",
                       "auto: undo the lens's lateral colour that dataset.json optics states (its red and blue planes "
                       "magnified relative to green) before colour images become gray, as a lens profile's TCA "
                       "correction does; off: gray as decoded (no effect on datasets without lateral colour)",
                       -kUnbounded, kUnbounded, true, Reuse::kYesMissingIsDefault},
            Named<bool>{&io.undo_lateral_colour, {{true, "auto"}, {false, "off"}}});
    visitor(OptionSpec{"--flat-field", "flat_field",
                       "auto: undo the lens's relative illumination (vignetting) that dataset.json optics states, "
                       "through the sensor's response curve, so that the dark rim where the views overlap gets its "
                       "contrast back; off: the brightness as decoded (no effect on datasets without it)",
                       -kUnbounded, kUnbounded, true, Reuse::kYesMissingIsDefault},
            Named<bool>{&io.flat_field, {{true, "auto"}, {false, "off"}}});
  } else {
    visitor(OptionSpec{"--quiet", nullptr, "No progress output"}, io.quiet);
  }
}

template <typename Visitor>
void VisitStart(VoStartOptions& start, Visitor& visitor) {
  using R = Reuse;
  visitor(OptionSpec{"--extrinsics", "mode",
                     "Extrinsics: gt (GTExt), noisy (NoisyExt: a perturbed set, fixed) or online (OnlineExt: a "
                     "perturbed set, calibrated online in the local BA)",
                     -kUnbounded, kUnbounded, true, R::kYes},
          Named<ExtrinsicsMode>{&start.mode,
                                {{ExtrinsicsMode::kGroundTruth, "gt"},
                                 {ExtrinsicsMode::kNoisy, "noisy"},
                                 {ExtrinsicsMode::kOnline, "online"}}});
  visitor(OptionSpec{"--noise-set", "noise_set", "Index of the perturbed extrinsic set in dataset.json", -kUnbounded,
                     kUnbounded, true, R::kYes},
          start.noise_set);
  visitor(OptionSpec{"--draw-seed", "draw_seed",
                     "noisy/online: start from a fresh perturbation draw with this seed instead of a stored set "
                     "(sigma --draw-sigma on roll, pitch and yaw of every camera; recorded in run.json)",
                     0, kUnbounded, false, R::kYesMissingIsDefault},
          start.draw_seed);
  visitor(OptionSpec{"--draw-sigma", "draw_sigma_deg", "Sigma of a --draw-seed draw in degrees", 0.0, 45.0, true,
                     R::kYesWhenDrawn},
          start.draw_sigma_deg);
}

template <typename Visitor>
void VisitStartup(VoStartupOptions& startup, Visitor& visitor) {
  visitor(OptionSpec{"--online-startup", "online_startup",
                     "OnlineExt: on (default) | off. on: the start-up calibration corrects the starting extrinsics "
                     "before the first frame; off: the local BA alone (an ablation, which does not correct errors "
                     "of degrees)",
                     -kUnbounded, kUnbounded, false},
          Named<bool>{&startup.enabled, {{true, "on"}, {false, "off"}}});
  visitor(OptionSpec{"--online-startup-shots", "online_startup_shots",
                     "OnlineExt: synchronous shots (every --online-startup-spacing frames from the first) pooled by "
                     "the start-up calibration",
                     1, 100},
          startup.shots);
  visitor(OptionSpec{"--online-anchor", "online_anchor_deg",
                     "OnlineExt: rotation sigma (degrees) with which every keyframe BA pulls the extrinsics towards a "
                     "converged start-up calibration's result; 0: none",
                     0.0, 45.0},
          startup.anchor_deg);
  visitor(OptionSpec{"--online-anchor-mm", "online_anchor_mm",
                     "OnlineExt: with --online-anchor, the camera centres' sigma (mm) towards the start-up's result; "
                     "0: the centres are not held",
                     0.0, 1000.0},
          startup.anchor_mm);
  visitor(OptionSpec{"--online-lens-scale", "online_apply_lens_scale",
                     "OnlineExt: apply (default) | report. apply: when the start-up calibration converges with an "
                     "angle scale of the lenses (a lens calibration that misjudges angles near the rim), the VO sees "
                     "through lenses scaled by it; report: the dataset's lenses, the scale only in run.json",
                     -kUnbounded, kUnbounded, false},
          Named<bool>{&startup.apply_lens_scale, {{true, "apply"}, {false, "report"}}});
  visitor(OptionSpec{"--online-startup-spacing", "online_startup_spacing",
                     "OnlineExt: frames between two shots of --online-startup-shots", 1, 100000},
          startup.spacing);
  visitor(OptionSpec{"--online-startup-max-shots", "online_startup_max_shots",
                     "OnlineExt: when the start-up's weakest camera pair keeps fewer than "
                     "--online-startup-min-inliers inliers, or the start-up fails, it runs again on up to this many "
                     "shots (same spacing); a value of at most --online-startup-shots turns this off",
                     1, 100},
          startup.max_shots);
  visitor(OptionSpec{"--online-startup-min-inliers", "online_startup_min_inliers",
                     "OnlineExt: inliers of the weakest camera pair below which the start-up runs again on more shots",
                     0, 1000000},
          startup.min_pair_inliers);
}

template <typename Visitor>
void VisitFrontend(FrontendOptions& frontend, Visitor& visitor) {
  using R = Reuse;
  visitor(OptionSpec{"--max-new-features", "max_new_features",
                     "New detections per view and frame at most, while the view has tracks (0: fill up to the target "
                     "count of 600). 150 makes the front-end about a fifth cheaper and the trajectories slightly less "
                     "accurate (docs/design-notes.md, docs/results.md)",
                     0, 100000, true, R::kYesMissingIsDefault},
          frontend.max_new_features_per_view);
  visitor(OptionSpec{"--warp-below", "warp_below_deg",
                     "Degrees below the rig plane that the hybrid warp reaches; features are tracked and detected "
                     "only inside it (recorded in run.json). 25 makes the full-size front-end about 18 % cheaper "
                     "(the road beside the vehicle, where fresh features die at once) at neutral full-size accuracy, "
                     "but costs accuracy at small image sizes (docs/design-notes.md: warp extents)",
                     1.0, 85.0},
          frontend.projection.vertical_fov_below_deg);
}

// The RANSAC seed (part 0); its view sampling and scoring (1); the inlier threshold and the online
// settling (2); keyframes and the BA's scheduling (3).
template <typename Visitor>
void VisitBackend(BackendOptions& backend, Visitor& visitor, int part) {
  using R = Reuse;
  if (part == 0) {
    visitor(OptionSpec{"--seed", "seed", "RANSAC seed (recorded in run.json)", -kUnbounded, kUnbounded, true, R::kYes},
            backend.ransac.seed);
  } else if (part == 1) {
    visitor(OptionSpec{"--sampling", "sampling", "RANSAC view sampling: pps (paper) or uniform (ablation)"},
            Named<ViewSampling>{&backend.ransac.sampling,
                                {{ViewSampling::kPps, "pps"}, {ViewSampling::kUniform, "uniform"}}});
    visitor(OptionSpec{"--ransac", "ransac",
                       "RANSAC scoring: multiview (paper: all views) or single-view (ablation: one view)"},
            Named<RansacViews>{&backend.ransac.views,
                               {{RansacViews::kMultiView, "multiview"}, {RansacViews::kSingleView, "single-view"}}});
  } else if (part == 2) {
    visitor(OptionSpec{"--tau", "backend.ransac_tau_deg",
                       "RANSAC inlier threshold in degrees: the angle between observed and predicted bearing, the same "
                       "for every rig (recorded in run.json)",
                       0.01, 10.0},
            DegreesOfRadians{&backend.ransac.tau_rad});
    visitor(OptionSpec{"--online-settle", "backend.online_settle_frames",
                       "OnlineExt: frames during which the calibration settles and observations up to 2 deg off are "
                       "kept; afterwards the RANSAC threshold rejects them, as in GTExt (default 50, recorded in "
                       "run.json)",
                       0, 1000000, false},
            backend.online_settle_frames);
  } else {
    visitor(OptionSpec{"--keyframe-distance", "backend.keyframe_distance_m",
                       "Rig travel in metres that makes a keyframe (and a local BA; default 1, recorded in run.json)",
                       0.0, 100.0, false},
            backend.keyframes.min_translation_m);
    visitor(OptionSpec{"--sync-ba", "backend.async_ba",
                       "Run each keyframe BA before the next frame's front-end instead of beside it, and each frame's "
                       "front-end after the previous frame's back-end (same GTExt/NoisyExt result, slower; OnlineExt's "
                       "front-end then sees the calibration one frame earlier)"},
            InvertedFlag{&backend.async_ba});
  }
}

}  // namespace vo_option_groups

// Calls visitor(OptionSpec, field) for each user-set field of `o`, in the command line's order.
template <typename Visitor>
void ForEachVoOption(VoOptions& o, Visitor& visitor) {
  using namespace vo_option_groups;
  VisitIo(o.io, visitor, 0);            // dataset
  VisitStart(o.start, visitor);         // --extrinsics ... --draw-sigma
  VisitBackend(o.backend, visitor, 0);  // --seed
  VisitIo(o.io, visitor, 1);            // --frames, --threads
  VisitBackend(o.backend, visitor, 1);  // --sampling, --ransac
  VisitStartup(o.startup, visitor);     // --online-startup ... --online-startup-spacing
  VisitBackend(o.backend, visitor, 2);  // --tau, --online-settle
  VisitFrontend(o.frontend, visitor);   // --max-new-features, --warp-below
  VisitBackend(o.backend, visitor, 3);  // --keyframe-distance, --sync-ba
  VisitIo(o.io, visitor, 2);            // --quiet
}

// run.json's record of the registry's fields (keys as OptionSpec::json_key).
nlohmann::json VoOptionsJson(const VoOptions& options);

// Whether a run.json (`info`) records the registry's reuse fields as `want` has them; otherwise
// `*mismatch` = "key: recorded vs wanted" (e.g. "seed: 1 vs 0").
bool VoRunSettingsMatch(const nlohmann::json& info, const VoOptions& want, std::string* mismatch);

}  // namespace rovo
