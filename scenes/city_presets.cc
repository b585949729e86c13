// The street and harder-world presets, one table entry per preset (scenes/README.md describes them).

#include <stdexcept>
#include <string>
#include <vector>

#include "scenes/city.h"

namespace rovo {
namespace {

// ---- Table I -------------------------------------------------------------------------------------

ScenePreset StaticUrban() {
  ScenePreset p;
  p.name = "static_urban";
  p.description = "Static Urban: ~2 km city drive, no moving objects, sunny";
  p.path_length_m = 2000;
  p.frames = 3000;
  p.lighting = SceneLighting::kSunny;
  p.traffic = false;
  p.quick_frames = 60;
  return p;
}

ScenePreset DynamicUrban() {
  ScenePreset p;
  p.name = "dynamic_urban";
  p.description = "Dynamic Urban: ~1.3 km fast drive on long blocks, heavy traffic";
  p.path_length_m = 1320;
  p.frames = 1000;
  p.lighting = SceneLighting::kSunny;
  p.traffic = true;
  p.quick_frames = 60;
  return p;
}

ScenePreset CloudyUrban() {
  ScenePreset p;
  p.name = "cloudy_urban";
  p.description = "Cloudy Urban: ~350 m in a small town, overcast";
  p.path_length_m = 350;
  p.frames = 300;
  p.lighting = SceneLighting::kCloudy;
  p.traffic = false;
  p.quick_frames = 60;
  return p;
}

ScenePreset SunsetUrban() {
  ScenePreset p;
  p.name = "sunset_urban";
  p.description = "Sunset Urban: the cloudy_urban streets at sunset (low warm sun)";
  p.path_length_m = 350;
  p.frames = 300;
  p.lighting = SceneLighting::kSunset;
  p.traffic = false;
  p.quick_frames = 60;
  return p;
}

ScenePreset CanyonMultiFov() {
  ScenePreset p;
  p.name = "canyon_multifov";
  p.description = "4view-MultiFOV-like: ~440 m slow drive in a narrow urban canyon";
  p.path_length_m = 440;
  p.frames = 2200;
  p.lighting = SceneLighting::kSunny;
  p.traffic = false;
  p.rig_preset = "omnimvs4";
  p.quick_frames = 80;
  return p;
}

// ---- harder worlds -------------------------------------------------------------------------------

ScenePreset IndoorHall() {
  ScenePreset p;
  p.name = "indoor_hall";
  p.description = "Indoor hall and corridor: plain walls, polished floor, ceiling lights, people near the rig";
  p.path_length_m = 128;
  p.frames = 1000;
  p.lighting = SceneLighting::kIndoor;
  p.traffic = true;
  p.quick_frames = 80;
  p.world = SceneWorld::kIndoor;
  return p;
}

ScenePreset SuburbanRoad() {
  ScenePreset p;
  p.name = "suburban_road";
  p.description = "Suburban road: plain houses behind lawns, wide spacing, open sky, sparse features";
  p.path_length_m = 600;
  p.frames = 600;
  p.lighting = SceneLighting::kSunny;
  p.traffic = false;
  p.quick_frames = 60;
  return p;
}

ScenePreset NightStreet() {
  ScenePreset p;
  p.name = "night_street";
  p.description = "The cloudy_urban streets at night: street lamps, headlights, dark sky (high gain)";
  p.path_length_m = 350;
  p.frames = 300;
  p.lighting = SceneLighting::kNight;
  p.traffic = true;
  p.quick_frames = 60;
  return p;
}

}  // namespace

std::string SceneLightingName(SceneLighting lighting) {
  switch (lighting) {
    case SceneLighting::kSunny:
      return "sunny";
    case SceneLighting::kCloudy:
      return "cloudy";
    case SceneLighting::kSunset:
      return "sunset";
    case SceneLighting::kNight:
      return "night";
    case SceneLighting::kIndoor:
      return "indoor";
  }
  throw std::logic_error("SceneLightingName: unknown lighting");
}

const std::vector<ScenePreset>& ScenePresets() {
  static const std::vector<ScenePreset> presets = {StaticUrban(), DynamicUrban(), CloudyUrban(), SunsetUrban(),
                                                   CanyonMultiFov()};
  return presets;
}

const std::vector<ScenePreset>& HarderScenePresets() {
  static const std::vector<ScenePreset> presets = {IndoorHall(), SuburbanRoad(), NightStreet()};
  return presets;
}

std::vector<ScenePreset> AllScenePresets() {
  std::vector<ScenePreset> all = ScenePresets();
  all.insert(all.end(), HarderScenePresets().begin(), HarderScenePresets().end());
  return all;
}

const ScenePreset& FindScenePreset(const std::string& name) {
  std::string names;
  for (const auto* list : {&ScenePresets(), &HarderScenePresets()}) {
    for (const ScenePreset& p : *list) {
      if (p.name == name) return p;
      names += (names.empty() ? "" : ", ") + p.name;
    }
  }
  throw std::invalid_argument("unknown scene preset '" + name + "' (valid: " + names + ")");
}

}  // namespace rovo
