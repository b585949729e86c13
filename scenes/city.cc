// Procedural urban scenes: presets, geometry, materials, lighting and traffic (plan in city_layout).

#include "scenes/city.h"

#include "rovo/version.h"
#include "scenes/city_layout.h"
#include "scenes/rng.h"
#include "scenes/texture_gen.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

namespace rovo {

const std::vector<ScenePreset>& ScenePresets() {
  static const std::vector<ScenePreset> presets = [] {
    std::vector<ScenePreset> p(5);
    p[0] = {"static_urban", "Static Urban: ~2 km city drive, no moving objects, sunny", 2000, 3000, "sunny", false, "rovo4", 60, 0.5};
    p[1] = {"dynamic_urban", "Dynamic Urban: ~1.3 km fast drive on long blocks, heavy traffic", 1320, 1000, "sunny", true, "rovo4", 60, 0.5};
    p[2] = {"cloudy_urban", "Cloudy Urban: ~350 m in a small town, overcast", 350, 300, "cloudy", false, "rovo4", 60, 0.5};
    p[3] = {"sunset_urban", "Sunset Urban: the cloudy_urban streets at sunset (low warm sun)", 350, 300, "sunset", false, "rovo4", 60, 0.5};
    p[4] = {"canyon_multifov", "4view-MultiFOV-like: ~440 m slow drive in a narrow urban canyon", 440, 2200, "sunny", false, "omnimvs4", 80, 0.5};
    return p;
  }();
  return presets;
}

const ScenePreset& FindScenePreset(const std::string& name) {
  std::string names;
  for (const ScenePreset& p : ScenePresets()) {
    if (p.name == name) return p;
    names += (names.empty() ? "" : ", ") + p.name;
  }
  throw std::invalid_argument("unknown scene preset '" + name + "' (valid: " + names + ")");
}

namespace {

using Vec3f = Eigen::Vector3f;
using Vec2f = Eigen::Vector2f;

// Appends geometry to one mesh with per-triangle materials. Faces are counter-clockwise seen from
// the side their normal points to.
class MeshBuilder {
 public:
  explicit MeshBuilder(std::string name) { mesh_.name = std::move(name); }
  void Tri(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec2f& ua, const Vec2f& ub, const Vec2f& uc, int material) {
    const int base = static_cast<int>(mesh_.positions.size());
    mesh_.positions.insert(mesh_.positions.end(), {a, b, c});
    mesh_.uvs.insert(mesh_.uvs.end(), {ua, ub, uc});
    mesh_.triangles.emplace_back(base, base + 1, base + 2);
    mesh_.triangle_materials.push_back(material);
  }
  // Quad a-b-c-d (counter-clockwise), two triangles sharing 4 vertices.
  void Quad(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& d, const Vec2f& ua, const Vec2f& ub,
            const Vec2f& uc, const Vec2f& ud, int material) {
    const int base = static_cast<int>(mesh_.positions.size());
    mesh_.positions.insert(mesh_.positions.end(), {a, b, c, d});
    mesh_.uvs.insert(mesh_.uvs.end(), {ua, ub, uc, ud});
    mesh_.triangles.emplace_back(base, base + 1, base + 2);
    mesh_.triangles.emplace_back(base, base + 2, base + 3);
    mesh_.triangle_materials.insert(mesh_.triangle_materials.end(), {material, material});
  }
  // Horizontal quad over [min, max] at height z facing up, UV = xy / tile (+ offset).
  void Floor(const Eigen::Vector2d& min, const Eigen::Vector2d& max, double z, double tile, int material,
             const Vec2f& offset = Vec2f::Zero()) {
    auto uv = [&](double x, double y) -> Vec2f { return Vec2f(static_cast<float>(x / tile), static_cast<float>(-y / tile)) + offset; };
    const float zf = static_cast<float>(z);
    Quad(P(min.x(), min.y(), zf), P(max.x(), min.y(), zf), P(max.x(), max.y(), zf), P(min.x(), max.y(), zf),
         uv(min.x(), min.y()), uv(max.x(), min.y()), uv(max.x(), max.y()), uv(min.x(), max.y()), material);
  }
  // Vertical wall from a to b (xy), z in [z0, z1], outward normal to the right of a->b.
  // u = (u0 + distance) / tile_u; v = v_at_z0 - (z - z0) / tile_v.
  void Wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1, double u0, double tile_u,
            double v_at_z0, double tile_v, int material) {
    const double len = (b - a).norm();
    const float ua = static_cast<float>(u0 / tile_u), ub = static_cast<float>((u0 + len) / tile_u);
    const float v0 = static_cast<float>(v_at_z0), v1 = static_cast<float>(v_at_z0 - (z1 - z0) / tile_v);
    Quad(P(a.x(), a.y(), z0), P(b.x(), b.y(), z0), P(b.x(), b.y(), z1), P(a.x(), a.y(), z1), {ua, v0}, {ub, v0}, {ub, v1},
         {ua, v1}, material);
  }
  // Axis-aligned box; per-face materials in order -x, +x, -y, +y, top (bottom omitted). UVs map each
  // face's full extent to [0, 1] unless tile > 0 (metres per texture tile).
  void Box(const Vec3f& lo, const Vec3f& hi, const int materials[5], float tile = 0) {
    auto uv = [&](float a, float b, float ext_a, float ext_b) {
      return tile > 0 ? Vec2f(a / tile, -b / tile) : Vec2f(a / ext_a, 1.0f - b / ext_b);
    };
    const Vec3f e = hi - lo;
    // -x face: seen from -x, u along -y.
    Quad(P(lo.x(), hi.y(), lo.z()), P(lo.x(), lo.y(), lo.z()), P(lo.x(), lo.y(), hi.z()), P(lo.x(), hi.y(), hi.z()),
         uv(0, 0, e.y(), e.z()), uv(e.y(), 0, e.y(), e.z()), uv(e.y(), e.z(), e.y(), e.z()), uv(0, e.z(), e.y(), e.z()), materials[0]);
    Quad(P(hi.x(), lo.y(), lo.z()), P(hi.x(), hi.y(), lo.z()), P(hi.x(), hi.y(), hi.z()), P(hi.x(), lo.y(), hi.z()),
         uv(0, 0, e.y(), e.z()), uv(e.y(), 0, e.y(), e.z()), uv(e.y(), e.z(), e.y(), e.z()), uv(0, e.z(), e.y(), e.z()), materials[1]);
    Quad(P(lo.x(), lo.y(), lo.z()), P(hi.x(), lo.y(), lo.z()), P(hi.x(), lo.y(), hi.z()), P(lo.x(), lo.y(), hi.z()),
         uv(0, 0, e.x(), e.z()), uv(e.x(), 0, e.x(), e.z()), uv(e.x(), e.z(), e.x(), e.z()), uv(0, e.z(), e.x(), e.z()), materials[2]);
    Quad(P(hi.x(), hi.y(), lo.z()), P(lo.x(), hi.y(), lo.z()), P(lo.x(), hi.y(), hi.z()), P(hi.x(), hi.y(), hi.z()),
         uv(0, 0, e.x(), e.z()), uv(e.x(), 0, e.x(), e.z()), uv(e.x(), e.z(), e.x(), e.z()), uv(0, e.z(), e.x(), e.z()), materials[3]);
    Quad(P(lo.x(), lo.y(), hi.z()), P(hi.x(), lo.y(), hi.z()), P(hi.x(), hi.y(), hi.z()), P(lo.x(), hi.y(), hi.z()),
         uv(0, 0, e.x(), e.y()), uv(e.x(), 0, e.x(), e.y()), uv(e.x(), e.y(), e.x(), e.y()), uv(0, e.y(), e.x(), e.y()), materials[4]);
  }
  // Vertical prism with a regular n-gon cross-section around `axis_centre`; axis along z (or along
  // y when `along_y`, for wheels). Sides tile the texture once around.
  void Prism(const Vec3f& centre, float radius, float z0, float z1, int n, int side_material, int cap_material,
             bool along_y = false) {
    auto at = [&](float ang, float h) {
      const float c = radius * std::cos(ang), s = radius * std::sin(ang);
      return along_y ? Vec3f(centre.x() + c, centre.y() + h, centre.z() + s) : Vec3f(centre.x() + c, centre.y() + s, centre.z() + h);
    };
    for (int k = 0; k < n; ++k) {
      const float a0 = static_cast<float>(2 * M_PI * k / n), a1 = static_cast<float>(2 * M_PI * (k + 1) / n);
      const float u0 = static_cast<float>(k) / n, u1 = static_cast<float>(k + 1) / n;
      if (along_y) {
        Quad(at(a0, z1), at(a1, z1), at(a1, z0), at(a0, z0), {u0, 0}, {u1, 0}, {u1, 1}, {u0, 1}, side_material);
      } else {
        Quad(at(a0, z0), at(a1, z0), at(a1, z1), at(a0, z1), {u0, 1}, {u1, 1}, {u1, 0}, {u0, 0}, side_material);
      }
    }
    for (int k = 1; k + 1 < n; ++k) {  // caps
      const float a0 = 0, a1 = static_cast<float>(2 * M_PI * k / n), a2 = static_cast<float>(2 * M_PI * (k + 1) / n);
      const Vec2f z(0.5f, 0.5f);
      if (along_y) {
        Tri(at(a0, z0), at(a1, z0), at(a2, z0), z, z, z, cap_material);
        Tri(at(a0, z1), at(a2, z1), at(a1, z1), z, z, z, cap_material);
      } else {
        Tri(at(a0, z1), at(a1, z1), at(a2, z1), z, z, z, cap_material);
      }
    }
  }
  Mesh Finish() {
    mesh_.material = mesh_.triangle_materials.empty() ? 0 : mesh_.triangle_materials.front();
    if (std::all_of(mesh_.triangle_materials.begin(), mesh_.triangle_materials.end(),
                    [&](int m) { return m == mesh_.material; })) {
      mesh_.triangle_materials.clear();
    }
    return std::move(mesh_);
  }
  size_t NumTriangles() const { return mesh_.triangles.size(); }

