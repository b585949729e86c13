#pragma once
// The 2-D plan of a procedural city and the car-like paths through it (internal to scenes/, used by
// GenerateScene and the tests).
//
// Plan: a rectilinear street grid. Street i runs along y at x = xs[i] ("vertical" streets) and
// street j along x at y = ys[j]. Roads are road_width_m wide curb to curb, sidewalks
// sidewalk_width_m wide and kCurbHeight high. Blocks fill the space between streets (and one ring of
// blocks outside the outermost streets); buildings stand on lots along each block's edges.
//
// Paths: a route is a walk on the grid's intersections (no U-turns). Its centre-line polyline is
// offset lane_offset_m to the right of the direction of travel (right-hand traffic); each corner is
// filleted with a circular arc (right turns as wide as the curb corner allows, at most 6 m; left
// turns concentric, 2 lane offsets wider), giving a C1 line-arc-line curve. Control points every
// kControlSpacing metres along it define a uniform cubic B-spline, which is C2: position, tangent
// and curvature are continuous (the curvature step at each arc end is spread over ~3 control
// spacings), and straights stay exactly straight (collinear control points).

#include <Eigen/Core>
#include <vector>

#include "scenes/city.h"
#include "scenes/rng.h"

namespace rovo {

inline constexpr double kCurbHeight = 0.15;
inline constexpr double kControlSpacing = 3.0;     // metres between B-spline control points
inline constexpr double kTurnCurbClearance = 0.9;  // right-turn arc midpoint to the curb lines, metres
inline constexpr double kRigHeight = 2.0;          // rig origin above the road (camera rig on a car roof)

// Per-preset look of the city.
struct CityStyle {
  double block_min_m = 70, block_max_m = 110;
  double road_width_m = 10.0;   // curb to curb
  double parking_lane_m = 1.5;  // 0: none
  double sidewalk_width_m = 3.0;
  double height_min_m = 9, height_max_m = 30;
  double lot_width_min_m = 8, lot_width_max_m = 24;
  double lot_depth_min_m = 10, lot_depth_max_m = 20;
  double straight_preference = 0.5;  // probability weight of going straight at an intersection
  bool trees = true;
  bool parked_cars = true;
  int facade_textures = 24, storefront_textures = 8;  // texture pool sizes (full form)
  int grid_streets_min = 6;                           // streets per axis at least
  bool high_sun_along_streets = false;                // sunny: high sun near a street axis (canyons)
  double tree_probability = 0.8;                      // a tree between two street lights
  double light_spacing_m = 28.0;                      // street lights along each curb
  // Suburban: detached houses (no shops) of house_width x house_depth set back from the sidewalk
  // behind lawns, one per lot, with plain walls (MakeHouseWallTexture) and few windows.
  bool houses = false;
  double setback_min_m = 6, setback_max_m = 10;
  double house_width_min_m = 9, house_width_max_m = 14;
  double house_depth_min_m = 8, house_depth_max_m = 11;
};

CityStyle StyleForPreset(const std::string& preset);

struct Box2 {
  Eigen::Vector2d min, max;
  bool Contains(const Eigen::Vector2d& p, double margin = 0.0) const {
    return p.x() > min.x() - margin && p.x() < max.x() + margin && p.y() > min.y() - margin && p.y() < max.y() + margin;
  }
};

struct BuildingPlan {
  Box2 footprint;      // base box
  double height = 10;  // top of the base box above the ground
  bool has_setback = false;
  Box2 upper_footprint;            // setback storey(s) on top, inside `footprint`
  double upper_height = 0;         // top of the setback part
  Eigen::Vector2d facing{0, -1};   // outward normal of the street-facing side
  int facade = 0, storefront = 0;  // texture pool indices
  Eigen::Vector3f tint{1, 1, 1};
  double u_offset = 0;  // metres, shifts the facade pattern
  bool house = false;   // a detached house (CityStyle::houses): no shop floor, hipped roof
};

struct StreetGrid {
  std::vector<double> xs, ys;  // street centre lines
  double road_width_m = 10, sidewalk_width_m = 3, parking_lane_m = 1.5;
  double MinX() const { return xs.front(); }
  double MaxX() const { return xs.back(); }
  double MinY() const { return ys.front(); }
  double MaxY() const { return ys.back(); }
  Eigen::Vector2d Node(int i, int j) const { return {xs[i], ys[j]}; }
  // True if p is on the road surface (between curbs) with `margin` metres to spare.
  bool OnRoad(const Eigen::Vector2d& p, double margin = 0.0) const;
};

// C2 planar path (uniform cubic B-spline), parameterized by arc length s in [0, Length()].
class LanePath {
 public:
  LanePath() = default;
  explicit LanePath(std::vector<Eigen::Vector2d> control_points);
  double Length() const { return s_.empty() ? 0.0 : s_.back(); }
  Eigen::Vector2d Position(double s) const;
  double Heading(double s) const;    // yaw of the tangent, radians
  double Curvature(double s) const;  // signed, 1/m, positive turning left
  const std::vector<Eigen::Vector2d>& control_points() const { return control_; }

