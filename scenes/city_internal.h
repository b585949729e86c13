#pragma once
// What the parts of the street generator share (internal to scenes/): GenerateScene (city.cc) calls
// the lighting, traffic, buildings and street-furniture steps of the city_*.cc files through these.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "scenes/city_layout.h"
#include "scenes/mesh_builder.h"
#include "scenes/rng.h"
#include "scenes/scene.h"
#include "scenes/texture_gen.h"

namespace rovo::city_internal {

// ---- textures and shared materials (city.cc) ----

struct CarTextures {
  int side = -1, end = -1, glass = -1;
};

// Texture indices of the generated textures (in scene.textures).
struct CityTextures {
  int num_facades = 0, num_storefronts = 0, num_awnings = 0;  // facades first, then storefronts
  int road = 0, intersection = 0, sidewalk = 0, concrete = 0, ground = 0, bark = 0, foliage = 0, sign = 0, awning = 0;
  int lawn = -1;  // suburban lots only
  CarTextures car;
};

// Materials shared by the whole city (material indices).
struct CityMaterials {
  int road[2] = {0, 0};
  int intersection = 0, sidewalk = 0, curb = 0, roof = 0, ground = 0, metal = 0, lamp = 0, bark = 0, foliage = 0;
  int lawn = -1;  // suburban lots only
};

// ---- lighting (city_lighting.cc) ----

// Sun and sky of a lighting preset. `high_sun_along_streets` (sunny only): a high sun 15-25 degrees
// off a street axis, so that light reaches the floor of a narrow canyon in strips.
Lighting MakeLighting(const std::string& preset, uint64_t seed, bool high_sun_along_streets);
// Street lamps at night: the lamp head's underside glows and a light just below it shines down.
void LightStreetLamps(Scene& scene, int mesh_light, int m_lamp);

// ---- vehicles and traffic (city_traffic.cc) ----

inline constexpr int kNumCarShapes = 4, kNumCarColors = 8;
struct CarShape;

// Car meshes, one per (shape, colour, lit), made on first use; parked cars and traffic share them.
class CarFactory {
 public:
  CarFactory(Scene& scene, const CarTextures& tex);
  // Mesh of a car: origin on the ground under the centre, x forward, z up. `lit`: with glowing head
  // and tail lamps (Headlights gives the headlight positions).
  int Get(int shape, int color, bool lit = false);
  // Headlight spots of a lit car of `shape`, in the car's frame, riding on object `object`.
  static std::vector<Light> Headlights(int shape, int object, const std::string& name);

 private:
  void AddLamps(MeshBuilder& b, const CarShape& s);

  Scene& scene_;
  CarTextures tex_;
  int glass_, tyre_;
  int headlamp_ = -1, taillamp_ = -1;
  std::map<int, int> meshes_;
};

// Moving vehicles (ids 1..N for the masks); with `lights_on`, glowing lamps and two headlight
// spots riding on each.
void AddTraffic(Scene& scene, const CityLayout& L, uint64_t traffic_seed, double frame_rate, CarFactory& cars,
                bool lights_on);

// ---- buildings (city_buildings.cc) ----

// Buildings: storefronts, facades, relief, balconies, awnings, rooflines; suburban houses.
void AddBuildings(Scene& scene, const CityLayout& L, const CityTextures& t, const CityMaterials& m,
                  uint64_t layout_seed, uint64_t texture_seed);

// ---- street furniture (city_furniture.cc) ----

// Street light mesh: arm along +x (towards the road).
int AddStreetLightMesh(Scene& scene, const CityMaterials& m);
// Tree variant v: a trunk and a crown (octahedron subdivided twice, vertices jittered; spherical UVs).
int AddTreeMesh(Scene& scene, const CityMaterials& m, uint64_t layout_seed, int v);
// Road sign kind k: pole and a 0.6 m plate whose face (sign texture) looks along the mesh's +x.
int AddSignMesh(Scene& scene, const CityMaterials& m, const CityTextures& t, int k);
// One sign at about half of the block corners, 0.7 m from both curbs, facing traffic on one of
// the two streets.
void PlaceSigns(Scene& scene, const CityLayout& L, const int (&mesh_sign)[kSignKinds], SceneRng& rng);
// Along every street segment side: lights every ~28 m, trees between them, parked cars in the lane.
void FurnishStreets(Scene& scene, const CityLayout& L, int mesh_light, const int (&mesh_tree)[3], CarFactory& cars,
                    SceneRng& rng);

}  // namespace rovo::city_internal