  static Vec3f P(double x, double y, double z) { return Vec3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)); }

 private:
  Mesh mesh_;
};

int AddMaterial(Scene& scene, const std::string& name, const Vec3f& color, int texture) {
  Material m;
  m.name = name;
  m.base_color = color;
  m.texture = texture;
  scene.materials.push_back(m);
  return static_cast<int>(scene.materials.size()) - 1;
}

int AddMesh(Scene& scene, Mesh mesh) {
  scene.meshes.push_back(std::move(mesh));
  return static_cast<int>(scene.meshes.size()) - 1;
}

void AddStatic(Scene& scene, const std::string& name, int mesh, const Rigid3& world_from_object) {
  Object o;
  o.name = name;
  o.mesh = mesh;
  o.world_from_object = world_from_object;
  scene.objects.push_back(o);
}

Rigid3 PlaceYaw(double x, double y, double yaw_rad, double z = 0.0) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())), Eigen::Vector3d(x, y, z));
}

Lighting MakeLighting(const std::string& preset, uint64_t seed) {
  SceneRng rng(SubSeed(seed, "lighting"));
  Lighting l;
  l.preset = preset;
  double elevation_deg = 60, azimuth_deg = rng.Uniform(0, 360);
  if (preset == "sunny") {
    elevation_deg = rng.Uniform(50, 65);
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
  } else {
    throw std::invalid_argument("unknown lighting preset '" + preset + "' (valid: sunny, cloudy, sunset)");
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
  // Mesh of a car: origin on the ground under the centre, x forward, z up.
  int Get(int shape, int color) {
    const int key = shape * kNumCarColors + color;
    auto it = meshes_.find(key);
    if (it != meshes_.end()) return it->second;
    const CarShape& s = kCarShapes[shape];
    const std::string name = std::string("car_") + s.name + "_" + std::to_string(color);
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
    const int mesh = AddMesh(scene_, b.Finish());
    meshes_[key] = mesh;
    return mesh;
  }

 private:
  Scene& scene_;
  CarTextures tex_;
  int glass_, tyre_;
  std::map<int, int> meshes_;
};

// Oriented rectangle (car footprint) overlap by separating axes.
struct Footprint {
  Eigen::Vector2d centre;
  double yaw, half_length, half_width;
};
bool Overlap(const Footprint& a, const Footprint& b) {
  if ((a.centre - b.centre).norm() > a.half_length + a.half_width + b.half_length + b.half_width) return false;
  const Eigen::Vector2d axes[4] = {{std::cos(a.yaw), std::sin(a.yaw)}, {-std::sin(a.yaw), std::cos(a.yaw)},
                                   {std::cos(b.yaw), std::sin(b.yaw)}, {-std::sin(b.yaw), std::cos(b.yaw)}};
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

}  // namespace

Scene GenerateScene(const std::string& preset_name, uint64_t seed, bool quick) {
  const ScenePreset& preset = FindScenePreset(preset_name);
  const CityLayout L = MakeCityLayout(preset, seed, quick);
  const CityStyle& st = L.style;
  const uint64_t layout_seed = LayoutSeed(preset.name, seed);
  const uint64_t texture_seed = SubSeed(layout_seed, "textures");
  SceneRng rng(SubSeed(layout_seed, "props"));

  Scene scene;
  scene.metadata.generator = "rovo";
  scene.metadata.generator_version = ROVO_VERSION;
  scene.metadata.preset = preset.name;
  scene.metadata.source = quick ? "procedural (quick form)" : "procedural";
  scene.metadata.seed = seed;
  scene.frame_rate = preset.frame_rate;
  scene.rig_preset = preset.rig_preset;
  scene.rig_trajectory = L.trajectory;
  scene.lighting = MakeLighting(preset.lighting, SubSeed(seed, preset.lighting.c_str()));

  // Textures, generated in parallel (each from its own seed, so the result does not depend on threads).
  const int num_facades = quick ? std::max(4, st.facade_textures / 3) : st.facade_textures;
  const int num_storefronts = quick ? std::max(3, st.storefront_textures / 2) : st.storefront_textures;
  std::vector<std::function<Texture()>> jobs;
  for (int i = 0; i < num_facades; ++i) jobs.push_back([=] { return MakeFacadeTexture(texture_seed, i); });
  for (int i = 0; i < num_storefronts; ++i) jobs.push_back([=] { return MakeStorefrontTexture(texture_seed, i); });
  const int t_road = static_cast<int>(jobs.size());
  for (int i = 0; i < 2; ++i) jobs.push_back([=] { return MakeRoadTexture(texture_seed, i, st.road_width_m, st.parking_lane_m); });
  const int t_intersection = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeIntersectionTexture(texture_seed, st.road_width_m); });
  const int t_sidewalk = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeSidewalkTexture(texture_seed); });
  const int t_concrete = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeConcreteTexture(texture_seed); });
  const int t_ground = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeGroundTexture(texture_seed); });
  CarTextures car_tex;
  car_tex.side = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeCarSideTexture(texture_seed); });
  car_tex.end = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeCarEndTexture(texture_seed); });
  car_tex.glass = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeCarGlassTexture(texture_seed); });
  const int t_bark = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeBarkTexture(texture_seed); });
  const int t_foliage = static_cast<int>(jobs.size());
  jobs.push_back([=] { return MakeFoliageTexture(texture_seed); });
  const int t_sign = static_cast<int>(jobs.size());
  for (int k = 0; k < kSignKinds; ++k) jobs.push_back([=] { return MakeSignTexture(texture_seed, k); });
  scene.textures.resize(jobs.size());
  tbb::parallel_for(size_t{0}, jobs.size(), [&](size_t i) { scene.textures[i] = jobs[i](); });

  // Shared materials.
  const int m_road[2] = {AddMaterial(scene, "road_0", {1, 1, 1}, t_road), AddMaterial(scene, "road_1", {1, 1, 1}, t_road + 1)};
  const int m_intersection = AddMaterial(scene, "intersection", {1, 1, 1}, t_intersection);
  const int m_sidewalk = AddMaterial(scene, "sidewalk", {1, 1, 1}, t_sidewalk);
  const int m_curb = AddMaterial(scene, "curb", {0.95f, 0.95f, 0.95f}, t_concrete);
  const int m_roof = AddMaterial(scene, "roof", {0.8f, 0.78f, 0.75f}, t_concrete);
  const int m_ground = AddMaterial(scene, "ground", {1, 1, 1}, t_ground);
  const int m_metal = AddMaterial(scene, "pole_metal", {0.25f, 0.27f, 0.28f}, -1);
  const int m_lamp = AddMaterial(scene, "lamp", {0.9f, 0.9f, 0.8f}, -1);
  const int m_bark = AddMaterial(scene, "bark", {1, 1, 1}, t_bark);
  const int m_foliage = AddMaterial(scene, "foliage", {1, 1, 1}, t_foliage);

  const StreetGrid& g = L.grid;
  const double W = g.road_width_m, hw = 0.5 * W;

  // Ground beyond the city.
  {
    MeshBuilder b("ground");
    const Eigen::Vector2d lo(g.MinX() - 1500, g.MinY() - 1500), hi(g.MaxX() + 1500, g.MaxY() + 1500);
    b.Floor(lo, hi, -0.02, kGroundTileMetres, m_ground);
    AddStatic(scene, "ground", AddMesh(scene, b.Finish()), Rigid3::Identity());
  }
  // Roads: segments between intersections (u along the street, v across from the left curb) and
  // intersection squares.
  {
    MeshBuilder b("roads");
    const int nx = static_cast<int>(g.xs.size()), ny = static_cast<int>(g.ys.size());
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {  // along +x at y = ys[j]
        const double x0 = g.xs[i] + hw, x1 = g.xs[i + 1] - hw, y = g.ys[j];
        const float u0 = static_cast<float>(rng.Uniform(0, 1)), u1 = u0 + static_cast<float>((x1 - x0) / W);
        b.Quad(MeshBuilder::P(x0, y - hw, 0), MeshBuilder::P(x1, y - hw, 0), MeshBuilder::P(x1, y + hw, 0),
               MeshBuilder::P(x0, y + hw, 0), {u0, 1}, {u1, 1}, {u1, 0}, {u0, 0}, m_road[rng.UniformInt(0, 1)]);
      }
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j + 1 < ny; ++j) {  // along +y at x = xs[i]; left curb is at -x
        const double y0 = g.ys[j] + hw, y1 = g.ys[j + 1] - hw, x = g.xs[i];
        const float u0 = static_cast<float>(rng.Uniform(0, 1)), u1 = u0 + static_cast<float>((y1 - y0) / W);
        b.Quad(MeshBuilder::P(x + hw, y0, 0), MeshBuilder::P(x + hw, y1, 0), MeshBuilder::P(x - hw, y1, 0),
               MeshBuilder::P(x - hw, y0, 0), {u0, 1}, {u1, 1}, {u1, 0}, {u0, 0}, m_road[rng.UniformInt(0, 1)]);
      }
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j) {
        const double x = g.xs[i], y = g.ys[j];
        b.Quad(MeshBuilder::P(x - hw, y - hw, 0), MeshBuilder::P(x + hw, y - hw, 0), MeshBuilder::P(x + hw, y + hw, 0),
               MeshBuilder::P(x - hw, y + hw, 0), {0, 1}, {1, 1}, {1, 0}, {0, 0}, m_intersection);
      }
    AddStatic(scene, "roads", AddMesh(scene, b.Finish()), Rigid3::Identity());
  }
  // Sidewalk slabs with curbs, one per block.
  {
    MeshBuilder b("sidewalks");
    for (const Box2& blk : L.blocks) {
      b.Floor(blk.min, blk.max, kCurbHeight, kSidewalkTileMetres, m_sidewalk);
      const Eigen::Vector2d c[4] = {blk.min, {blk.max.x(), blk.min.y()}, blk.max, {blk.min.x(), blk.max.y()}};
      // Counter-clockwise corners seen from above; the outward normal of edge a->b is to its right,
      // so walk them clockwise for outward-facing curb faces.
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d a = c[(k + 1) % 4], bb = c[k];
        b.Wall(a, bb, 0.0, kCurbHeight, 0.0, kRoofTileMetres, 0.0, kRoofTileMetres, m_curb);
      }
    }
    AddStatic(scene, "sidewalks", AddMesh(scene, b.Finish()), Rigid3::Identity());
  }
  // Buildings: ground floor with shops, upper floors with the facade pattern, flat roofs.
  {
    MeshBuilder b("buildings");
    for (size_t k = 0; k < L.buildings.size(); ++k) {
      const BuildingPlan& p = L.buildings[k];
      const std::string name = "building_" + std::to_string(k);
      const int m_facade = AddMaterial(scene, name + "_facade", p.tint, p.facade);
      const int m_shop = AddMaterial(scene, name + "_shop", p.tint, num_facades + p.storefront);
      auto walls = [&](const Box2& fp, double z0, double z1, bool shops) {
        const Eigen::Vector2d c[4] = {fp.min, {fp.max.x(), fp.min.y()}, fp.max, {fp.min.x(), fp.max.y()}};
        for (int e = 0; e < 4; ++e) {
          // Clockwise walk (c[e+1] -> c[e]) puts the outward normal on the right.
          const Eigen::Vector2d a = c[(e + 1) % 4], bb = c[e];
          double zs = z0;
          if (shops) {
            b.Wall(a, bb, 0.0, kStorefrontHeightMetres, p.u_offset, kFacadeTileMetres, 1.0, kStorefrontHeightMetres, m_shop);
            zs = kStorefrontHeightMetres;
          }
          // v = 100 at z = 4 m: texture floor boundaries coincide with storey boundaries.
          const double v0 = 100.0 - (zs - kStorefrontHeightMetres) / kFacadeTileMetres;
          b.Wall(a, bb, zs, z1, p.u_offset, kFacadeTileMetres, v0, kFacadeTileMetres, m_facade);
        }
        b.Floor(fp.min, fp.max, z1, kRoofTileMetres, m_roof);
      };
      walls(p.footprint, 0.0, p.height, true);
      if (p.has_setback) walls(p.upper_footprint, p.height, p.upper_height, false);
    }
    AddStatic(scene, "buildings", AddMesh(scene, b.Finish()), Rigid3::Identity());
  }

  // Street furniture: shared meshes placed along the curbs.
  int mesh_light, mesh_tree[3];
  {
    MeshBuilder b("street_light");  // arm along +x (towards the road)
    b.Prism({0, 0, 0}, 0.09f, 0.0f, 6.5f, 8, m_metal, m_metal);
    const int arm[5] = {m_metal, m_metal, m_metal, m_metal, m_metal};
    b.Box({0, -0.05f, 6.3f}, {1.6f, 0.05f, 6.42f}, arm);
    const int lamp[5] = {m_metal, m_metal, m_metal, m_metal, m_metal};
    b.Box({1.3f, -0.18f, 6.15f}, {1.9f, 0.18f, 6.3f}, lamp);
    b.Floor({1.35, -0.15}, {1.85, 0.15}, 6.149, 1.0, m_lamp);
    mesh_light = AddMesh(scene, b.Finish());
  }
  for (int v = 0; v < 3; ++v) {
    MeshBuilder b("tree_" + std::to_string(v));
    const float crown = 1.7f + 0.4f * v, centre = 4.3f + 0.3f * v;
    b.Prism({0, 0, 0}, 0.14f + 0.03f * v, 0.0f, centre, 6, m_bark, m_bark);
    // Crown: octahedron subdivided twice, vertices jittered; spherical UVs.
    std::vector<Vec3f> tris = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 0}, {-1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0},
                               {0, 0, 1}, {0, -1, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {0, 0, -1}, {-1, 0, 0},
                               {0, 1, 0}, {0, 0, -1}, {0, -1, 0}, {-1, 0, 0}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
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
      const int64_t key = std::lround(d.x() * 1000) * 1000003 + std::lround(d.y() * 1000) * 1009 + std::lround(d.z() * 1000);
      SceneRng r(SubSeed(layout_seed ^ static_cast<uint64_t>(key), "crown", static_cast<uint64_t>(v)));
      const float scale = crown * static_cast<float>(r.Uniform(0.8, 1.15));
      return Vec3f(d.x() * scale, d.y() * scale, d.z() * scale * 0.85f + centre + 0.6f);
    };
    auto uv = [](const Vec3f& d) {
      return Vec2f(static_cast<float>(2.0 * (std::atan2(d.y(), d.x()) / (2 * M_PI) + 0.5)), static_cast<float>(2.0 * std::acos(std::clamp(d.z(), -1.0f, 1.0f)) / M_PI));
    };
    for (size_t t = 0; t < tris.size(); t += 3) {
      b.Tri(jitter(tris[t]), jitter(tris[t + 1]), jitter(tris[t + 2]), uv(tris[t]), uv(tris[t + 1]), uv(tris[t + 2]), m_foliage);
    }
    mesh_tree[v] = AddMesh(scene, b.Finish());
  }
  // Road signs: pole and a 0.6 m plate whose face (sign texture) looks along the mesh's +x.
  int mesh_sign[kSignKinds];
  for (int k = 0; k < kSignKinds; ++k) {
    MeshBuilder b("sign_" + std::to_string(k));
    const int m_face = AddMaterial(scene, "sign_" + std::to_string(k), {1, 1, 1}, t_sign + k);
    b.Prism({-0.05f, 0, 0}, 0.04f, 0.0f, 2.9f, 6, m_metal, m_metal);
    const int plate[5] = {m_metal, m_face, m_metal, m_metal, m_metal};
    b.Box({0.0f, -0.3f, 2.3f}, {0.025f, 0.3f, 2.9f}, plate);
    mesh_sign[k] = AddMesh(scene, b.Finish());
  }
  // One sign at about half of the block corners, 0.7 m from both curbs, facing traffic on one of
  // the two streets.
  {
    int signs = 0;
    for (const Box2& blk : L.blocks) {
      const bool inner_x = blk.min.x() > g.MinX() && blk.max.x() < g.MaxX();
      const bool inner_y = blk.min.y() > g.MinY() && blk.max.y() < g.MaxY();
      if (!inner_x && !inner_y) continue;  // outer corner blocks face no intersection
      for (int corner = 0; corner < 4; ++corner) {
        if (!rng.Bernoulli(0.5)) continue;
        const double sx = corner & 1 ? 1.0 : -1.0, sy = corner & 2 ? 1.0 : -1.0;
        const double x = (sx > 0 ? blk.max.x() : blk.min.x()) - 0.7 * sx, y = (sy > 0 ? blk.max.y() : blk.min.y()) - 0.7 * sy;
        // Face traffic approaching along x (yaw 0 or pi) or along y (yaw +-pi/2) on this corner's side.
        const double yaw = rng.Bernoulli(0.5) ? (sx > 0 ? 0.0 : M_PI) : (sy > 0 ? M_PI / 2 : -M_PI / 2);
        AddStatic(scene, "sign_" + std::to_string(signs++), mesh_sign[rng.UniformInt(0, kSignKinds - 1)],
                  PlaceYaw(x, y, yaw, kCurbHeight));
      }
    }
  }
  CarFactory cars(scene, car_tex);
  {
    int lights = 0, trees = 0;
    // Along every street segment side: lights every ~28 m, trees between them, parked cars in the lane.
    const int nx = static_cast<int>(g.xs.size()), ny = static_cast<int>(g.ys.size());
    auto furnish = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& dir, double length, const Eigen::Vector2d& to_road) {
      // a: start of the curb line; dir: along the street; to_road: unit normal from sidewalk to road.
      const double yaw_to_road = std::atan2(to_road.y(), to_road.x());
      for (double s = 6.0; s < length - 6.0; s += 28.0) {
        const Eigen::Vector2d p = a + s * dir - 0.45 * to_road;
        AddStatic(scene, "light_" + std::to_string(lights++), mesh_light, PlaceYaw(p.x(), p.y(), yaw_to_road, kCurbHeight));
        if (st.trees && s + 14.0 < length - 6.0 && rng.Bernoulli(0.8)) {
          const Eigen::Vector2d q = a + (s + 14.0) * dir - 1.0 * to_road;
          AddStatic(scene, "tree_" + std::to_string(trees++), mesh_tree[rng.UniformInt(0, 2)],
                    PlaceYaw(q.x(), q.y(), rng.Uniform(0, 2 * M_PI), kCurbHeight));
        }
      }
      if (st.parked_cars && st.parking_lane_m > 0) {
        for (double s = 9.0; s < length - 9.0; s += 6.5) {
          if (!rng.Bernoulli(0.45)) continue;
          const Eigen::Vector2d p = a + s * dir + (0.5 * st.parking_lane_m + 0.15) * to_road;
          const int mesh = cars.Get(rng.UniformInt(0, kNumCarShapes - 1), rng.UniformInt(0, kNumCarColors - 1));
          AddStatic(scene, "parked_car", mesh, PlaceYaw(p.x(), p.y(), std::atan2(dir.y(), dir.x()) + rng.Normal(0, 0.02)));
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

  // Moving vehicles (ids 1..N for the masks).
  if (preset.traffic) {
    const int frames = static_cast<int>(L.trajectory.size());
    const std::vector<VehicleTrack> tracks = PlanTraffic(L, layout_seed ^ seed, frames, preset.frame_rate);
    uint16_t id = 1;
    for (const VehicleTrack& v : tracks) {
      Object o;
      o.name = "vehicle_" + std::to_string(id) + "_" + v.kind;
      o.mesh = cars.Get(v.shape, v.color);
      o.id = id++;
      o.world_from_object_per_frame = v.world_from_object;
      scene.objects.push_back(std::move(o));
    }
  }
  return scene;
}

}  // namespace rovo
