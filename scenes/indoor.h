#pragma once
// The indoor_hall world (internal to scenes/, used by GenerateScene and the tests): a hall and a
// long corridor with plain painted walls, a polished stone floor, ceiling lights (glowing panels
// with a point light under each) and people standing or walking slowly near the rig's path.
//
// Plan (metres, world frame, z up): hall x in [0, 30], y in [-10, 10], 6 m high; corridor x in
// [30, 30 + corridor_length], y in [-2.2, 2.2], 3 m high, entered through an opening in the hall's
// east wall. The rig (on a pushed cart, kIndoorRigHeight above the floor) crosses the hall on a
// line-arc path and walks down the corridor's centre line; the quick form is the stretch around the
// corridor entrance (half in the hall, half in the corridor).

#include <Eigen/Core>
#include <vector>

#include "scenes/city.h"
#include "scenes/city_layout.h"

namespace rovo {

inline constexpr double kIndoorRigHeight = 1.4;
inline constexpr double kHallHeight = 6.0;
inline constexpr double kCorridorHeight = 3.0;
inline constexpr double kCorridorHalfWidth = 2.2;
inline constexpr double kHallEndX = 30.0;      // the hall's east wall, where the corridor starts
inline constexpr double kPersonRadius = 0.33;  // a person (arms included) fits in this cylinder around its axis

struct IndoorPerson {
  int variant = 0;                  // mesh variant (clothes, height)
  double yaw = 0.0;                 // facing, radians
  std::vector<Eigen::Vector2d> xy;  // position per frame (one entry for a person standing still)
  bool Moving() const { return xy.size() > 1; }
};

struct IndoorLayout {
  ScenePreset preset;
  bool quick = false;
  Box2 hall, corridor;
  double corridor_length = 0.0;
  std::vector<Eigen::Vector3d> hall_lights, corridor_lights;  // point-light positions
  std::vector<Eigen::Vector2d> pillars;                       // 0.6 m square columns in the hall
  std::vector<IndoorPerson> people;
  LanePath rig_path;
  DriveProfile drive;
  double corridor_entry_s = 0.0;                // rig path arc length at the corridor entrance (x = kHallEndX)
  Trajectory trajectory;                        // world_from_rig per frame
  std::vector<Eigen::Vector3d> cameras_in_rig;  // camera centres of the preset's rig

  // True if p is on the floor (hall or corridor) with `margin` metres to every wall.
  bool OnFloor(const Eigen::Vector2d& p, double margin) const;
};

IndoorLayout MakeIndoorLayout(const ScenePreset& preset, uint64_t seed, bool quick);
// The indoor_hall scene (GenerateScene dispatches here for presets whose world is "indoor").
Scene GenerateIndoorScene(const ScenePreset& preset, uint64_t seed, bool quick);

}  // namespace rovo
