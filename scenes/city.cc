// Street scenes: GenerateScene runs the steps in a fixed order (layout, lighting, textures, shared
// materials, ground, roads, sidewalks, buildings, street furniture, traffic, lamps, lawns); the
// steps live in city_*.cc (city_internal.h).

#include "scenes/city.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "rovo/version.h"
#include "scenes/city_internal.h"
#include "scenes/city_layout.h"
#include "scenes/indoor.h"
#include "scenes/mesh_builder.h"
#include "scenes/rng.h"
#include "scenes/texture_gen.h"

namespace rovo {

using namespace city_internal;  // the steps of GenerateScene

namespace {

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
  if (preset.world == SceneWorld::kIndoor) return GenerateIndoorScene(preset, seed, quick);
  const CityLayout L = MakeCityLayout(preset, seed, quick);
  const CityStyle& st = L.style;
  const uint64_t layout_seed = LayoutSeed(preset.name, seed);
  const uint64_t texture_seed = SubSeed(layout_seed, "textures");
  SceneRng rng(SubSeed(layout_seed, "props"));

  Scene scene = ProceduralSceneHeader(preset, seed, quick, L.trajectory);
  const std::string lighting = SceneLightingName(preset.lighting);
  scene.lighting = MakeLighting(lighting, SubSeed(seed, lighting.c_str()), st.high_sun_along_streets);

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

  const bool night = preset.lighting == SceneLighting::kNight;
  if (preset.traffic) AddTraffic(scene, L, layout_seed ^ seed, preset.frame_rate, cars, night);
  if (night) LightStreetLamps(scene, mesh_light, materials.lamp);
  if (st.houses) AddLawns(scene, L, materials.lawn);
  return scene;
}

}  // namespace rovo
