#pragma once
// Procedural urban scenes and the paper's Table I presets.

#include "scenes/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace rovo {

struct ScenePreset {
  std::string name;            // e.g. "static_urban"
  std::string description;
  double path_length_m = 0;    // full form
  int frames = 0;              // full form, at 10 Hz
  std::string lighting;        // "sunny" | "cloudy" | "sunset"
  bool traffic = false;        // moving vehicles
  std::string rig_preset = "rovo4";
  int quick_frames = 0;        // --quick form
  double quick_scale = 0.5;    // image scale for the --quick form
  double frame_rate = 10.0;    // Hz
};

// All presets, in Table I order.
const std::vector<ScenePreset>& ScenePresets();
// Throws std::invalid_argument listing the valid names.
const ScenePreset& FindScenePreset(const std::string& name);

// Deterministic: the same (preset, seed, quick) gives the same scene, byte for byte.
Scene GenerateScene(const std::string& preset, uint64_t seed, bool quick);

}  // namespace rovo