 private:
  double ParamAt(double s) const;
  void Eval(double param, Eigen::Vector2d* p, Eigen::Vector2d* d1, Eigen::Vector2d* d2) const;
  std::vector<Eigen::Vector2d> control_;
  std::vector<double> s_, param_;  // dense arc-length table
};

// Route on the grid: intersections (i, j) visited in order.
using GridRoute = std::vector<Eigen::Vector2i>;
GridRoute RandomRoute(const StreetGrid& grid, SceneRng& rng, double min_length_m, double straight_preference,
                      Eigen::Vector2i start, int start_dir);
// Lane path along a route, lane_offset_m right of the direction of travel (negative: left).
LanePath PathAlongRoute(const StreetGrid& grid, const GridRoute& route, double lane_offset_m);

// Arc length at each frame k (time k / frame_rate) for a drive over [s_begin, s_begin + length]
// lasting (frames - 1) / frame_rate seconds: top speed found by bisection so the time matches; the
// speed is capped by lateral acceleration in turns and limited by longitudinal acceleration, then
// smoothed. Returns false if the timing is not feasible below 30 m/s. Optional outputs: speed and
// longitudinal acceleration per frame.
struct DriveProfile {
  std::vector<double> s, speed, accel_longitudinal;
};
bool PlanDrive(const LanePath& path, double s_begin, double length, int frames, double frame_rate,
               DriveProfile* profile);

struct CityLayout {
  ScenePreset preset;
  CityStyle style;
  bool quick = false;
  StreetGrid grid;
  std::vector<Box2> blocks;  // curb-to-curb block areas (sidewalk included)
  std::vector<BuildingPlan> buildings;
  GridRoute route;
  LanePath rig_path;
  DriveProfile drive;       // per frame
  double path_begin_s = 0;  // rig path arc length at frame 0
  double path_length_m = 0;
  Trajectory trajectory;  // world_from_rig per frame

  // True if p (metres, world xy) is inside a building footprint grown by `margin`.
  bool InsideBuilding(const Eigen::Vector2d& p, double margin = 0.0) const;
};

// Plan of the city and the rig's drive. Layout depends on (style family, seed); presets that share
// a family (cloudy_urban, sunset_urban, night_street) share streets and buildings for the same seed.
CityLayout MakeCityLayout(const ScenePreset& preset, uint64_t seed, bool quick);

// Seed of everything that shapes the world (plan, textures, props) for a preset and user seed.
// cloudy_urban, sunset_urban and night_street share one layout family, so they share it.
uint64_t LayoutSeed(const std::string& preset, uint64_t seed);

// Quick-form path length: the full length scaled by the frame ratio (same speeds).
double QuickPathLength(const ScenePreset& preset);

}  // namespace rovo
