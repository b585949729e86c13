// The indoor_hall world: plan (room boxes, lights, pillars, the rig's walk, people) and scene.

#include "scenes/indoor.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "datasets/rig.h"
#include "scenes/mesh_builder.h"
#include "scenes/rng.h"
#include "scenes/texture_gen.h"

namespace rovo {
namespace {

constexpr double kHallLightSpacing = 4.0;      // ceiling light grid in the hall
constexpr double kCorridorLightSpacing = 3.0;  // along the corridor
constexpr double kControlStep = 1.0;           // B-spline control points along the filleted polyline
constexpr double kFilletRadius = 3.0;
constexpr double kPersonClearance = 0.5;  // body surface to every camera centre, at every frame

// Points every `step` metres along the polyline `corners` with each inner corner replaced by a
// circular arc of `radius` (line-arc-line, as PathAlongRoute does for streets).
std::vector<Eigen::Vector2d> SampleFilletedPolyline(const std::vector<Eigen::Vector2d>& corners, double radius,
                                                    double step) {
  // Pieces: straight segments between tangent points and the arcs, each as a function of length.
  std::vector<std::pair<double, std::function<Eigen::Vector2d(double)>>> pieces;
  Eigen::Vector2d from = corners.front();
  for (size_t i = 1; i + 1 < corners.size(); ++i) {
    const Eigen::Vector2d a = (corners[i] - corners[i - 1]).normalized(),
                          b = (corners[i + 1] - corners[i]).normalized();
    const double turn = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
    const double cut = radius * std::tan(0.5 * std::abs(turn));
    const Eigen::Vector2d t0 = corners[i] - cut * a, start = from;
    pieces.push_back({(t0 - start).norm(), [start, a](double s) { return Eigen::Vector2d(start + s * a); }});
    const double side = turn > 0 ? 1.0 : -1.0;
    const Eigen::Vector2d centre = t0 + side * radius * Eigen::Vector2d(-a.y(), a.x());
    const double phi0 = std::atan2(t0.y() - centre.y(), t0.x() - centre.x());
    pieces.push_back({radius * std::abs(turn), [centre, phi0, side, radius](double s) {
                        const double phi = phi0 + side * s / radius;
                        return Eigen::Vector2d(centre + radius * Eigen::Vector2d(std::cos(phi), std::sin(phi)));
                      }});
    from = corners[i] + cut * b;
  }
  const Eigen::Vector2d dir = (corners.back() - from).normalized(), start = from;
  pieces.push_back(
      {(corners.back() - from).norm(), [start, dir](double s) { return Eigen::Vector2d(start + s * dir); }});
  std::vector<Eigen::Vector2d> out;
  double carry = 0.0;
  for (const auto& [length, at] : pieces) {
    double s = carry;
    for (; s <= length; s += step) out.push_back(at(s));
    carry = s - length;
  }
  return out;
}

// The rig's path: (4, 6) east, an S-bend south to y = 0, east through the opening and down the
// corridor's centre line to 3 m before its end wall.
void PlanRigWalk(IndoorLayout* L, int frames, double length, uint64_t seed) {
  const double end_x = L->corridor.max.x() - 3.0;
  const std::vector<Eigen::Vector2d> corners = {{4, 6}, {16, 6}, {16, 0}, {end_x, 0}};
  L->rig_path = LanePath(SampleFilletedPolyline(corners, kFilletRadius, kControlStep));
  // Arc length where the path crosses x = kHallEndX (the path runs east there).
  double lo = 0.0, hi = L->rig_path.Length();
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (L->rig_path.Position(mid).x() < kHallEndX ? lo : hi) = mid;
  }
  L->corridor_entry_s = lo;
  const double s_begin = L->quick ? L->corridor_entry_s - 0.5 * length : 1.0;
  if (!PlanDrive(L->rig_path, s_begin, length, frames, L->preset.frame_rate, &L->drive))
    throw std::runtime_error("MakeIndoorLayout: no feasible walk for preset " + L->preset.name);
  // A cart pushed on a smooth floor: slight roll/pitch wobble and bob.
  SceneRng vib(SubSeed(seed, "vibration"));
  double amp[4], freq[4], phase[4];
  for (int k = 0; k < 4; ++k) {
    amp[k] = vib.Uniform(0.05, 0.15);  // degrees
    freq[k] = vib.Uniform(0.4, 1.5);   // Hz
    phase[k] = vib.Uniform(0, 2 * M_PI);
  }
  L->trajectory.resize(frames);
  for (int f = 0; f < frames; ++f) {
    const double t = f / L->preset.frame_rate, s = L->drive.s[f];
    const Eigen::Vector2d xy = L->rig_path.Position(s);
    const double roll =
        amp[0] * std::sin(2 * M_PI * freq[0] * t + phase[0]) + amp[1] * std::sin(2 * M_PI * freq[1] * t + phase[1]);
    const double pitch =
        amp[2] * std::sin(2 * M_PI * freq[2] * t + phase[2]) + amp[3] * std::sin(2 * M_PI * freq[3] * t + phase[3]);
    const double z = kIndoorRigHeight + 0.003 * std::sin(2 * M_PI * 1.7 * t);
    L->trajectory[f].timestamp = t;
    L->trajectory[f].world_from_rig =
        Rigid3(QuaternionFromRollPitchYawDeg(roll, pitch, L->rig_path.Heading(s) * 180.0 / M_PI),
               Eigen::Vector3d(xy.x(), xy.y(), z));
  }
}

// Ceiling lights on a grid over the hall and along the corridor; pillars in two rows, kept clear of
// the rig's path.
void PlanFixtures(IndoorLayout* L) {
  for (double x = 0.5 * kHallLightSpacing + 1.0; x < kHallEndX; x += kHallLightSpacing)
    for (double y = -8.0; y <= 8.0 + 1e-9; y += kHallLightSpacing)
      L->hall_lights.emplace_back(x, y, kHallHeight - 0.15);
  for (double x = kHallEndX + 1.5; x < L->corridor.max.x(); x += kCorridorLightSpacing)
    L->corridor_lights.emplace_back(x, 0.0, kCorridorHeight - 0.15);
  for (double x = 6.0; x < kHallEndX - 2.0; x += 8.0)
    for (double y : {-5.5, 3.0}) {
      const Eigen::Vector2d p(x, y);
      double clear = 1e9;
      for (double s = 0.0; s < L->rig_path.Length(); s += 0.25)
        clear = std::min(clear, (L->rig_path.Position(s) - p).norm());
      if (clear > 2.2) L->pillars.push_back(p);
    }
}

// Centre of a person walking at `speed` back and forth between a and b, at time t.
Eigen::Vector2d PingPong(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double speed, double t) {
  const double len = (b - a).norm();
  double u = std::fmod(speed * t, 2.0 * len);
  if (u > len) u = 2.0 * len - u;
  return a + (b - a) * (u / len);
}

// Smallest distance over the frames from the person's body (a cylinder of kPersonRadius) to any
// camera centre of the rig.
double ClosestCameraDistance(const IndoorLayout& L, const IndoorPerson& p) {
  double best = 1e9;
  for (size_t f = 0; f < L.trajectory.size(); ++f) {
    const Eigen::Vector2d& xy = p.xy[p.Moving() ? f : 0];
    for (const Eigen::Vector3d& c : L.cameras_in_rig) {
      const Eigen::Vector3d w = L.trajectory[f].world_from_rig * c;
      best = std::min(best, (w.head<2>() - xy).norm() - kPersonRadius);
    }
  }
  return best;
}

// People beside the rig's path (1.3-2.7 m from its centre line, about a third of them walking
// slowly along it) and a few standing farther away in the hall. Every person keeps
// kPersonClearance to every camera at every frame, 0.2 m to the walls and 1 m to the others.
void PlacePeople(IndoorLayout* L, uint64_t seed) {
  SceneRng rng(SubSeed(seed, "people"));
  const int frames = static_cast<int>(L->trajectory.size());
  auto free_spot = [&](const Eigen::Vector2d& p) {
    if (!L->OnFloor(p, 0.2 + kPersonRadius)) return false;
    for (const Eigen::Vector2d& q : L->pillars)
      if ((q - p).cwiseAbs().maxCoeff() < 0.3 + kPersonRadius + 0.3) return false;
    for (const IndoorPerson& o : L->people)
      for (const Eigen::Vector2d& q : o.xy)
        if ((q - p).norm() < 1.0) return false;
    return true;
  };
  auto try_add = [&](IndoorPerson person) {
    for (const Eigen::Vector2d& q : person.xy)
      if (!free_spot(q)) return;
    if (ClosestCameraDistance(*L, person) >= kPersonClearance) L->people.push_back(std::move(person));
  };
  const double s0 = std::max(0.0, L->drive.s.front() - 10.0),
               s1 = std::min(L->rig_path.Length(), L->drive.s.back() + 10.0);
  for (double s = s0 + rng.Uniform(0.0, 1.0); s < s1; s += rng.Uniform(1.2, 2.5)) {
    IndoorPerson person;
    person.variant = rng.UniformInt(0, 5);
    const bool in_corridor = L->rig_path.Position(s).x() > kHallEndX - 1.0;
    const double side = rng.Bernoulli(0.5) ? 1.0 : -1.0;
    const double offset = in_corridor ? rng.Uniform(1.3, 1.65) : rng.Uniform(1.3, 2.7);
    const double heading = L->rig_path.Heading(s);
    const Eigen::Vector2d normal(-std::sin(heading), std::cos(heading)), along(std::cos(heading), std::sin(heading));
    const Eigen::Vector2d base = L->rig_path.Position(s) + side * offset * normal;
    if (rng.Bernoulli(0.35)) {  // walking slowly along the path, back and forth
      const double speed = rng.Uniform(0.3, 0.6), span = rng.Uniform(2.0, 5.0);
      person.yaw = heading;
      for (int f = 0; f < frames; ++f)
        person.xy.push_back(PingPong(base, base + span * along, speed, f / L->preset.frame_rate));
    } else {  // standing, facing the path or along it
      person.yaw =
          rng.Bernoulli(0.5) ? std::atan2(-side * normal.y(), -side * normal.x()) : heading + rng.Normal(0, 0.5);
      person.xy.push_back(base);
    }
    try_add(std::move(person));
  }
  const int far = L->quick ? 4 : 10;
  const size_t near = L->people.size();
  for (int k = 0; k < 3 * far && static_cast<int>(L->people.size() - near) < far; ++k) {
    IndoorPerson person;
    person.variant = rng.UniformInt(0, 5);
    person.yaw = rng.Uniform(0, 2 * M_PI);
    person.xy.push_back({rng.Uniform(1.0, kHallEndX - 1.0), rng.Uniform(-9.0, 9.0)});
    try_add(std::move(person));
  }
}

}  // namespace

