#pragma once
// The on-disk dataset (datasets/FORMAT.md): dataset.json, camN/NNNNNN.png, groundtruth.tum,
// optional depth/, masks/ and imu/.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "datasets/dataset_validate.h"
#include "datasets/exposure_csv.h"
#include "datasets/imu.h"
#include "datasets/optics_record.h"
#include "datasets/rig.h"
#include "datasets/rig_json.h"
#include "datasets/trajectory.h"

namespace rovo {

inline constexpr int kDatasetSchemaVersion = 1;

// dataset.json "sensor": the physical sensor model a render used (render/sensor.h; the rules are
// in datasets/FORMAT.md, section "Sensor"). Absent for the default rendering.
struct SensorRecord {
  std::string profile;  // "ideal", "realistic"
  bool auto_exposure = true;
  double exposure_ms = 0.1;  // fixed exposure (auto_exposure false)
  double gain = 1.0;         // fixed analogue gain (auto_exposure false)
  double min_exposure_ms = 0.01;
  double max_exposure_ms = 20.0;
  double max_gain = 16.0;
  double ae_target = 0.18;
  double ae_rate = 0.25;
  double ae_max_step_stops = 0.5;
  int meter_width = 200;
  double sensitivity_e_per_ms = 100000.0;
  double sensitivity_spread = 0.0;
  std::vector<double> camera_sensitivity;  // q_c, one per rig camera
  double full_well_e = 10000.0;
  bool shot_noise = true;
  double read_noise_e = 0.0;
  double dark_current_e_per_s = 0.0;
  int adc_bits = 12;
  std::string response = "srgb";  // "srgb", "bt709" or "linear"
  bool grayscale = false;         // 1-channel images
  bool operator==(const SensorRecord& other) const;
  bool operator!=(const SensorRecord& other) const { return !(*this == other); }
};

// dataset.json "timing": trigger offsets, motion blur and rolling shutter of a render
// (render/timing.h; the time rules are in datasets/FORMAT.md, section "Timing"). Absent when every
// camera saw frame i at the time of line i of groundtruth.tum.
struct TimingRecord {
  std::string exposure = "none";          // motion blur interval: "none", "fixed" (shutter_ms), "sensor" (exposure.csv)
  double shutter_ms = 0.0;                // the fixed interval ("fixed"), else 0
  double rolling_shutter_ms = 0.0;        // readout of the whole image, top row first; 0 = global shutter
  double trigger_offset_std_ms = 0.0;     // standard deviation of the seeded draw (0: explicit or none)
  std::vector<double> trigger_offset_ms;  // o_c, one per rig camera
  // Samples per pixel (optional `sampling`; 0 = not recorded): at most `spp`; with adaptive
  // sampling a pixel takes min_spp and doubles while the means of its samples' halves differ by more than
  // threshold_codes (render/tracer.h, AdaptiveSampling); min_spp = spp for a fixed count.
  int spp = 0;
  int min_spp = 0;
  double threshold_codes = 0.0;
  bool operator==(const TimingRecord& other) const;
  bool operator!=(const TimingRecord& other) const { return !(*this == other); }
  // Equal but for the sampling (spp, min_spp, threshold_codes): the same exposure times.
  bool SameExposure(const TimingRecord& other) const;
};

struct DatasetInfo {
  int schema_version = kDatasetSchemaVersion;
  std::string generator = "rovo";
  std::string generator_version;
  uint64_t seed = 0;
  std::string preset;        // scene preset name or "" for a custom scene
  std::string scene_hash;    // hash of the scene the images were rendered from
  double frame_rate = 10.0;  // Hz
  int frame_count = 0;
  Rig rig;                                     // ground-truth rig (intrinsics + cam_from_rig)
  std::vector<PerturbedExtrinsics> perturbed;  // NoisyExt starting points
  bool has_depth = false;
  bool has_masks = false;
  // Real captures: no ground-truth poses (groundtruth.tum absent; the rig is the capture's own
  // calibration), and optional static masks (static_masks/<camera>.png, 0 = invalid: rig body,
  // vehicle, operator), honoured by the start-up calibration's detector.
  bool has_ground_truth = true;
  bool has_static_masks = false;
  // Rendered with the sensor model: its parameters, and exposure.csv holds every frame's exposure.
  std::optional<SensorRecord> sensor;
  // Rendered with exposure timing effects (trigger offsets, motion blur, rolling shutter).
  std::optional<TimingRecord> timing;
  // Rendered with the lens model of image quality (blur, vignetting, colour fringes, glare).
  std::optional<OpticsRecord> optics;
  // Rendered with an IMU (datasets/imu.h): how its streams under imu/ were made.
  std::optional<ImuRecord> imu;
};

// Paths inside a dataset folder.
std::string DatasetJsonPath(const std::string& dir);
std::string GroundTruthPath(const std::string& dir);
std::string ImagePath(const std::string& dir, const std::string& camera_name, int frame);  // camN/NNNNNN.png
std::string DepthPath(const std::string& dir, const std::string& camera_name, int frame);  // depth/camN/NNNNNN.exr
std::string MaskPath(const std::string& dir, const std::string& camera_name, int frame);   // masks/camN/NNNNNN.png
std::string StaticMaskPath(const std::string& dir, const std::string& camera_name);        // static_masks/camN.png
std::string ExposurePath(const std::string& dir);                                          // exposure.csv

// Reads and checks dataset.json (throws std::runtime_error naming file and field).
DatasetInfo ReadDatasetInfo(const std::string& dir);
// Atomic write of dataset.json.
void WriteDatasetInfo(const std::string& dir, const DatasetInfo& info);

}  // namespace rovo
