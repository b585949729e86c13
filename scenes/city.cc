// Procedural urban scenes: presets, geometry, materials, lighting and traffic (plan in city_layout).

#include "scenes/city.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "rovo/version.h"
#include "scenes/city_layout.h"
#include "scenes/indoor.h"
#include "scenes/mesh_builder.h"
#include "scenes/rng.h"
#include "scenes/texture_gen.h"

namespace rovo {

const std::vector<ScenePreset>& ScenePresets() {
  static const std::vector<ScenePreset> presets = [] {
    std::vector<ScenePreset> p(5);
    p[0] = {"static_urban",
            "Static Urban: ~2 km city drive, no moving objects, sunny",
            2000,
            3000,
            "sunny",
            false,
            "rovo4",
            60,
            0.5};
    p[1] = {"dynamic_urban",
            "Dynamic Urban: ~1.3 km fast drive on long blocks, heavy traffic",
            1320,
            1000,
            "sunny",
            true,
            "rovo4",
            60,
            0.5};
    p[2] = {
        "cloudy_urban", "Cloudy Urban: ~350 m in a small town, overcast", 350, 300, "cloudy", false, "rovo4", 60, 0.5};
    p[3] = {"sunset_urban",
            "Sunset Urban: the cloudy_urban streets at sunset (low warm sun)",
            350,
            300,
            "sunset",
            false,
            "rovo4",
            60,
            0.5};
    p[4] = {"canyon_multifov",
            "4view-MultiFOV-like: ~440 m slow drive in a narrow urban canyon",
            440,
            2200,
            "sunny",
            false,
            "omnimvs4",
            80,
            0.5};
    return p;
  }();
  return presets;
}

const std::vector<ScenePreset>& HarderScenePresets() {
  static const std::vector<ScenePreset> presets = [] {
    std::vector<ScenePreset> p(3);
    p[0] = {"indoor_hall", "Indoor hall and corridor: plain walls, polished floor, ceiling lights, people near the rig",
            128,           1000,
            "indoor",      true,
            "rovo4",       80,
            0.5,           10.0,
            "indoor"};
    p[1] = {"suburban_road",
            "Suburban road: plain houses behind lawns, wide spacing, open sky, sparse features",
            600,
            600,
            "sunny",
            false,
            "rovo4",
            60,
            0.5};
    p[2] = {"night_street",
            "The cloudy_urban streets at night: street lamps, headlights, dark sky (high gain)",
            350,
            300,
            "night",
            true,
            "rovo4",
            60,
            0.5};
    return p;
  }();
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

namespace {

// `high_sun_along_streets` (sunny only): a high sun 15-25 degrees off a street axis, so that light
// reaches the floor of a narrow canyon in strips instead of only the upper floors.
Lighting MakeLighting(const std::string& preset, uint64_t seed, bool high_sun_along_streets) {
  SceneRng rng(SubSeed(seed, "lighting"));
  Lighting l;
  l.preset = preset;
  double elevation_deg = 60, azimuth_deg = rng.Uniform(0, 360);
  if (preset == "sunny") {
    elevation_deg = rng.Uniform(50, 65);
    if (high_sun_along_streets) {
      elevation_deg = rng.Uniform(68, 76);
      azimuth_deg = rng.UniformInt(0, 3) * 90.0 + rng.Uniform(15, 25);
    }
    l.sun_radiance = {3.0f, 2.9f, 2.7f};
    l.sun_angular_diameter_deg = 0.53;
    l.sky_zenith = {0.25f, 0.45f, 0.9f};
    l.sky_horizon = {0.7f, 0.8f, 0.95f};
    l.ambient = 0.35f;
    l.exposure = 1.0f;
  } else if (preset == "cloudy") {
    elevation_deg = rng.Uniform(35, 55);
    l.sun_radiance = {0.3f, 0.3f, 0.32f};
    l.sun_angular_diameter_deg = 30.0;  // a bright patch in the overcast, no crisp shadows
    l.sky_zenith = {0.78f, 0.8f, 0.84f};
    l.sky_horizon = {0.86f, 0.87f, 0.9f};
    l.ambient = 0.95f;
    l.exposure = 1.25f;
  } else if (preset == "sunset") {
    elevation_deg = rng.Uniform(6, 10);
    // 25-35 degrees off the street axes: long shadows across the streets, sun not straight down them.
    azimuth_deg = rng.UniformInt(0, 3) * 90.0 + rng.Uniform(25, 35);
    l.sun_radiance = {2.6f, 1.45f, 0.65f};
    l.sun_angular_diameter_deg = 0.53;
    l.sky_zenith = {0.28f, 0.33f, 0.6f};
    l.sky_horizon = {0.95f, 0.62f, 0.38f};
    l.ground_albedo = {0.3f, 0.25f, 0.22f};
    l.ambient = 0.3f;
    l.exposure = 1.3f;
  } else if (preset == "night") {
    // Moonless, light-polluted night: no sun, a dark blue zenith and an orange glow at the horizon;
    // the street lamps and headlights (scene lights) do the rest. Radiances are on the day presets'
    // scale (sun irradiance 3), so the exposure is 1000 times a day preset's: a real camera
    // needs a long exposure and high gain.
    elevation_deg = -20.0;
    l.sun_radiance = {0.0f, 0.0f, 0.0f};
    l.sky_zenith = {0.6e-5f, 0.8e-5f, 1.8e-5f};
    l.sky_horizon = {2.6e-5f, 2.0e-5f, 1.4e-5f};
    l.ground_albedo = {0.2f, 0.2f, 0.2f};
    l.ambient = 1.0f;
    l.exposure = 1000.0f;
  } else {
    throw std::invalid_argument("unknown lighting preset '" + preset + "' (valid: sunny, cloudy, sunset, night)");
  }
  const double el = elevation_deg * M_PI / 180, az = azimuth_deg * M_PI / 180;
  l.direction_to_sun = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  return l;
}

// ---- vehicles ------------------------------------------------------------------------------------

struct CarShape {
  const char* name;
  float length, width, body_top, cabin_top, cabin_length, cabin_shift;
};
const CarShape kCarShapes[] = {{"sedan", 4.5f, 1.8f, 1.0f, 1.45f, 2.5f, -0.2f},
                               {"suv", 4.7f, 1.9f, 1.15f, 1.75f, 2.9f, -0.3f},
                               {"van", 5.0f, 2.0f, 1.25f, 2.1f, 3.9f, -0.4f},
                               {"compact", 3.8f, 1.7f, 0.95f, 1.45f, 2.1f, -0.2f}};
const Vec3f kCarColors[] = {{0.8f, 0.05f, 0.04f}, {0.05f, 0.1f, 0.45f}, {0.85f, 0.85f, 0.85f}, {0.04f, 0.04f, 0.045f},
                            {0.5f, 0.52f, 0.55f}, {0.9f, 0.6f, 0.05f},  {0.1f, 0.35f, 0.15f},  {0.6f, 0.3f, 0.15f}};
constexpr int kNumCarShapes = 4, kNumCarColors = 8;

struct CarTextures {
  int side = -1, end = -1, glass = -1;
};

class CarFactory {
 public:
  CarFactory(Scene& scene, const CarTextures& tex) : scene_(scene), tex_(tex) {
    glass_ = AddMaterial(scene, "car_glass", {0.9f, 0.9f, 0.9f}, tex.glass);
    tyre_ = AddMaterial(scene, "car_tyre", {0.04f, 0.04f, 0.04f}, -1);
  }
  // Mesh of a car: origin on the ground under the centre, x forward, z up. `lit`: with glowing head
  // and tail lamps (CarLamps gives the headlight positions).
  int Get(int shape, int color, bool lit = false) {
    const int key = (shape * kNumCarColors + color) * 2 + (lit ? 1 : 0);
    auto it = meshes_.find(key);
    if (it != meshes_.end()) return it->second;
    const CarShape& s = kCarShapes[shape];
    const std::string name = std::string("car_") + s.name + "_" + std::to_string(color) + (lit ? "_lit" : "");
    const Vec3f paint = kCarColors[color];
    const int side = AddMaterial(scene_, name + "_side", paint, tex_.side);
    const int end = AddMaterial(scene_, name + "_end", paint, tex_.end);
    const int top = AddMaterial(scene_, name + "_top", paint, -1);
    MeshBuilder b(name);
    const float hl = 0.5f * s.length, hw = 0.5f * s.width;
    const int body[5] = {end, end, side, side, top};
    b.Box({-hl, -hw, 0.3f}, {hl, hw, s.body_top}, body);
    const float c0 = s.cabin_shift - 0.5f * s.cabin_length, c1 = s.cabin_shift + 0.5f * s.cabin_length;
    const int cabin[5] = {glass_, glass_, glass_, glass_, top};
    b.Box({c0, -hw + 0.1f, s.body_top}, {c1, hw - 0.1f, s.cabin_top}, cabin);
    for (float wx : {-hl + 0.8f, hl - 0.8f})
      for (float wy : {-hw + 0.12f, hw - 0.34f}) b.Prism({wx, wy, 0.33f}, 0.33f, 0.0f, 0.22f, 8, tyre_, tyre_, true);
    if (lit) AddLamps(b, s);
    const int mesh = AddMesh(scene_, b.Finish());
    meshes_[key] = mesh;
    return mesh;
  }

  // Headlight spots of a lit car of `shape`, in the car's frame, riding on object `object`.
  static std::vector<Light> Headlights(int shape, int object, const std::string& name) {
    const CarShape& s = kCarShapes[shape];
    std::vector<Light> lights;
    for (const double side : {-1.0, 1.0}) {
      Light l;
      l.name = name + (side < 0 ? "_headlight_right" : "_headlight_left");
      l.position = Eigen::Vector3d(0.5 * s.length + 0.05, side * (0.5 * s.width - 0.35), 0.65);
      l.intensity = Eigen::Vector3f(0.3f, 0.3f, 0.28f);  // about 10 street lamps on axis
      l.range = 60.0;
      l.object = object;
      l.spot = true;
      l.spot_direction = Eigen::Vector3d(1.0, 0.0, -0.06);  // dipped beam, 3.4 degrees down
      l.spot_angle_deg = 55.0;
      l.spot_blend = 0.6;
      lights.push_back(l);
    }
    return lights;
  }

 private:
  // Glowing head lamps (front corners) and tail lamps (rear corners) of a lit car.
  void AddLamps(MeshBuilder& b, const CarShape& s) {
    if (headlamp_ < 0) {
      headlamp_ = AddMaterial(scene_, "car_headlamp", {0.9f, 0.9f, 0.9f}, -1);
      scene_.materials[headlamp_].emission = {20.0f, 20.0f, 18.0f};
      taillamp_ = AddMaterial(scene_, "car_taillamp", {0.6f, 0.05f, 0.05f}, -1);
      scene_.materials[taillamp_].emission = {1.5f, 0.05f, 0.03f};
    }
    const float hl = 0.5f * s.length, hw = 0.5f * s.width;
    const int head[5] = {headlamp_, headlamp_, headlamp_, headlamp_, headlamp_};
    const int tail[5] = {taillamp_, taillamp_, taillamp_, taillamp_, taillamp_};
    for (const float side : {-1.0f, 1.0f}) {
      const float y0 = side * (hw - 0.35f) - 0.13f, y1 = y0 + 0.26f;
      b.Box({hl - 0.02f, y0, 0.58f}, {hl + 0.03f, y1, 0.72f}, head);
      b.Box({-hl - 0.03f, y0, 0.7f}, {-hl + 0.02f, y1, 0.82f}, tail);
    }
  }

  Scene& scene_;
  CarTextures tex_;
  int glass_, tyre_;
  int headlamp_ = -1, taillamp_ = -1;
  std::map<int, int> meshes_;
};

// Oriented rectangle (car footprint) overlap by separating axes.
struct Footprint {
  Eigen::Vector2d centre;
  double yaw, half_length, half_width;
};
bool Overlap(const Footprint& a, const Footprint& b) {
  if ((a.centre - b.centre).norm() > a.half_length + a.half_width + b.half_length + b.half_width) return false;
  const Eigen::Vector2d axes[4] = {{std::cos(a.yaw), std::sin(a.yaw)},
                                   {-std::sin(a.yaw), std::cos(a.yaw)},
                                   {std::cos(b.yaw), std::sin(b.yaw)},
                                   {-std::sin(b.yaw), std::cos(b.yaw)}};
  const Eigen::Vector2d d = b.centre - a.centre;
  for (const Eigen::Vector2d& n : axes) {
    const double ra = a.half_length * std::abs(n.dot(axes[0])) + a.half_width * std::abs(n.dot(axes[1]));
    const double rb = b.half_length * std::abs(n.dot(axes[2])) + b.half_width * std::abs(n.dot(axes[3]));
    if (std::abs(d.dot(n)) > ra + rb) return false;
  }
  return true;
}

struct VehicleTrack {
  int shape = 0, color = 0;
  std::string kind;
  std::vector<Rigid3> world_from_object;  // per frame
  std::vector<bool> active;               // on its path (else parked out of sight)
};

// Pose of a vehicle at arc length s of a path; s outside the path hides it 100 m below the ground.
Rigid3 VehiclePose(const LanePath& path, double s, bool* active) {
  *active = s >= 0 && s <= path.Length();
  if (!*active) return Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -100));
  const Eigen::Vector2d p = path.Position(s);
  return PlaceYaw(p.x(), p.y(), path.Heading(s));
}

std::vector<VehicleTrack> PlanTraffic(const CityLayout& L, uint64_t seed, int frames, double rate) {
  SceneRng rng(SubSeed(seed, "traffic"));
  std::vector<VehicleTrack> accepted;
  std::vector<Footprint> rig(frames);
  for (int f = 0; f < frames; ++f) {
    const Rigid3& p = L.trajectory[f].world_from_rig;
    rig[f] = {p.translation.head<2>(), L.rig_path.Heading(L.drive.s[f]), 2.6, 1.2};  // the rig's car, with margin
  }
  auto footprint = [](const VehicleTrack& v, int f) {
    const Rigid3& p = v.world_from_object[f];
    const Eigen::Vector3d x = p.rotation * Eigen::Vector3d::UnitX();
    return Footprint{p.translation.head<2>(), std::atan2(x.y(), x.x()), 0.5 * kCarShapes[v.shape].length + 0.4,
                     0.5 * kCarShapes[v.shape].width + 0.2};
  };
  auto try_accept = [&](VehicleTrack v) {
    for (int f = 0; f < frames; ++f) {
      if (!v.active[f]) continue;
      const Footprint a = footprint(v, f);
      if (Overlap(a, rig[f])) return false;
      for (const VehicleTrack& o : accepted)
        if (o.active[f] && Overlap(a, footprint(o, f))) return false;
    }
    accepted.push_back(std::move(v));
    return true;
  };
  auto new_track = [&](const char* kind) {
    VehicleTrack v;
    v.kind = kind;
    v.shape = rng.UniformInt(0, kNumCarShapes - 1);
    v.color = rng.UniformInt(0, kNumCarColors - 1);
    v.world_from_object.resize(frames);
    v.active.resize(frames);
    return v;
  };
  const double duration = (frames - 1) / rate;
  const double lane = 0.25 * (L.style.road_width_m - 2 * L.style.parking_lane_m);

  // 1) A lead vehicle in the rig's lane, 12-35 m ahead (fills much of the front view).
  {
    VehicleTrack v = new_track("lead");
    const double period = rng.Uniform(30, 50), phase = rng.Uniform(0, 2 * M_PI);
    for (int f = 0; f < frames; ++f) {
      const double t = f / rate;
      const double gap = 23.5 - 11.5 * std::cos(2 * M_PI * t / period + phase);
      bool active;
      v.world_from_object[f] = VehiclePose(L.rig_path, L.drive.s[f] + gap, &active);
      v.active[f] = active;
    }
    try_accept(std::move(v));
  }
  // 2) Oncoming traffic on the rig's route, opposite lane, passing 3.5 m from the rig.
  {
    GridRoute reversed(L.route.rbegin(), L.route.rend());
    const LanePath back = PathAlongRoute(L.grid, reversed, lane);
    const double speed = rng.Uniform(8, 11), spacing = rng.Uniform(35, 55);
    for (double s0 = -speed * duration; s0 < back.Length(); s0 += spacing * rng.Uniform(0.8, 1.2)) {
      VehicleTrack v = new_track("oncoming");
      bool any = false;
      for (int f = 0; f < frames; ++f) {
        bool active;
        v.world_from_object[f] = VehiclePose(back, s0 + speed * f / rate, &active);
        v.active[f] = active;
        any = any || active;
      }
      if (any) try_accept(std::move(v));
    }
  }
  // 3) Cross traffic: random routes through the grid at constant speed; rejected if they would
  //    ever overlap the rig or an accepted vehicle.
  const int candidates = L.quick ? 12 : 60;
  const int nx = static_cast<int>(L.grid.xs.size()), ny = static_cast<int>(L.grid.ys.size());
  for (int c = 0; c < candidates; ++c) {
    const double speed = rng.Uniform(6, 11);
    const Eigen::Vector2i start(rng.UniformInt(0, nx - 1), rng.UniformInt(0, ny - 1));
    const GridRoute route = RandomRoute(L.grid, rng, speed * duration + 150, 0.5, start, rng.UniformInt(0, 3));
    const LanePath path = PathAlongRoute(L.grid, route, lane);
    const double s0 = rng.Uniform(0, 80);
    VehicleTrack v = new_track("cross");
    for (int f = 0; f < frames; ++f) {
      bool active;
      v.world_from_object[f] = VehiclePose(path, s0 + speed * f / rate, &active);
      v.active[f] = active;
    }
    try_accept(std::move(v));
  }
  return accepted;
}

// ---- buildings -----------------------------------------------------------------------------------

// Shared materials of the architectural details.
struct ArchitectureMaterials {
  int roof = -1;
  std::vector<int> trim;        // cornices, parapets, balcony slabs, rooftop structures
  std::vector<int> roof_tiles;  // pitched roofs
  std::vector<int> railing;     // balcony railings (plain paint)
  std::vector<int> awning;      // striped cloth
  int metal = -1;
};

// The street-facing wall of a building's base box, and where the facade texture paints its windows
// (MakeFacadeTexture's integer pixel arithmetic reproduced) in wall coordinates d (metres from origin).
struct StreetFacade {
  Eigen::Vector2d origin, along;  // wall start and unit direction (outward normal on its right)
  double length = 0.0;
  double texel = 0.0;  // metres per facade texel (both axes)
  int bay_px = 0, win_w_px = 0, win_h_px = 0;
  int win_top_px = 0;  // below the floor's top
  int floors = 0;
  double top = 0.0;  // base box top (parapet included)
  std::vector<double> bay_edges, window_centres;
  std::function<Vec2f(double, double)> facade_uv;  // uv of the facade texture at (d, z)
  double FloorTop(int k) const { return kStorefrontHeightMetres + (k + 1) * kFloorHeightMetres; }
};

StreetFacade MakeStreetFacade(const BuildingPlan& p, const FacadeLayout& fl) {
  StreetFacade f;
  f.texel = kFacadeTileMetres / 1024.0;
  f.bay_px = 1024 / fl.bays;
  f.win_w_px = static_cast<int>(f.bay_px * fl.window_width_fraction);
  f.win_h_px = static_cast<int>(256 * fl.window_height_fraction);
  f.win_top_px = (256 - f.win_h_px) / 2 - 8;
  f.floors =
      std::max(1, static_cast<int>(std::lround((p.height - 0.4 - kStorefrontHeightMetres) / kFloorHeightMetres)));
  const Eigen::Vector2d corners[4] = {p.footprint.min,
                                      {p.footprint.max.x(), p.footprint.min.y()},
                                      p.footprint.max,
                                      {p.footprint.min.x(), p.footprint.max.y()}};
  int street = 0;
  for (int e = 0; e < 4; ++e) {
    const Eigen::Vector2d along = (corners[(e + 1) % 4] - corners[e]).normalized();
    if (Eigen::Vector2d(along.y(), -along.x()).dot(p.facing) > 0.5) street = e;
  }
  f.origin = corners[street];
  f.along = (corners[(street + 1) % 4] - f.origin).normalized();
  f.length = (corners[(street + 1) % 4] - f.origin).norm();
  const double u_offset = p.u_offset;
  f.facade_uv = [u_offset](double d, double z) {
    return Vec2f(static_cast<float>((u_offset + d) / kFacadeTileMetres),
                 static_cast<float>(100.0 - (z - kStorefrontHeightMetres) / kFacadeTileMetres));
  };
  // Wall coordinate d of texture column x (pixels, any tile).
  auto d_of_px = [&](double x) { return x * f.texel - p.u_offset; };
  const int tile_first = static_cast<int>(std::floor(p.u_offset / kFacadeTileMetres)) - 1;
  const int tile_last = static_cast<int>(std::ceil((p.u_offset + f.length) / kFacadeTileMetres)) + 1;
  for (int t = tile_first; t <= tile_last; ++t)
    for (int k = 0; k < fl.bays; ++k) {
      const double x0 = 1024.0 * t + k * f.bay_px;
      f.bay_edges.push_back(d_of_px(x0));
      f.window_centres.push_back(d_of_px(x0 + (f.bay_px - f.win_w_px) / 2 + 0.5 * f.win_w_px));
    }
  f.top = p.height;
  return f;
}

// Storefront ground floor, facade walls and flat roofs of the base box and of the setback.
void AddBuildingWalls(MeshBuilder& b, const BuildingPlan& p, int m_facade, int m_shop, int m_roof, bool hip_roof) {
  auto walls = [&](const Box2& fp, double z0, double z1, bool shops, bool roof) {
    const Eigen::Vector2d c[4] = {fp.min, {fp.max.x(), fp.min.y()}, fp.max, {fp.min.x(), fp.max.y()}};
    for (int e = 0; e < 4; ++e) {
      // Counter-clockwise walk (c[e] -> c[e+1]): the outward normal is on the right and the
      // texture's u runs left to right for a viewer outside (signs are not mirrored).
      const Eigen::Vector2d a = c[e], bb = c[(e + 1) % 4];
      double zs = z0;
      if (shops) {
        b.Wall(a, bb, 0.0, kStorefrontHeightMetres, p.u_offset, kFacadeTileMetres, 1.0, kStorefrontHeightMetres,
               m_shop);
        zs = kStorefrontHeightMetres;
      }
      // v = 100 at z = 4 m: texture floor boundaries coincide with storey boundaries.
      const double v0 = 100.0 - (zs - kStorefrontHeightMetres) / kFacadeTileMetres;
      b.Wall(a, bb, zs, z1, p.u_offset, kFacadeTileMetres, v0, kFacadeTileMetres, m_facade);
    }
    if (roof) b.Floor(fp.min, fp.max, z1, kRoofTileMetres, m_roof);
  };
  walls(p.footprint, 0.0, p.height, true, !hip_roof);
  if (p.has_setback) walls(p.upper_footprint, p.height, p.upper_height, false, true);
}

// Facade relief: the wall between the windows steps forward, so the windows sit in recesses.
void AddFacadeRelief(MeshBuilder& b, const StreetFacade& f, const FacadeLayout& fl, double r_relief, int m_facade,
                     SceneRng& arch) {
  const double texel = f.texel, length = f.length, top = f.top;
  if (fl.style == 3) {
    if (r_relief < 0.7) {  // glass curtain wall: thin vertical fins at the mullion lines
      const double fin_w = std::min(0.1, 0.6 * (f.bay_px - f.win_w_px) * texel), fin_d = arch.Uniform(0.3, 0.5);
      for (double d : f.bay_edges)
        if (d - fin_w > 0.2 && d + fin_w < length - 0.2)
          b.WallBlock(f.origin, f.along, d - 0.5 * fin_w, d + 0.5 * fin_w, 0.0, fin_d, kStorefrontHeightMetres, top,
                      f.facade_uv, m_facade);
    }
  } else if (r_relief < 0.6) {
    const double depth = arch.Uniform(0.12, 0.3);
    const int kind = arch.UniformInt(0, 2);  // 0 pilasters, 1 floor bands, 2 both
    if (kind != 1) {
      const double w = std::min(0.45, 0.7 * (f.bay_px - f.win_w_px) * texel);
      // Corner pilasters where no painted window column reaches the corner.
      auto clear_of_windows = [&](double d0, double d1) {
        for (double dc : f.window_centres)
          if (d1 > dc - 0.5 * f.win_w_px * texel && d0 < dc + 0.5 * f.win_w_px * texel) return false;
        return true;
      };
      if (clear_of_windows(0.0, w))
        b.WallBlock(f.origin, f.along, 0.0, w, 0.0, depth, kStorefrontHeightMetres, top, f.facade_uv, m_facade);
      if (clear_of_windows(length - w, length))
        b.WallBlock(f.origin, f.along, length - w, length, 0.0, depth, kStorefrontHeightMetres, top, f.facade_uv,
                    m_facade);
      for (double d : f.bay_edges)
        if (d - w > 0.3 && d + w < length - 0.3)
          b.WallBlock(f.origin, f.along, d - 0.5 * w, d + 0.5 * w, 0.0, depth, kStorefrontHeightMetres, top,
                      f.facade_uv, m_facade);
    }
    if (kind != 0) {
      // From the window top of one floor to the window bottom of the next (the storefront top and
      // the roof close the first and last band).
      for (int k = 0; k <= f.floors; ++k) {
        const double z0 = k == 0 ? kStorefrontHeightMetres : f.FloorTop(k - 1) - f.win_top_px * texel;
        const double z1 = k == f.floors ? top : f.FloorTop(k) - (f.win_top_px + f.win_h_px) * texel;
        if (z1 - z0 > 0.05) b.WallBlock(f.origin, f.along, 0.0, length, 0.0, depth, z0, z1, f.facade_uv, m_facade);
      }
    }
  }
}

// Balconies under the windows of the street side: slab, front and side railing panels.
void AddBalconies(MeshBuilder& b, const StreetFacade& f, const ArchitectureMaterials& am, SceneRng& arch) {
  const double texel = f.texel, length = f.length;
  const double depth = arch.Uniform(0.9, 1.3);
  const int stride = arch.UniformInt(1, 2), phase = arch.UniformInt(0, 1), first_floor = arch.UniformInt(0, 1);
  const int rail = am.railing[arch.UniformInt(0, static_cast<int>(am.railing.size()) - 1)];
  const int slab = am.trim[arch.UniformInt(0, static_cast<int>(am.trim.size()) - 1)];
  const double half = std::min(0.5 * f.win_w_px * texel + 0.3, 0.5 * f.bay_px * texel - 0.05);
  auto plain_uv = [](double d, double z) {
    return Vec2f(static_cast<float>(d / kRoofTileMetres), static_cast<float>(-z / kRoofTileMetres));
  };
  int count = 0;
  for (size_t i = 0; i < f.window_centres.size(); ++i) {
    const double dc = f.window_centres[i];
    if (static_cast<int>(i) % stride != phase % stride || dc - half < 0.3 || dc + half > length - 0.3) continue;
    for (int k = first_floor; k < f.floors && count < 120; ++k, ++count) {
      const double z = kStorefrontHeightMetres + k * kFloorHeightMetres;  // floor level
      b.WallBlock(f.origin, f.along, dc - half, dc + half, 0.0, depth, z - 0.18, z, plain_uv, slab);
      b.WallBlock(f.origin, f.along, dc - half, dc + half, depth - 0.05, depth, z, z + 1.0, plain_uv, rail);
      b.WallBlock(f.origin, f.along, dc - half, dc - half + 0.05, 0.0, depth - 0.05, z, z + 1.0, plain_uv, rail);
      b.WallBlock(f.origin, f.along, dc + half - 0.05, dc + half, 0.0, depth - 0.05, z, z + 1.0, plain_uv, rail);
    }
  }
}

// Awnings over the shop windows: a sloped cloth, a front valance and closed sides.
void AddAwnings(MeshBuilder& b, const StreetFacade& f, const ArchitectureMaterials& am, const CityStyle& st,
                SceneRng& arch) {
  const Eigen::Vector2d& origin = f.origin;
  const Eigen::Vector2d& along = f.along;
  const double length = f.length;
  const double reach = std::min(1.3, st.sidewalk_width_m - 0.8);
  const int n = arch.UniformInt(1, 3);
  const double part = length / n;
  for (int i = 0; i < n; ++i) {
    const double w = arch.Uniform(std::min(2.0, part - 0.8), part - 0.8);
    const double d0 = i * part + 0.4 + arch.Uniform(0.0, part - 0.8 - w), d1 = d0 + w;
    const int m = am.awning[arch.UniformInt(0, static_cast<int>(am.awning.size()) - 1)];
    if (w < 1.0) continue;
    const double z_wall = 3.15, z_edge = 2.6, z_low = 2.35;
    const Eigen::Vector2d normal(along.y(), -along.x());
    auto at = [&](double d, double nn, double z) {
      const Eigen::Vector2d xy = origin + d * along + nn * normal;
      return MeshBuilder::P(xy.x(), xy.y(), z);
    };
    const float u0 = static_cast<float>(d0 / 2.56), u1 = static_cast<float>(d1 / 2.56);
    const float v_edge = static_cast<float>(std::hypot(reach, z_wall - z_edge) / 0.64);
    const float v_low = v_edge + static_cast<float>((z_edge - z_low) / 0.64);
    b.Quad(at(d0, reach, z_edge), at(d1, reach, z_edge), at(d1, 0.0, z_wall), at(d0, 0.0, z_wall), {u0, v_edge},
           {u1, v_edge}, {u1, 0}, {u0, 0}, m);
    b.Quad(at(d0, reach, z_low), at(d1, reach, z_low), at(d1, reach, z_edge), at(d0, reach, z_edge), {u0, v_low},
           {u1, v_low}, {u1, v_edge}, {u0, v_edge}, m);
    b.Tri(at(d0, 0.0, z_wall), at(d0, reach, z_low), at(d0, reach, z_edge), {0, 0}, {0.2f, v_low}, {0.2f, v_edge}, m);
    b.Tri(at(d1, 0.0, z_wall), at(d1, reach, z_edge), at(d1, reach, z_low), {0, 0}, {0.2f, v_edge}, {0.2f, v_low}, m);
  }
}

// A hipped roof over `roof_fp` at height `roof_z`, with eaves and a soffit of material `trim`.
void AddHipRoof(MeshBuilder& b, const Box2& roof_fp, double roof_z, int trim, const ArchitectureMaterials& am,
                SceneRng& arch) {
  const double eave = arch.Uniform(0.3, 0.6), pitch = arch.Uniform(22.0, 35.0) * M_PI / 180.0;
  const int tiles = am.roof_tiles[arch.UniformInt(0, static_cast<int>(am.roof_tiles.size()) - 1)];
  const Eigen::Vector2d lo = roof_fp.min.array() - eave, hi = roof_fp.max.array() + eave;
  // Local frame: a along the ridge, c across it.
  const bool ridge_x = hi.x() - lo.x() >= hi.y() - lo.y();
  const double a0 = ridge_x ? lo.x() : lo.y(), a1 = ridge_x ? hi.x() : hi.y();
  const double c0 = ridge_x ? lo.y() : lo.x(), c1 = ridge_x ? hi.y() : hi.x();
  const double half = 0.5 * (c1 - c0), cm = 0.5 * (c0 + c1), rise = half * std::tan(pitch);
  auto P = [&](double a, double c, double z) { return ridge_x ? MeshBuilder::P(a, c, z) : MeshBuilder::P(c, a, z); };
  auto uv = [&](double a, double c) {
    return Vec2f(static_cast<float>(a / kRoofTileMetres), static_cast<float>(c / kRoofTileMetres));
  };
  const double z = roof_z, zr = roof_z + rise;
  // With ridge_x false the local frame is mirrored; the tracer shades both sides of a triangle.
  b.Quad(P(a0, c0, z), P(a1, c0, z), P(a1 - half, cm, zr), P(a0 + half, cm, zr), uv(a0, c0), uv(a1, c0),
         uv(a1 - half, cm), uv(a0 + half, cm), tiles);
  b.Quad(P(a1, c1, z), P(a0, c1, z), P(a0 + half, cm, zr), P(a1 - half, cm, zr), uv(a1, c1), uv(a0, c1),
         uv(a0 + half, cm), uv(a1 - half, cm), tiles);
  b.Tri(P(a0, c1, z), P(a0, c0, z), P(a0 + half, cm, zr), uv(c1, a0), uv(c0, a0), uv(cm, a0 + half), tiles);
  b.Tri(P(a1, c0, z), P(a1, c1, z), P(a1 - half, cm, zr), uv(c0, a1), uv(c1, a1), uv(cm, a1 - half), tiles);
  b.Floor(lo, hi, z, kRoofTileMetres, trim);  // eave soffit (and ceiling under the roof)
}

// Roofline: a hipped roof on some low buildings, else a cornice or a parapet. Returns the trim
// material it drew (the rooftop structures use it too).
int AddRoofline(MeshBuilder& b, const BuildingPlan& p, bool hip_roof, double r_roof, const ArchitectureMaterials& am,
                SceneRng& arch) {
  const int trim = am.trim[arch.UniformInt(0, static_cast<int>(am.trim.size()) - 1)];
  const Box2& roof_fp = p.has_setback ? p.upper_footprint : p.footprint;
  const double roof_z = p.has_setback ? p.upper_height : p.height;
  if (hip_roof) {
    AddHipRoof(b, roof_fp, roof_z, trim, am, arch);
  } else if (r_roof < 0.75) {
    const double over = arch.Uniform(0.25, 0.45), height = arch.Uniform(0.4, 0.7);
    const int faces[5] = {trim, trim, trim, trim, am.roof};
    auto cornice = [&](const Box2& fp, double z) {
      b.Box(MeshBuilder::P(fp.min.x() - over, fp.min.y() - over, z - height),
            MeshBuilder::P(fp.max.x() + over, fp.max.y() + over, z + 0.05), faces, static_cast<float>(kRoofTileMetres),
            true);
    };
    cornice(p.footprint, p.height);
    if (p.has_setback) cornice(p.upper_footprint, p.upper_height);
  } else {
    const double h = arch.Uniform(0.6, 1.1), t = 0.25;
    const int faces[5] = {trim, trim, trim, trim, trim};
    const Box2& fp = roof_fp;
    const float z0 = static_cast<float>(roof_z), z1 = static_cast<float>(roof_z + h);
    auto box = [&](double x0, double y0, double x1, double y1) {
      b.Box(MeshBuilder::P(x0, y0, z0), MeshBuilder::P(x1, y1, z1), faces, static_cast<float>(kRoofTileMetres));
    };
    box(fp.min.x(), fp.min.y(), fp.max.x(), fp.min.y() + t);
    box(fp.min.x(), fp.max.y() - t, fp.max.x(), fp.max.y());
    box(fp.min.x(), fp.min.y() + t, fp.min.x() + t, fp.max.y() - t);
    box(fp.max.x() - t, fp.min.y() + t, fp.max.x(), fp.max.y() - t);
  }
  return trim;
}

// Rooftop structures on a flat roof: stair house, air conditioners, sometimes a water tank.
void AddRooftopStructures(MeshBuilder& b, const BuildingPlan& p, int trim, const ArchitectureMaterials& am,
                          SceneRng& arch) {
  const Box2& roof_fp = p.has_setback ? p.upper_footprint : p.footprint;
  const double roof_z = p.has_setback ? p.upper_height : p.height;
  const Eigen::Vector2d room = roof_fp.max - roof_fp.min;
  const int faces[5] = {trim, trim, trim, trim, am.roof};
  const float z = static_cast<float>(roof_z);
  auto spot = [&](double sx, double sy) {
    return Eigen::Vector2d(arch.Uniform(roof_fp.min.x() + 1.0, roof_fp.max.x() - 1.0 - sx),
                           arch.Uniform(roof_fp.min.y() + 1.0, roof_fp.max.y() - 1.0 - sy));
  };
  const double sx = std::min(room.x() - 2.5, arch.Uniform(2.2, 3.5)),
               sy = std::min(room.y() - 2.5, arch.Uniform(2.2, 3.5));
  const Eigen::Vector2d s0 = spot(sx, sy);
  b.Box(MeshBuilder::P(s0.x(), s0.y(), z), MeshBuilder::P(s0.x() + sx, s0.y() + sy, z + arch.Uniform(2.4, 3.0)), faces,
        static_cast<float>(kRoofTileMetres));
  const int units = arch.UniformInt(0, 3);
  const int metal[5] = {am.metal, am.metal, am.metal, am.metal, am.metal};
  for (int i = 0; i < units; ++i) {
    const Eigen::Vector2d u0 = spot(1.2, 0.8);
    b.Box(MeshBuilder::P(u0.x(), u0.y(), z), MeshBuilder::P(u0.x() + 1.2, u0.y() + 0.8, z + 0.9), metal);
  }
  if (arch.Bernoulli(0.3)) {
    const double r = arch.Uniform(0.8, 1.2);
    const Eigen::Vector2d t0 = spot(2 * r, 2 * r);
    b.Prism(MeshBuilder::P(t0.x() + r, t0.y() + r, 0), static_cast<float>(r), z,
            z + static_cast<float>(arch.Uniform(2.0, 3.0)), 10, am.metal, am.metal);
  }
}

// One building: storefront ground floor, facade walls, roof, and real geometry that lines up with
// the facade texture's windows (facade relief that recesses the windows, glass-wall fins,
// balconies), awnings over the shops, a roofline (cornice, parapet or hipped roof) and rooftop
// structures. `arch` draws every random choice, in a fixed order per building.
void AddBuilding(MeshBuilder& b, const BuildingPlan& p, const FacadeLayout& fl, int m_facade, int m_shop,
                 const ArchitectureMaterials& am, const CityStyle& st, SceneRng& arch) {
  const StreetFacade facade = MakeStreetFacade(p, fl);
  const double r_relief = arch.Uniform(), r_balcony = arch.Uniform(), r_roof = arch.Uniform(),
               r_awning = arch.Uniform(), r_rooftop = arch.Uniform();
  const bool hip_roof = !p.has_setback && p.height <= 17.0 && fl.style != 3 && r_roof < 0.45;

  AddBuildingWalls(b, p, m_facade, m_shop, am.roof, hip_roof);
  AddFacadeRelief(b, facade, fl, r_relief, m_facade, arch);
  if (fl.style != 3 && facade.floors >= 2 && r_balcony < 0.3) AddBalconies(b, facade, am, arch);
  if (r_awning < 0.45 && facade.length > 3.0) AddAwnings(b, facade, am, st, arch);
  const int trim = AddRoofline(b, p, hip_roof, r_roof, am, arch);
  const Box2& roof_fp = p.has_setback ? p.upper_footprint : p.footprint;
  const Eigen::Vector2d room = roof_fp.max - roof_fp.min;
  if (!hip_roof && r_rooftop < 0.55 && room.minCoeff() > 5.0) AddRooftopStructures(b, p, trim, am, arch);
}

// ---- suburban houses ----------------------------------------------------------------------------

struct HouseMaterials {
  int glass = -1, frame = -1, door = -1, plinth = -1;
};

// The four walls of a footprint, counter-clockwise seen from above: origin, unit direction (outward
// normal on its right) and length; `street` is the index of the wall facing `facing`.
struct FootprintWalls {
  Eigen::Vector2d origin[4], along[4];
  double length[4];
  int street = 0;
};

FootprintWalls WallsOf(const Box2& fp, const Eigen::Vector2d& facing) {
  FootprintWalls w;
  const Eigen::Vector2d c[4] = {fp.min, {fp.max.x(), fp.min.y()}, fp.max, {fp.min.x(), fp.max.y()}};
  for (int e = 0; e < 4; ++e) {
    w.origin[e] = c[e];
    w.length[e] = (c[(e + 1) % 4] - c[e]).norm();
    w.along[e] = (c[(e + 1) % 4] - c[e]) / w.length[e];
    if (Eigen::Vector2d(w.along[e].y(), -w.along[e].x()).dot(facing) > 0.5) w.street = e;
  }
  return w;
}

// A detached house: plain rendered walls, a plinth, a few framed windows per storey (more on the
// street side), a front door and a hipped roof. `arch` draws every random choice in a fixed order.
void AddHouse(MeshBuilder& b, const BuildingPlan& p, int m_wall, const HouseMaterials& hm,
              const ArchitectureMaterials& am, SceneRng& arch) {
  const FootprintWalls w = WallsOf(p.footprint, p.facing);
  const int storeys = static_cast<int>(std::lround(p.height / kHouseStoreyMetres));
  const int street_windows = arch.UniformInt(2, 3);
  auto plain_uv = [](double d, double z) {
    return Vec2f(static_cast<float>(d / kHouseWallTileMetres), static_cast<float>(-z / kHouseWallTileMetres));
  };
  for (int e = 0; e < 4; ++e) {
    const double len = w.length[e];
    b.Wall(w.origin[e], w.origin[e] + len * w.along[e], 0.0, p.height, 0.0, kHouseWallTileMetres, 0.0,
           kHouseWallTileMetres, m_wall);
    b.WallBlock(w.origin[e], w.along[e], 0.0, len, 0.0, 0.04, 0.0, 0.4, plain_uv, hm.plinth);
    // Window centres along the wall (fractions); on the street side the door takes the middle of
    // the ground floor.
    const bool street = e == w.street;
    std::vector<double> at;
    if (street)
      at = street_windows == 2 ? std::vector<double>{0.25, 0.75} : std::vector<double>{0.2, 0.5, 0.8};
    else if (len > 7.0)
      at = {0.5};
    for (int k = 0; k < storeys; ++k) {
      const double z0 = k * kHouseStoreyMetres + 0.9, z1 = z0 + 1.3;
      for (const double f : at) {
        if (street && k == 0 && f == 0.5) continue;
        const double dc = f * len, d0 = dc - 0.6, d1 = dc + 0.6;
        b.WallBlock(w.origin[e], w.along[e], d0, d1, 0.0, 0.02, z0, z1, plain_uv, hm.glass);
        b.WallBlock(w.origin[e], w.along[e], d0 - 0.07, d1 + 0.07, 0.0, 0.06, z1, z1 + 0.07, plain_uv, hm.frame);
        b.WallBlock(w.origin[e], w.along[e], d0 - 0.07, d1 + 0.07, 0.0, 0.08, z0 - 0.07, z0, plain_uv, hm.frame);
        b.WallBlock(w.origin[e], w.along[e], d0 - 0.07, d0, 0.0, 0.06, z0, z1, plain_uv, hm.frame);
        b.WallBlock(w.origin[e], w.along[e], d1, d1 + 0.07, 0.0, 0.06, z0, z1, plain_uv, hm.frame);
      }
    }
    if (street)
      b.WallBlock(w.origin[e], w.along[e], 0.5 * len - 0.5, 0.5 * len + 0.5, 0.0, 0.05, 0.0, 2.1, plain_uv, hm.door);
  }
  AddHipRoof(b, p.footprint, p.height, am.trim[arch.UniformInt(0, static_cast<int>(am.trim.size()) - 1)], am, arch);
}

// Texture indices of the generated textures (in scene.textures).
struct CityTextures {
  int num_facades = 0, num_storefronts = 0, num_awnings = 0;  // facades first, then storefronts
  int road = 0, intersection = 0, sidewalk = 0, concrete = 0, ground = 0, bark = 0, foliage = 0, sign = 0, awning = 0;
  int lawn = -1;  // suburban lots only
  CarTextures car;
};

// Generates every texture in parallel (each from its own seed, so the result does not depend on threads).
CityTextures GenerateTextures(Scene& scene, const CityStyle& st, uint64_t texture_seed, bool quick) {
  CityTextures t;
  t.num_facades = quick ? std::max(4, st.facade_textures / 3) : st.facade_textures;
  t.num_storefronts = quick ? std::max(3, st.storefront_textures / 2) : st.storefront_textures;
  if (st.houses) t.num_storefronts = 0;  // houses: plain walls (MakeHouseWallTexture), no shops
  t.num_awnings = quick ? 3 : 6;
  std::vector<std::function<Texture()>> jobs;
  for (int i = 0; i < t.num_facades; ++i) {
    if (st.houses)
      jobs.push_back([=] { return MakeHouseWallTexture(texture_seed, i); });
    else
      jobs.push_back([=] { return MakeFacadeTexture(texture_seed, i); });
  }
  for (int i = 0; i < t.num_storefronts; ++i) jobs.push_back([=] { return MakeStorefrontTexture(texture_seed, i); });
  const auto next = [&jobs] { return static_cast<int>(jobs.size()); };
  t.road = next();
  for (int i = 0; i < 2; ++i)
    jobs.push_back([=] { return MakeRoadTexture(texture_seed, i, st.road_width_m, st.parking_lane_m); });
  t.intersection = next();
  jobs.push_back([=] { return MakeIntersectionTexture(texture_seed, st.road_width_m); });
  t.sidewalk = next();
  jobs.push_back([=] { return MakeSidewalkTexture(texture_seed); });
  t.concrete = next();
  jobs.push_back([=] { return MakeConcreteTexture(texture_seed); });
  t.ground = next();
  jobs.push_back([=] { return MakeGroundTexture(texture_seed); });
  t.car.side = next();
  jobs.push_back([=] { return MakeCarSideTexture(texture_seed); });
  t.car.end = next();
  jobs.push_back([=] { return MakeCarEndTexture(texture_seed); });
  t.car.glass = next();
  jobs.push_back([=] { return MakeCarGlassTexture(texture_seed); });
  t.bark = next();
  jobs.push_back([=] { return MakeBarkTexture(texture_seed); });
  t.foliage = next();
  jobs.push_back([=] { return MakeFoliageTexture(texture_seed); });
  t.sign = next();
  for (int k = 0; k < kSignKinds; ++k) jobs.push_back([=] { return MakeSignTexture(texture_seed, k); });
  t.awning = next();
  for (int k = 0; k < t.num_awnings; ++k) jobs.push_back([=] { return MakeAwningTexture(texture_seed, k); });
  if (st.houses) {
    t.lawn = next();
    jobs.push_back([=] { return MakeLawnTexture(texture_seed); });
  }
  scene.textures.resize(jobs.size());
  tbb::parallel_for(size_t{0}, jobs.size(), [&](size_t i) { scene.textures[i] = jobs[i](); });
  return t;
}

// Materials shared by the whole city (material indices).
struct CityMaterials {
  int road[2] = {0, 0};
  int intersection = 0, sidewalk = 0, curb = 0, roof = 0, ground = 0, metal = 0, lamp = 0, bark = 0, foliage = 0;
  int lawn = -1;  // suburban lots only
};

CityMaterials AddSharedMaterials(Scene& scene, const CityTextures& t) {
  CityMaterials m;
  m.road[0] = AddMaterial(scene, "road_0", {1, 1, 1}, t.road);
  m.road[1] = AddMaterial(scene, "road_1", {1, 1, 1}, t.road + 1);
  m.intersection = AddMaterial(scene, "intersection", {1, 1, 1}, t.intersection);
  m.sidewalk = AddMaterial(scene, "sidewalk", {1, 1, 1}, t.sidewalk);
  m.curb = AddMaterial(scene, "curb", {0.95f, 0.95f, 0.95f}, t.concrete);
  m.roof = AddMaterial(scene, "roof", {0.8f, 0.78f, 0.75f}, t.concrete);
  m.ground = AddMaterial(scene, "ground", {1, 1, 1}, t.ground);
  m.metal = AddMaterial(scene, "pole_metal", {0.25f, 0.27f, 0.28f}, -1);
  m.lamp = AddMaterial(scene, "lamp", {0.9f, 0.9f, 0.8f}, -1);
  m.bark = AddMaterial(scene, "bark", {1, 1, 1}, t.bark);
  m.foliage = AddMaterial(scene, "foliage", {1, 1, 1}, t.foliage);
  if (t.lawn >= 0) m.lawn = AddMaterial(scene, "lawn", {1, 1, 1}, t.lawn);
  return m;
}

HouseMaterials AddHouseMaterials(Scene& scene, const CityTextures& t) {
  HouseMaterials hm;
  hm.glass = AddMaterial(scene, "house_window", {0.08f, 0.1f, 0.13f}, -1);
  hm.frame = AddMaterial(scene, "house_frame", {0.85f, 0.85f, 0.83f}, -1);
  hm.door = AddMaterial(scene, "house_door", {0.25f, 0.15f, 0.1f}, -1);
  hm.plinth = AddMaterial(scene, "house_plinth", {0.55f, 0.55f, 0.55f}, t.concrete);
  return hm;
}

// Ground beyond the city.
void AddGround(Scene& scene, const StreetGrid& g, int m_ground) {
  MeshBuilder b("ground");
  const Eigen::Vector2d lo(g.MinX() - 1500, g.MinY() - 1500), hi(g.MaxX() + 1500, g.MaxY() + 1500);
  b.Floor(lo, hi, -0.02, kGroundTileMetres, m_ground);
  AddStatic(scene, "ground", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Roads: segments between intersections (u along the street, v across from the left curb) and
// intersection squares.
void AddRoads(Scene& scene, const StreetGrid& g, const CityMaterials& m, SceneRng& rng) {
  const double W = g.road_width_m, hw = 0.5 * W;
  MeshBuilder b("roads");
  const int nx = static_cast<int>(g.xs.size()), ny = static_cast<int>(g.ys.size());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {  // along +x at y = ys[j]
      const double x0 = g.xs[i] + hw, x1 = g.xs[i + 1] - hw, y = g.ys[j];
      const float u0 = static_cast<float>(rng.Uniform(0, 1)), u1 = u0 + static_cast<float>((x1 - x0) / W);
      b.Quad(MeshBuilder::P(x0, y - hw, 0), MeshBuilder::P(x1, y - hw, 0), MeshBuilder::P(x1, y + hw, 0),
             MeshBuilder::P(x0, y + hw, 0), {u0, 1}, {u1, 1}, {u1, 0}, {u0, 0}, m.road[rng.UniformInt(0, 1)]);
    }
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j + 1 < ny; ++j) {  // along +y at x = xs[i]; left curb is at -x
      const double y0 = g.ys[j] + hw, y1 = g.ys[j + 1] - hw, x = g.xs[i];
      const float u0 = static_cast<float>(rng.Uniform(0, 1)), u1 = u0 + static_cast<float>((y1 - y0) / W);
      b.Quad(MeshBuilder::P(x + hw, y0, 0), MeshBuilder::P(x + hw, y1, 0), MeshBuilder::P(x - hw, y1, 0),
             MeshBuilder::P(x - hw, y0, 0), {u0, 1}, {u1, 1}, {u1, 0}, {u0, 0}, m.road[rng.UniformInt(0, 1)]);
    }
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const double x = g.xs[i], y = g.ys[j];
      b.Quad(MeshBuilder::P(x - hw, y - hw, 0), MeshBuilder::P(x + hw, y - hw, 0), MeshBuilder::P(x + hw, y + hw, 0),
             MeshBuilder::P(x - hw, y + hw, 0), {0, 1}, {1, 1}, {1, 0}, {0, 0}, m.intersection);
    }
  AddStatic(scene, "roads", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Sidewalk slabs with curbs, one per block.
void AddSidewalks(Scene& scene, const std::vector<Box2>& blocks, const CityMaterials& m) {
  MeshBuilder b("sidewalks");
  for (const Box2& blk : blocks) {
    b.Floor(blk.min, blk.max, kCurbHeight, kSidewalkTileMetres, m.sidewalk);
    const Eigen::Vector2d c[4] = {blk.min, {blk.max.x(), blk.min.y()}, blk.max, {blk.min.x(), blk.max.y()}};
    // Corners counter-clockwise seen from above: walking them in order keeps the block on the
    // left, so each curb face's outward normal is on the right of a->b (as Wall expects).
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d a = c[k], bb = c[(k + 1) % 4];
      b.Wall(a, bb, 0.0, kCurbHeight, 0.0, kRoofTileMetres, 0.0, kRoofTileMetres, m.curb);
    }
  }
  AddStatic(scene, "sidewalks", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Buildings (AddBuilding): storefronts, facades, relief, balconies, awnings, rooflines.
void AddBuildings(Scene& scene, const CityLayout& L, const CityTextures& t, const CityMaterials& m,
                  uint64_t layout_seed, uint64_t texture_seed) {
  ArchitectureMaterials am;
  am.roof = m.roof;
  am.metal = AddMaterial(scene, "rooftop_metal", {0.62f, 0.64f, 0.66f}, t.concrete);
  const Vec3f trims[] = {{0.95f, 0.93f, 0.88f}, {0.7f, 0.7f, 0.72f}, {0.85f, 0.78f, 0.65f}, {0.45f, 0.43f, 0.42f}};
  for (size_t i = 0; i < 4; ++i)
    am.trim.push_back(AddMaterial(scene, "trim_" + std::to_string(i), trims[i], t.concrete));
  am.roof_tiles.push_back(AddMaterial(scene, "roof_tiles_0", {0.62f, 0.3f, 0.2f}, t.concrete));
  am.roof_tiles.push_back(AddMaterial(scene, "roof_tiles_1", {0.3f, 0.32f, 0.36f}, t.concrete));
  const Vec3f rails[] = {{0.12f, 0.12f, 0.13f}, {0.85f, 0.85f, 0.83f}, {0.3f, 0.42f, 0.42f}};
  for (size_t i = 0; i < 3; ++i) am.railing.push_back(AddMaterial(scene, "railing_" + std::to_string(i), rails[i], -1));
  for (int i = 0; i < t.num_awnings; ++i)
    am.awning.push_back(AddMaterial(scene, "awning_" + std::to_string(i), {1, 1, 1}, t.awning + i));
  SceneRng arch(SubSeed(layout_seed, "architecture"));
  MeshBuilder b("buildings");
  HouseMaterials hm;
  if (L.style.houses) hm = AddHouseMaterials(scene, t);
  for (size_t k = 0; k < L.buildings.size(); ++k) {
    const BuildingPlan& p = L.buildings[k];
    const std::string name = "building_" + std::to_string(k);
    if (p.house) {
      AddHouse(b, p, AddMaterial(scene, name + "_wall", p.tint, p.facade), hm, am, arch);
      continue;
    }
    const int m_facade = AddMaterial(scene, name + "_facade", p.tint, p.facade);
    const int m_shop = AddMaterial(scene, name + "_shop", p.tint, t.num_facades + p.storefront);
    AddBuilding(b, p, GetFacadeLayout(texture_seed, p.facade), m_facade, m_shop, am, L.style, arch);
  }
  AddStatic(scene, "buildings", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Street light mesh: arm along +x (towards the road).
int AddStreetLightMesh(Scene& scene, const CityMaterials& m) {
  MeshBuilder b("street_light");
  b.Prism({0, 0, 0}, 0.09f, 0.0f, 6.5f, 8, m.metal, m.metal);
  const int arm[5] = {m.metal, m.metal, m.metal, m.metal, m.metal};
  b.Box({0, -0.05f, 6.3f}, {1.6f, 0.05f, 6.42f}, arm);
  const int lamp[5] = {m.metal, m.metal, m.metal, m.metal, m.metal};
  b.Box({1.3f, -0.18f, 6.15f}, {1.9f, 0.18f, 6.3f}, lamp);
  b.Floor({1.35, -0.15}, {1.85, 0.15}, 6.149, 1.0, m.lamp);
  return AddMesh(scene, b.Finish());
}

// Tree variant v: a trunk and a crown (octahedron subdivided twice, vertices jittered; spherical UVs).
int AddTreeMesh(Scene& scene, const CityMaterials& m, uint64_t layout_seed, int v) {
  MeshBuilder b("tree_" + std::to_string(v));
  const float crown = 1.7f + 0.4f * v, centre = 4.3f + 0.3f * v;
  b.Prism({0, 0, 0}, 0.14f + 0.03f * v, 0.0f, centre, 6, m.bark, m.bark);
  std::vector<Vec3f> tris = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1},  {0, 1, 0},  {-1, 0, 0}, {0, 0, 1},
                             {-1, 0, 0}, {0, -1, 0}, {0, 0, 1},  {0, -1, 0}, {1, 0, 0},  {0, 0, 1},
                             {0, 1, 0},  {1, 0, 0},  {0, 0, -1}, {-1, 0, 0}, {0, 1, 0},  {0, 0, -1},
                             {0, -1, 0}, {-1, 0, 0}, {0, 0, -1}, {1, 0, 0},  {0, -1, 0}, {0, 0, -1}};
  for (int level = 0; level < 2; ++level) {
    std::vector<Vec3f> next;
    for (size_t t = 0; t < tris.size(); t += 3) {
      const Vec3f a = tris[t], bb = tris[t + 1], c = tris[t + 2];
      const Vec3f ab = (a + bb).normalized(), bc = (bb + c).normalized(), ca = (c + a).normalized();
      next.insert(next.end(), {a, ab, ca, ab, bb, bc, ca, bc, c, ab, bc, ca});
    }
    tris = next;
  }
  auto jitter = [&](const Vec3f& d) {
    // Deterministic per direction: hash the quantized direction so shared vertices move together.
    const int64_t key =
        std::lround(d.x() * 1000) * 1000003 + std::lround(d.y() * 1000) * 1009 + std::lround(d.z() * 1000);
    SceneRng r(SubSeed(layout_seed ^ static_cast<uint64_t>(key), "crown", static_cast<uint64_t>(v)));
    const float scale = crown * static_cast<float>(r.Uniform(0.8, 1.15));
    return Vec3f(d.x() * scale, d.y() * scale, d.z() * scale * 0.85f + centre + 0.6f);
  };
  auto uv = [](const Vec3f& d) {
    return Vec2f(static_cast<float>(2.0 * (std::atan2(d.y(), d.x()) / (2 * M_PI) + 0.5)),
                 static_cast<float>(2.0 * std::acos(std::clamp(d.z(), -1.0f, 1.0f)) / M_PI));
  };
  for (size_t t = 0; t < tris.size(); t += 3) {
    b.Tri(jitter(tris[t]), jitter(tris[t + 1]), jitter(tris[t + 2]), uv(tris[t]), uv(tris[t + 1]), uv(tris[t + 2]),
          m.foliage);
  }
  return AddMesh(scene, b.Finish());
}

// Road sign kind k: pole and a 0.6 m plate whose face (sign texture) looks along the mesh's +x.
int AddSignMesh(Scene& scene, const CityMaterials& m, const CityTextures& t, int k) {
  MeshBuilder b("sign_" + std::to_string(k));
  const int m_face = AddMaterial(scene, "sign_" + std::to_string(k), {1, 1, 1}, t.sign + k);
  b.Prism({-0.05f, 0, 0}, 0.04f, 0.0f, 2.9f, 6, m.metal, m.metal);
  const int plate[5] = {m.metal, m_face, m.metal, m.metal, m.metal};
  b.Box({0.0f, -0.3f, 2.3f}, {0.025f, 0.3f, 2.9f}, plate);
  return AddMesh(scene, b.Finish());
}

// One sign at about half of the block corners, 0.7 m from both curbs, facing traffic on one of
// the two streets.
void PlaceSigns(Scene& scene, const CityLayout& L, const int (&mesh_sign)[kSignKinds], SceneRng& rng) {
  const StreetGrid& g = L.grid;
  int signs = 0;
  for (const Box2& blk : L.blocks) {
    const bool inner_x = blk.min.x() > g.MinX() && blk.max.x() < g.MaxX();
    const bool inner_y = blk.min.y() > g.MinY() && blk.max.y() < g.MaxY();
    if (!inner_x && !inner_y) continue;  // outer corner blocks face no intersection
    for (int corner = 0; corner < 4; ++corner) {
      if (!rng.Bernoulli(0.5)) continue;
      const double sx = corner & 1 ? 1.0 : -1.0, sy = corner & 2 ? 1.0 : -1.0;
      const double x = (sx > 0 ? blk.max.x() : blk.min.x()) - 0.7 * sx,
                   y = (sy > 0 ? blk.max.y() : blk.min.y()) - 0.7 * sy;
      // Face traffic approaching along x (yaw 0 or pi) or along y (yaw +-pi/2) on this corner's side.
      const double yaw = rng.Bernoulli(0.5) ? (sx > 0 ? 0.0 : M_PI) : (sy > 0 ? M_PI / 2 : -M_PI / 2);
      AddStatic(scene, "sign_" + std::to_string(signs++), mesh_sign[rng.UniformInt(0, kSignKinds - 1)],
                PlaceYaw(x, y, yaw, kCurbHeight));
    }
  }
}

// Along every street segment side: lights every ~28 m, trees between them, parked cars in the lane.
void FurnishStreets(Scene& scene, const CityLayout& L, int mesh_light, const int (&mesh_tree)[3], CarFactory& cars,
                    SceneRng& rng) {
  const CityStyle& st = L.style;
  const StreetGrid& g = L.grid;
  const double hw = 0.5 * g.road_width_m;
  int lights = 0, trees = 0;
  const int nx = static_cast<int>(g.xs.size()), ny = static_cast<int>(g.ys.size());
  auto furnish = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& dir, double length,
                     const Eigen::Vector2d& to_road) {
    // a: start of the curb line; dir: along the street; to_road: unit normal from sidewalk to road.
    const double yaw_to_road = std::atan2(to_road.y(), to_road.x());
    const double half_spacing = 0.5 * st.light_spacing_m;
    for (double s = 6.0; s < length - 6.0; s += st.light_spacing_m) {
      const Eigen::Vector2d p = a + s * dir - 0.45 * to_road;
      AddStatic(scene, "light_" + std::to_string(lights++), mesh_light,
                PlaceYaw(p.x(), p.y(), yaw_to_road, kCurbHeight));
      if (st.trees && s + half_spacing < length - 6.0 && rng.Bernoulli(st.tree_probability)) {
        const Eigen::Vector2d q = a + (s + half_spacing) * dir - 1.0 * to_road;
        AddStatic(scene, "tree_" + std::to_string(trees++), mesh_tree[rng.UniformInt(0, 2)],
                  PlaceYaw(q.x(), q.y(), rng.Uniform(0, 2 * M_PI), kCurbHeight));
      }
    }
    if (st.parked_cars && st.parking_lane_m > 0) {
      for (double s = 9.0; s < length - 9.0; s += 6.5) {
        if (!rng.Bernoulli(0.45)) continue;
        const Eigen::Vector2d p = a + s * dir + (0.5 * st.parking_lane_m + 0.15) * to_road;
        const int mesh = cars.Get(rng.UniformInt(0, kNumCarShapes - 1), rng.UniformInt(0, kNumCarColors - 1));
        AddStatic(scene, "parked_car", mesh,
                  PlaceYaw(p.x(), p.y(), std::atan2(dir.y(), dir.x()) + rng.Normal(0, 0.02)));
      }
    }
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const double x0 = g.xs[i] + hw, len = g.xs[i + 1] - hw - x0;
      furnish({x0, g.ys[j] - hw}, {1, 0}, len, {0, 1});
      furnish({x0 + len, g.ys[j] + hw}, {-1, 0}, len, {0, -1});
    }
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j + 1 < ny; ++j) {
      const double y0 = g.ys[j] + hw, len = g.ys[j + 1] - hw - y0;
      furnish({g.xs[i] + hw, y0}, {0, 1}, len, {-1, 0});
      furnish({g.xs[i] - hw, y0 + len}, {0, -1}, len, {1, 0});
    }
}

// Moving vehicles (ids 1..N for the masks); with `lights_on`, glowing lamps and two headlight
// spots riding on each.
void AddTraffic(Scene& scene, const CityLayout& L, uint64_t traffic_seed, double frame_rate, CarFactory& cars,
                bool lights_on) {
  const int frames = static_cast<int>(L.trajectory.size());
  const std::vector<VehicleTrack> tracks = PlanTraffic(L, traffic_seed, frames, frame_rate);
  uint16_t id = 1;
  for (const VehicleTrack& v : tracks) {
    Object o;
    o.name = "vehicle_" + std::to_string(id) + "_" + v.kind;
    o.mesh = cars.Get(v.shape, v.color, lights_on);
    o.id = id++;
    o.world_from_object_per_frame = v.world_from_object;
    scene.objects.push_back(std::move(o));
    if (!lights_on) continue;
    const int object = static_cast<int>(scene.objects.size()) - 1;
    for (const Light& l : CarFactory::Headlights(v.shape, object, scene.objects.back().name)) scene.lights.push_back(l);
  }
}

// Street lamps at night: the lamp head's underside glows and a light just below it shines down.
void LightStreetLamps(Scene& scene, int mesh_light, int m_lamp) {
  scene.materials[m_lamp].emission = {5.0f, 4.4f, 3.4f};  // warm white
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    if (scene.objects[o].mesh != mesh_light) continue;
    Light l;
    l.name = scene.objects[o].name + "_lamp";
    l.position = Eigen::Vector3d(1.6, 0.0, 6.1);           // in the street light's frame (AddStreetLightMesh)
    l.intensity = Eigen::Vector3f(0.035f, 0.03f, 0.024f);  // about 25 lux below on the day scale
    l.range = 30.0;
    l.object = static_cast<int>(o);
    // A full cut-off luminaire: light goes down (A = cos of the angle off the axis, none above
    // 75 degrees), so the road is lit in pools and the facades stay dark.
    l.spot = true;
    l.spot_direction = Eigen::Vector3d(0.0, 0.0, -1.0);
    l.spot_angle_deg = 150.0;
    l.spot_blend = 0.3;
    scene.lights.push_back(l);
  }
}

// Suburban lots: a lawn over each block inside its sidewalk ring, 1 cm above the sidewalk.
void AddLawns(Scene& scene, const CityLayout& L, int m_lawn) {
  MeshBuilder b("lawns");
  for (const Box2& blk : L.blocks) {
    const Eigen::Vector2d lo = blk.min.array() + L.style.sidewalk_width_m;
    const Eigen::Vector2d hi = blk.max.array() - L.style.sidewalk_width_m;
    if ((hi - lo).minCoeff() > 0.0) b.Floor(lo, hi, kCurbHeight + 0.01, kLawnTileMetres, m_lawn);
  }
  AddStatic(scene, "lawns", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

}  // namespace

Scene ProceduralSceneHeader(const ScenePreset& preset, uint64_t seed, bool quick, Trajectory rig_trajectory) {
  Scene scene;
  scene.metadata.generator = "rovo";
  scene.metadata.generator_version = ROVO_VERSION;
  scene.metadata.preset = preset.name;
  scene.metadata.source = quick ? "procedural (quick form)" : "procedural";
  scene.metadata.seed = seed;
  scene.frame_rate = preset.frame_rate;
  scene.rig_preset = preset.rig_preset;
  scene.rig_trajectory = std::move(rig_trajectory);
  return scene;
}

Scene GenerateScene(const std::string& preset_name, uint64_t seed, bool quick) {
  const ScenePreset& preset = FindScenePreset(preset_name);
  if (preset.world == "indoor") return GenerateIndoorScene(preset, seed, quick);
  const CityLayout L = MakeCityLayout(preset, seed, quick);
  const CityStyle& st = L.style;
  const uint64_t layout_seed = LayoutSeed(preset.name, seed);
  const uint64_t texture_seed = SubSeed(layout_seed, "textures");
  SceneRng rng(SubSeed(layout_seed, "props"));

  Scene scene = ProceduralSceneHeader(preset, seed, quick, L.trajectory);
  scene.lighting = MakeLighting(preset.lighting, SubSeed(seed, preset.lighting.c_str()), st.high_sun_along_streets);

  const CityTextures textures = GenerateTextures(scene, st, texture_seed, quick);
  const CityMaterials materials = AddSharedMaterials(scene, textures);
  AddGround(scene, L.grid, materials.ground);
  AddRoads(scene, L.grid, materials, rng);
  AddSidewalks(scene, L.blocks, materials);
  AddBuildings(scene, L, textures, materials, layout_seed, texture_seed);

  // Street furniture: shared meshes placed along the curbs.
  const int mesh_light = AddStreetLightMesh(scene, materials);
  int mesh_tree[3];
  for (int v = 0; v < 3; ++v) mesh_tree[v] = AddTreeMesh(scene, materials, layout_seed, v);
  int mesh_sign[kSignKinds];
  for (int k = 0; k < kSignKinds; ++k) mesh_sign[k] = AddSignMesh(scene, materials, textures, k);
  PlaceSigns(scene, L, mesh_sign, rng);
  CarFactory cars(scene, textures.car);
  FurnishStreets(scene, L, mesh_light, mesh_tree, cars, rng);

  const bool night = preset.lighting == "night";
  if (preset.traffic) AddTraffic(scene, L, layout_seed ^ seed, preset.frame_rate, cars, night);
  if (night) LightStreetLamps(scene, mesh_light, materials.lamp);
  if (st.houses) AddLawns(scene, L, materials.lawn);
  return scene;
}

}  // namespace rovo