bool IndoorLayout::OnFloor(const Eigen::Vector2d& p, double margin) const {
  const Box2 h{hall.min.array() + margin, hall.max.array() - margin};
  const Box2 c{{corridor.min.x() - margin - 1.0, corridor.min.y() + margin}, corridor.max.array() - margin};
  return h.Contains(p) || c.Contains(p);
}

IndoorLayout MakeIndoorLayout(const ScenePreset& preset, uint64_t seed, bool quick) {
  IndoorLayout L;
  L.preset = preset;
  L.quick = quick;
  const uint64_t layout_seed = SubSeed(seed, preset.name.c_str());
  const int frames = quick ? preset.quick_frames : preset.frames;
  const double length = quick ? QuickPathLength(preset) : preset.path_length_m;
  // The full walk: about 24 m through the hall, the rest down the corridor.
  L.corridor_length = preset.path_length_m - 20.0;
  L.hall = {{0.0, -10.0}, {kHallEndX, 10.0}};
  L.corridor = {{kHallEndX, -kCorridorHalfWidth}, {kHallEndX + L.corridor_length, kCorridorHalfWidth}};
  const Rig rig = MakeRigPreset(preset.rig_preset);
  for (const RigCamera& c : rig.cameras) L.cameras_in_rig.push_back(CameraPositionInRig(c.cam_from_rig));
  PlanRigWalk(&L, frames, length, layout_seed);
  PlanFixtures(&L);
  PlacePeople(&L, layout_seed);
  return L;
}

