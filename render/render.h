#pragma once
// Renders a dataset (datasets/FORMAT.md) from a scene and a rig. Entry point of `rovo render`.

#include <cstdint>
#include <string>
#include <vector>

#include "datasets/imu_model.h"
#include "datasets/rig.h"
#include "render/optics.h"
#include "render/sensor.h"
#include "render/timing.h"
#include "scenes/scene.h"

namespace rovo {

struct RenderOptions {
  std::string preset;     // scenes preset to generate and render, or ""
  bool quick = false;     // the preset's quick form (fewer frames, smaller images)
  std::string scene_dir;  // or a scene folder (scenes/FORMAT.md)
  std::string rig;        // rig preset name or rig .json path; "" = the scene's rig (ChooseRig)
  std::string out_dir;    // dataset folder
  int frame_begin = 0;    // [frame_begin, frame_end) of the trajectory; -1 = to the end
  int frame_end = -1;
  int shard_index = 0;  // render frames with (frame / chunk) % shard_count == shard_index
  int shard_count = 1;
  int spp = 0;  // samples per pixel; 0 = the measured default
  // Adaptive sampling (render/tracer.h, AdaptiveSampling): auto = on when motion blur takes the default
  // spp (kDefaultBlurSpp), pixels starting at kDefaultSpp samples; on = whenever spp allows; off = fixed.
  std::string adaptive = "auto";
  double adaptive_threshold_codes = 0.0;  // AdaptiveSampling::threshold in 8-bit codes; 0 = kAdaptiveThresholdCodes
  int threads = 0;                        // 0 = all cores
  uint64_t seed = 0;                      // scene seed (preset) and seed of the sensor model's draws
  bool depth = false;                     // write depth/ (EXR ray length)
  bool masks = false;                     // write masks/ (16-bit object ids)
  double scale = 0.0;                     // image scale; 0 = 1.0, or the preset's quick scale with --quick
  bool quiet = false;                     // no progress output
  float vignetting = 0.0f;                // optional vignetting: gain 1 - v * (theta / theta_max)^2 (0 = off)
  // The physical sensor model (render/sensor.h); off by default (the scene's exposure and sRGB).
  SensorSettings sensor;
  // The lens model of image quality (render/optics.h); off by default (an ideal lens). Needs the sensor model.
  OpticsSettings optics;
  // Exposure timing (render/timing.h): trigger offsets, motion blur, rolling shutter; off by default.
  TimingSettings timing;
  // An IMU on the rig (datasets/imu_model.h), sampled from the continuous-time ground truth; off by default.
  bool imu = false;
  ImuSettings imu_settings;
};

struct RenderSummary {
  int frames_total = 0;
  int frames_rendered = 0;
  int frames_skipped = 0;  // already complete on disk (resume)
  double seconds = 0.0;
  // Process CPU time (all threads) of rendering and writing the frames, without the scene's build and
  // the auto-exposure meter: the figure to compare settings by, per frame.
  double frames_cpu_seconds = 0.0;
  std::string rig;  // the rig used and where it came from (DescribeRigChoice)
};

// Renders the frames of `options` (see RenderOptions) into options.out_dir. Throws
// std::invalid_argument / std::runtime_error naming the file or option for bad input, before any
// output is written. Resumable: frames whose files all exist are skipped (files appear only by
// atomic rename). groundtruth.tum, dataset.json and, with the sensor model, exposure.csv (with the
// IMU, imu/*.csv) cover the whole frame range and are identical from every shard. Images are identical for any thread
// count. Unless quiet, prints the rig line (DescribeRigChoice) to stderr before rendering. With the sensor model, a
// small meter render of every frame of the range comes first (the auto-exposure schedule).
RenderSummary RenderDataset(const RenderOptions& options);

// Samples per pixel when RenderOptions::spp is 0: the cheapest setting whose mean error against a
// 32-spp reference is below one 8-bit code (fixed 2-sample diagonal pattern, trilinear textures,
// LOD bias -0.5; measured with `rovo bench render --quality`, table in render/README.md).
inline constexpr int kDefaultSpp = 2;
// Samples per pixel when RenderOptions::spp is 0 and motion blur is on: up to eight time strata per
// pixel (the blur of a fast pan is several pixels wide; measured in render/README.md).
inline constexpr int kDefaultBlurSpp = 8;
// Adaptive sampling's threshold (AdaptiveSampling::threshold x 255): the difference of the means of the two
// halves of a pixel's samples, in 8-bit codes of the output, above which it takes more (measured: render/README.md,
// "Adaptive sampling").
inline constexpr double kAdaptiveThresholdCodes = 8.0;
// The adaptive sampling of a render of `spp` samples per pixel (`defaulted`: spp came from DefaultSpp):
// per RenderOptions::adaptive, min_spp kDefaultSpp; output_scale 0 (set per camera with the sensor
// model). Throws std::invalid_argument naming --adaptive for an unknown mode, and for `on` without timing
// (dataset.json records the sampling with the timing) or with an spp it does not apply to (AdaptiveApplies).
AdaptiveSampling RenderAdaptiveSampling(const RenderOptions& options, int spp, bool defaulted);
// --motion-blur (the sensor's exposure) gets kDefaultBlurSpp only when some exposure of the schedule
// is at least this long: a point 3 m to the side of a rig at 11.5 m/s moves 0.8 px of a full-size
// view in 0.5 ms, and daylight exposures (0.07-0.3 ms) blur less.
inline constexpr double kBlurSppMinExposureMs = 0.5;
// The samples per pixel of a render with RenderOptions::spp 0: kDefaultBlurSpp with a fixed
// shutter, or with the sensor's exposure when some entry of `exposure` (frame x camera) is at least
// kBlurSppMinExposureMs; else kDefaultSpp. The schedule covers the whole range, so every shard agrees.
int DefaultSpp(const TimingSettings& timing, const std::vector<std::vector<CameraExposure>>& exposure);
// Shards take frames in chunks of this many consecutive frames: frame f belongs to shard
// (f / kShardChunkFrames) % shard_count.
inline constexpr int kShardChunkFrames = 8;
// Perturbed extrinsic sets written to dataset.json (sigma 5 deg, seeds derived from --seed).
inline constexpr int kNumPerturbedSets = 5;

// The scene of a preset (generated) or a scene folder (loaded); exactly one must be non-empty.
Scene SceneForOptions(const std::string& preset, bool quick, uint64_t seed, const std::string& scene_dir);
// The rig of a render and where it came from.
struct RigChoice {
  Rig rig;
  std::string source;  // e.g. "scene/rig.json (the scene's rig.json)", "preset rovo4 (--rig)"
};
// The first that applies: `rig` (a preset name, or a rig.json/dataset.json path); <scene_dir>/rig.json
// (written by scenes/blender/export_scene.py); the scene's rig_preset; "rovo4". `scale` 0 means 1.
// Throws naming the file or option.
RigChoice ChooseRig(const std::string& rig, const Scene& scene, const std::string& scene_dir, double scale);
// ChooseRig's rig.
Rig RigForOptions(const std::string& rig, const Scene& scene, double scale, const std::string& scene_dir = "");
// One line: the source, the camera count, model and image size, e.g.
// "rig: preset rovo4 (the scene's rig_preset): 4 cameras, equidistant 1024x1024".
std::string DescribeRigChoice(const RigChoice& choice);
// True when every file of dataset frame `frame` exists under its final name.
bool FrameComplete(const std::string& out_dir, const Rig& rig, int frame, bool depth, bool masks);

// `rovo scene preview`: a contact sheet with one row per frame and one column per camera.
struct PreviewOptions {
  std::string scene_dir;
  std::string preset;  // alternatively a preset (generated, quick form)
  uint64_t seed = 0;
  std::vector<int> frames;  // trajectory frames; empty = first, middle and last
  std::string rig;
  double scale = 0.25;  // of the rig's image size
  int spp = 1;
  int threads = 0;
  std::string out_png;  // default <scene_dir>/preview.png
  int width = 0;        // > 0: the sheet is area-downscaled to at most this many pixels wide
};
void RenderScenePreview(const PreviewOptions& options);

}  // namespace rovo
