#pragma once
// Procedural scenes: the paper's Table I presets (urban streets) and harder worlds (an indoor hall
// and corridor, a low-texture suburban road, a night street).
// The presets are defined in city_presets.cc; GenerateScene's steps in city.cc and city_*.cc.

#include <cstdint>
#include <string>
#include <vector>

#include "scenes/scene.h"

namespace rovo {

// The procedural lighting of a preset; its name goes into the scene (Lighting::preset).
enum class SceneLighting { kSunny, kCloudy, kSunset, kNight, kIndoor };
std::string SceneLightingName(SceneLighting lighting);  // "sunny" | "cloudy" | "sunset" | "night" | "indoor"
// What a preset is built from: the street grid (city_layout.h) or a hall and corridor (indoor.h).
enum class SceneWorld { kCity, kIndoor };

struct ScenePreset {
  std::string name;  // e.g. "static_urban"
  std::string description;
  double path_length_m = 0;  // full form
  int frames = 0;            // full form, at 10 Hz
  SceneLighting lighting = SceneLighting::kSunny;
  bool traffic = false;  // moving objects (vehicles; people in indoor_hall)
  std::string rig_preset = "rovo4";
  int quick_frames = 0;      // --quick form
  double quick_scale = 0.5;  // image scale for the --quick form
  double frame_rate = 10.0;  // Hz
  SceneWorld world = SceneWorld::kCity;
};

// The Table I presets, in Table I order (what `rovo suite` runs by default).
const std::vector<ScenePreset>& ScenePresets();
// Harder worlds beyond Table I: indoor_hall, suburban_road, night_street.
const std::vector<ScenePreset>& HarderScenePresets();
// Both lists, Table I first.
std::vector<ScenePreset> AllScenePresets();
// Any preset of AllScenePresets(); throws std::invalid_argument listing the valid names.
const ScenePreset& FindScenePreset(const std::string& name);

// A procedural scene's header: metadata (generator, version, preset, seed, source), frame rate, rig
// preset and rig trajectory.
Scene ProceduralSceneHeader(const ScenePreset& preset, uint64_t seed, bool quick, Trajectory rig_trajectory);

// Deterministic: the same (preset, seed, quick) gives the same scene, byte for byte.
Scene GenerateScene(const std::string& preset, uint64_t seed, bool quick);

}  // namespace rovo