namespace {

constexpr int kPersonVariants = 6;
constexpr int kPosters = 4;

struct IndoorMaterials {
  int wall = 0, floor = 0, ceiling = 0, skirting = 0, door = 0, door_frame = 0, panel = 0, bench = 0;
  int poster[kPosters] = {0, 0, 0, 0};
  int skin[3] = {0, 0, 0}, hair = 0, shirt[kPersonVariants] = {}, trousers[3] = {0, 0, 0};
};

// Textures (generated in parallel, each from its own seed) and materials.
IndoorMaterials AddIndoorMaterials(Scene& scene, uint64_t texture_seed) {
  std::vector<std::function<Texture()>> jobs = {[=] { return MakeWallPaintTexture(texture_seed); },
                                                [=] { return MakePolishedFloorTexture(texture_seed); },
                                                [=] { return MakeCeilingTileTexture(texture_seed); }};
  for (int k = 0; k < kPosters; ++k) jobs.push_back([=] { return MakePosterTexture(texture_seed, k); });
  scene.textures.resize(jobs.size());
  tbb::parallel_for(size_t{0}, jobs.size(), [&](size_t i) { scene.textures[i] = jobs[i](); });
  IndoorMaterials m;
  m.wall = AddMaterial(scene, "wall_paint", {0.97f, 0.95f, 0.9f}, 0);
  m.floor = AddMaterial(scene, "polished_floor", {1, 1, 1}, 1);
  scene.materials[m.floor].specular = 0.25f;  // polished stone: highlights of the ceiling lights
  scene.materials[m.floor].shininess = 80.0f;
  m.ceiling = AddMaterial(scene, "ceiling", {1, 1, 1}, 2);
  m.skirting = AddMaterial(scene, "skirting", {0.2f, 0.2f, 0.22f}, -1);
  m.door = AddMaterial(scene, "door", {0.42f, 0.3f, 0.2f}, -1);
  m.door_frame = AddMaterial(scene, "door_frame", {0.55f, 0.56f, 0.58f}, -1);
  m.panel = AddMaterial(scene, "light_panel", {0.95f, 0.95f, 0.95f}, -1);
  scene.materials[m.panel].emission = {0.5f, 0.49f, 0.45f};  // about 5000 cd/m^2 on the day scale
  m.bench = AddMaterial(scene, "bench", {0.15f, 0.16f, 0.18f}, -1);
  for (int k = 0; k < kPosters; ++k) m.poster[k] = AddMaterial(scene, "poster_" + std::to_string(k), {1, 1, 1}, 3 + k);
  const Vec3f skins[3] = {{0.75f, 0.55f, 0.42f}, {0.5f, 0.33f, 0.22f}, {0.3f, 0.2f, 0.14f}};
  for (int k = 0; k < 3; ++k) m.skin[k] = AddMaterial(scene, "skin_" + std::to_string(k), skins[k], -1);
  m.hair = AddMaterial(scene, "hair", {0.08f, 0.06f, 0.05f}, -1);
  const Vec3f shirts[kPersonVariants] = {{0.1f, 0.2f, 0.5f},  {0.6f, 0.1f, 0.1f}, {0.8f, 0.8f, 0.78f},
                                         {0.15f, 0.4f, 0.2f}, {0.5f, 0.4f, 0.2f}, {0.2f, 0.2f, 0.22f}};
  for (int k = 0; k < kPersonVariants; ++k)
    m.shirt[k] = AddMaterial(scene, "shirt_" + std::to_string(k), shirts[k], -1);
  const Vec3f trousers[3] = {{0.1f, 0.1f, 0.15f}, {0.3f, 0.28f, 0.25f}, {0.05f, 0.05f, 0.05f}};
  for (int k = 0; k < 3; ++k) m.trousers[k] = AddMaterial(scene, "trousers_" + std::to_string(k), trousers[k], -1);
  return m;
}

// Inward-facing walls (MeshBuilder::Wall puts the normal on the right of a -> b, so the room is
// walked clockwise seen from above); `skirting` adds a 10 cm dark board at the foot of each.
struct WallRun {
  Eigen::Vector2d a, b;
  double z0, z1;
  bool skirting;
};

std::vector<WallRun> ShellWalls(const IndoorLayout& L) {
  const double x0 = L.hall.min.x(), x1 = L.hall.max.x(), y0 = L.hall.min.y(), y1 = L.hall.max.y();
  const double xe = L.corridor.max.x(), w = kCorridorHalfWidth;
  return {{{x1, y0}, {x0, y0}, 0, kHallHeight, true},
          {{x0, y0}, {x0, y1}, 0, kHallHeight, true},
          {{x0, y1}, {x1, y1}, 0, kHallHeight, true},
          {{x1, y1}, {x1, w}, 0, kHallHeight, true},
          {{x1, w}, {x1, -w}, kCorridorHeight, kHallHeight, false},  // above the corridor opening
          {{x1, -w}, {x1, y0}, 0, kHallHeight, true},
          {{x1, w}, {xe, w}, 0, kCorridorHeight, true},
          {{xe, w}, {xe, -w}, 0, kCorridorHeight, true},
          {{xe, -w}, {x1, -w}, 0, kCorridorHeight, true}};
}

// Floors, ceilings and walls of the hall and the corridor, with skirting boards.
void AddShell(Scene& scene, const IndoorLayout& L, const IndoorMaterials& m) {
  MeshBuilder b("shell");
  b.Floor(L.hall.min, L.hall.max, 0.0, kHallFloorTileMetres, m.floor);
  b.Floor(L.corridor.min, L.corridor.max, 0.0, kHallFloorTileMetres, m.floor);
  b.Floor(L.hall.min, L.hall.max, kHallHeight, kHallCeilingTileMetres, m.ceiling);
  b.Floor(L.corridor.min, L.corridor.max, kCorridorHeight, kHallCeilingTileMetres, m.ceiling);
  auto flat_uv = [](double d, double z) { return Vec2f(static_cast<float>(d), static_cast<float>(-z)); };
  for (const WallRun& r : ShellWalls(L)) {
    b.Wall(r.a, r.b, r.z0, r.z1, 0.0, kHallWallTileMetres, -r.z0 / kHallWallTileMetres, kHallWallTileMetres, m.wall);
    if (!r.skirting) continue;
    const double len = (r.b - r.a).norm();
    b.WallBlock(r.a, (r.b - r.a) / len, 0.0, len, 0.0, 0.015, 0.0, 0.1, flat_uv, m.skirting);
  }
  AddStatic(scene, "shell", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Doors (a plain leaf in a grey frame) and notice-board posters on the walls: the sparse features.
// Corridor: a door every 5-9 m on alternating sides, a poster every 12-20 m; hall: three doors
// and three posters.
void AddWallDetails(Scene& scene, const IndoorLayout& L, const IndoorMaterials& m, SceneRng& rng) {
  MeshBuilder b("wall_details");
  auto flat_uv = [](double d, double z) { return Vec2f(static_cast<float>(d), static_cast<float>(-z)); };
  auto door = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& along, double d) {
    b.WallBlock(a, along, d - 0.55, d + 0.55, 0.0, 0.04, 0.0, 2.2, flat_uv, m.door_frame);
    b.WallBlock(a, along, d - 0.45, d + 0.45, 0.0, 0.05, 0.0, 2.1, flat_uv, m.door);
  };
  auto poster = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& along, double d) {
    const int k = rng.UniformInt(0, kPosters - 1);
    const double d0 = d - 0.35, z0 = 1.1;
    auto uv = [d0, z0](double dd, double z) {
      return Vec2f(static_cast<float>((dd - d0) / 0.7), static_cast<float>((z0 + 1.0 - z) / 1.0));
    };
    b.WallBlock(a, along, d0, d0 + 0.7, 0.0, 0.01, z0, z0 + 1.0, uv, m.poster[k]);
  };
  const double w = kCorridorHalfWidth, x1 = kHallEndX, xe = L.corridor.max.x();
  // Corridor walls: north (a = (x1, w), along +x), south (a = (xe, -w), along -x).
  const Eigen::Vector2d north_a(x1, w), south_a(xe, -w), east(1, 0), west(-1, 0);
  bool north = rng.Bernoulli(0.5);
  for (double x = x1 + rng.Uniform(3.0, 6.0); x < xe - 2.0; x += rng.Uniform(5.0, 9.0), north = !north)
    north ? door(north_a, east, x - x1) : door(south_a, west, xe - x);
  for (double x = x1 + rng.Uniform(6.0, 12.0); x < xe - 2.0; x += rng.Uniform(12.0, 20.0))
    rng.Bernoulli(0.5) ? poster(north_a, east, x - x1 + 1.6) : poster(south_a, west, xe - x + 1.6);
  // Hall: doors on the north and west walls, posters on the south and west walls.
  const Eigen::Vector2d hall_north(L.hall.min.x(), L.hall.max.y()), hall_west(L.hall.min.x(), L.hall.min.y());
  const Eigen::Vector2d hall_south(L.hall.max.x(), L.hall.min.y()), north_dir(0, 1);
  door(hall_north, east, rng.Uniform(5.0, 12.0));
  door(hall_north, east, rng.Uniform(17.0, 25.0));
  door(hall_west, north_dir, rng.Uniform(6.0, 14.0));
  poster(hall_south, west, rng.Uniform(4.0, 12.0));
  poster(hall_south, west, rng.Uniform(16.0, 26.0));
  poster(hall_west, north_dir, rng.Uniform(3.0, 5.0));
  AddStatic(scene, "wall_details", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Glowing ceiling panels (0.6 m squares in the hall, 1.2 x 0.3 m strips in the corridor) with a
// light 15 cm below each that shines downwards only.
void AddCeilingLights(Scene& scene, const IndoorLayout& L, const IndoorMaterials& m) {
  MeshBuilder b("light_panels");
  auto panel = [&](const Eigen::Vector3d& p, double hx, double hy) {
    b.Floor({p.x() - hx, p.y() - hy}, {p.x() + hx, p.y() + hy}, p.z() + 0.13, 1.0, m.panel);
  };
  auto light = [&](const Eigen::Vector3d& p, const std::string& name, float intensity, double range) {
    Light l;
    l.name = name;
    l.position = p;
    l.intensity = Eigen::Vector3f(1.0f, 0.97f, 0.88f) * intensity;  // neutral-warm white
    l.range = range;
    // A downward hemisphere with A = cos(angle off the axis): a Lambertian panel, dark above.
    l.spot = true;
    l.spot_direction = Eigen::Vector3d(0.0, 0.0, -1.0);
    l.spot_angle_deg = 180.0;
    l.spot_blend = 0.0;
    scene.lights.push_back(l);
  };
  for (size_t i = 0; i < L.hall_lights.size(); ++i) {
    panel(L.hall_lights[i], 0.3, 0.3);
    light(L.hall_lights[i], "hall_light_" + std::to_string(i), 0.14f, 10.0);
  }
  for (size_t i = 0; i < L.corridor_lights.size(); ++i) {
    panel(L.corridor_lights[i], 0.6, 0.15);
    light(L.corridor_lights[i], "corridor_light_" + std::to_string(i), 0.07f, 7.0);
  }
  AddStatic(scene, "light_panels", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Pillars (plain, floor to ceiling) and benches along the hall's south wall.
void AddFurniture(Scene& scene, const IndoorLayout& L, const IndoorMaterials& m, SceneRng& rng) {
  MeshBuilder b("furniture");
  const int plain[5] = {m.wall, m.wall, m.wall, m.wall, m.wall};
  for (const Eigen::Vector2d& p : L.pillars)
    b.Box(MeshBuilder::P(p.x() - 0.3, p.y() - 0.3, 0.0), MeshBuilder::P(p.x() + 0.3, p.y() + 0.3, kHallHeight), plain,
          static_cast<float>(kHallWallTileMetres));
  const int bench[5] = {m.bench, m.bench, m.bench, m.bench, m.bench};
  for (int k = 0; k < 3; ++k) {
    const double x = 5.0 + 8.0 * k + rng.Uniform(-1.0, 1.0), y = L.hall.min.y() + 0.4;
    b.Box(MeshBuilder::P(x - 0.9, y - 0.22, 0.0), MeshBuilder::P(x + 0.9, y + 0.22, 0.45), bench);
  }
  AddStatic(scene, "furniture", AddMesh(scene, b.Finish()), Rigid3::Identity());
}

// Person variant v: two legs, torso, two arms, neck and head (prisms and boxes); origin on the
// floor under the body's axis, facing +x, about 1.6-1.8 m tall.
int AddPersonMesh(Scene& scene, const IndoorMaterials& m, int v) {
  MeshBuilder b("person_" + std::to_string(v));
  const float h = 0.92f + 0.04f * static_cast<float>(v % 4);  // height scale of a 1.85 m figure
  const int skin = m.skin[v % 3], shirt = m.shirt[v], trousers = m.trousers[v % 3];
  for (const float y : {-0.1f, 0.1f}) b.Prism({0.0f, y, 0.0f}, 0.075f, 0.0f, 0.86f * h, 8, trousers, trousers);
  const int torso[5] = {shirt, shirt, shirt, shirt, shirt};
  b.Box({-0.12f, -0.21f, 0.86f * h}, {0.12f, 0.21f, 1.48f * h}, torso, 0.0f, true);
  for (const float y : {-0.27f, 0.27f}) b.Prism({0.0f, y, 0.0f}, 0.05f, 0.82f * h, 1.46f * h, 8, shirt, skin);
  b.Prism({0.0f, 0.0f, 0.0f}, 0.05f, 1.48f * h, 1.55f * h, 8, skin, skin);
  b.Prism({0.0f, 0.0f, 0.0f}, 0.1f, 1.55f * h, 1.78f * h, 10, skin, skin);
  b.Prism({-0.01f, 0.0f, 0.0f}, 0.105f, 1.74f * h, 1.82f * h, 10, m.hair, m.hair);
  return AddMesh(scene, b.Finish());
}

// People: standing ones are static objects, walking ones dynamic (mask ids 1..N).
void AddPeople(Scene& scene, const IndoorLayout& L, const int (&meshes)[kPersonVariants]) {
  uint16_t id = 1;
  for (size_t k = 0; k < L.people.size(); ++k) {
    const IndoorPerson& p = L.people[k];
    const std::string name = "person_" + std::to_string(k) + (p.Moving() ? "_walking" : "_standing");
    if (!p.Moving()) {
      AddStatic(scene, name, meshes[p.variant], PlaceYaw(p.xy[0].x(), p.xy[0].y(), p.yaw));
      continue;
    }
    Object o;
    o.name = name;
    o.mesh = meshes[p.variant];
    o.id = id++;
    for (size_t f = 0; f < p.xy.size(); ++f) {
      // Facing the way it walks (turning round at the ends of its beat).
      const Eigen::Vector2d step =
          p.xy[std::min(f + 1, p.xy.size() - 1)] - p.xy[f > 0 && f + 1 == p.xy.size() ? f - 1 : f];
      const double yaw = step.norm() > 1e-9 ? std::atan2(step.y(), step.x()) : p.yaw;
      o.world_from_object_per_frame.push_back(PlaceYaw(p.xy[f].x(), p.xy[f].y(), yaw));
    }
    scene.objects.push_back(std::move(o));
  }
}

// Indoors the sky is never seen; its terms stand for the light the walls, floor and ceiling pass
// on (upward faces get sky_zenith, downward ones ground_albedo times it). On the day presets'
// scale (sun irradiance 3) an office is about 150 times darker, hence the exposure.
Lighting IndoorLighting() {
  Lighting l;
  l.preset = "indoor";
  l.direction_to_sun = Eigen::Vector3d(0.3, 0.2, 0.9);
  l.sun_radiance = {0.0f, 0.0f, 0.0f};
  l.sky_zenith = {0.0015f, 0.00146f, 0.00135f};
  l.sky_horizon = l.sky_zenith;
  l.ground_albedo = {0.45f, 0.45f, 0.45f};
  l.ambient = 1.0f;
  l.exposure = 150.0f;
  return l;
}

}  // namespace

Scene GenerateIndoorScene(const ScenePreset& preset, uint64_t seed, bool quick) {
  const IndoorLayout L = MakeIndoorLayout(preset, seed, quick);
  const uint64_t layout_seed = SubSeed(seed, preset.name.c_str());
  SceneRng rng(SubSeed(layout_seed, "props"));
  Scene scene = ProceduralSceneHeader(preset, seed, quick, L.trajectory);
  scene.lighting = IndoorLighting();
  const IndoorMaterials m = AddIndoorMaterials(scene, SubSeed(layout_seed, "textures"));
  AddShell(scene, L, m);
  AddWallDetails(scene, L, m, rng);
  AddCeilingLights(scene, L, m);
  AddFurniture(scene, L, m, rng);
  int person_meshes[kPersonVariants];
  for (int v = 0; v < kPersonVariants; ++v) person_meshes[v] = AddPersonMesh(scene, m, v);
  AddPeople(scene, L, person_meshes);
  return scene;
}

}  // namespace rovo
