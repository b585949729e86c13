#pragma once
// The on-disk dataset (datasets/FORMAT.md): dataset.json, camN/NNNNNN.png, groundtruth.tum,
// optional depth/ and masks/.

#include "datasets/rig.h"
#include "datasets/trajectory.h"

#include <cstdint>
#include <string>
#include <vector>

namespace rovo {

inline constexpr int kDatasetSchemaVersion = 1;

struct DatasetInfo {
  int schema_version = kDatasetSchemaVersion;
  std::string generator = "rovo";
  std::string generator_version;
  uint64_t seed = 0;
  std::string preset;        // scene preset name or "" for a custom scene
  std::string scene_hash;    // hash of the scene the images were rendered from
  double frame_rate = 10.0;  // Hz
  int frame_count = 0;
  Rig rig;                   // ground-truth rig (intrinsics + cam_from_rig)
  std::vector<PerturbedExtrinsics> perturbed;  // NoisyExt starting points
  bool has_depth = false;
  bool has_masks = false;
  // Real captures: no ground-truth poses (groundtruth.tum absent; the rig is the capture's own
  // calibration), and optional static masks (static_masks/<camera>.png, 0 = invalid: rig body,
  // vehicle, operator), honoured by the start-up calibration's detector.
  bool has_ground_truth = true;
  bool has_static_masks = false;
};

// Paths inside a dataset folder.
std::string DatasetJsonPath(const std::string& dir);
std::string GroundTruthPath(const std::string& dir);
std::string ImagePath(const std::string& dir, const std::string& camera_name, int frame);  // camN/NNNNNN.png
std::string DepthPath(const std::string& dir, const std::string& camera_name, int frame);  // depth/camN/NNNNNN.exr
std::string MaskPath(const std::string& dir, const std::string& camera_name, int frame);   // masks/camN/NNNNNN.png
std::string StaticMaskPath(const std::string& dir, const std::string& camera_name);      // static_masks/camN.png

// Reads and checks dataset.json (throws std::runtime_error naming file and field).
DatasetInfo ReadDatasetInfo(const std::string& dir);
// Atomic write of dataset.json.
void WriteDatasetInfo(const std::string& dir, const DatasetInfo& info);

struct ValidationIssue {
  std::string file;   // path of the offending file
  std::string field;  // JSON pointer, line number or image property
  std::string message;
};
// Checks every field and file; returns all problems (empty when valid).
std::vector<ValidationIssue> ValidateDataset(const std::string& dir);

}  // namespace rovo
