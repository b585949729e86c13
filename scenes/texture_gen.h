#pragma once
// Procedural textures for the city (all seamlessly tileable, generated in memory, 8-bit sRGB).
// Each generator is deterministic in its seed. Texel densities are chosen for visual odometry:
// about 1.25 cm per texel on facades and about 1 cm on roads and sidewalks, with corners
// (window frames, brick joints, slab joints, markings, cracks) that ORB/KLT can track.

#include <cstdint>

#include "scenes/scene.h"

namespace rovo {

// Physical sizes the generators assume (metres covered by one texture tile).
inline constexpr double kFacadeTileMetres = 12.8;  // 1024 px wide, 4 floors of 3.2 m tall
inline constexpr double kFloorHeightMetres = 3.2;
inline constexpr double kStorefrontHeightMetres = 4.0;  // 1024 x 320 px: 12.8 m x 4 m
inline constexpr double kSidewalkTileMetres = 8.0;
inline constexpr double kGroundTileMetres = 12.0;
inline constexpr double kRoofTileMetres = 8.0;

// Upper-floor facade: 1024 x 1024 px for 12.8 m x 12.8 m (4 floors of 3.2 m; texture row 0 is the
// top of a floor), windows centred in FacadeBays(seed, index) equal columns. The wall colour is
// near neutral so the material tint sets the building colour.
Texture MakeFacadeTexture(uint64_t seed, int index);
int FacadeBays(uint64_t seed, int index);
// Where MakeFacadeTexture(seed, index) paints its windows, so geometry can line up with them. In a
// 3.2 m floor whose top is texture row 0 of a 256 px band, the window is window_height_fraction *
// 256 px tall and starts (256 - height) / 2 - 8 px below the top; horizontally it is centred in its
// bay, window_width_fraction of the bay wide.
struct FacadeLayout {
  int style = 0;                        // 0 brick, 1 plaster, 2 precast panels, 3 glass curtain wall
  int bays = 3;                         // window columns per 12.8 m tile
  double window_width_fraction = 0.5;   // of the bay width
  double window_height_fraction = 0.5;  // of the floor height
};
FacadeLayout GetFacadeLayout(uint64_t seed, int index);
// Ground-floor shops: 1024 x 320 px for 12.8 m x 4 m (shop windows, doors, signs, plinth).
Texture MakeStorefrontTexture(uint64_t seed, int index);
// Road segment: square tile `road_width_m` across (v, curb to curb) and along (u). Asphalt noise,
// cracks, patches, dashed centre line (2 dashes per tile), edge lines `parking_lane_m` from the curbs
// when > 0, gutters.
Texture MakeRoadTexture(uint64_t seed, int index, double road_width_m, double parking_lane_m);
// Intersection square of the road width: asphalt with zebra crossings along its four edges.
Texture MakeIntersectionTexture(uint64_t seed, double road_width_m);
Texture MakeSidewalkTexture(uint64_t seed);  // 0.5 m slabs, kSidewalkTileMetres per tile
Texture MakeConcreteTexture(uint64_t seed);  // curbs, roofs (kRoofTileMetres per tile)
Texture MakeGroundTexture(uint64_t seed);    // grass/dirt beyond the city
Texture MakeCarSideTexture(uint64_t seed);   // 512 x 128: doors, handles, sills (4.4 m x 1.1 m)
Texture MakeCarEndTexture(uint64_t seed);    // 256 x 128: grille, lights, plate
Texture MakeCarGlassTexture(uint64_t seed);  // 256 x 64: dark glass with pillars
Texture MakeBarkTexture(uint64_t seed);
Texture MakeAwningTexture(uint64_t seed, int index);  // 256 x 64: striped or plain cloth, 1 texel ~1 cm
// Road sign face, 256 x 256 px for a 0.6 m plate; kind in [0, kSignKinds): stop, give way, no
// entry, speed limit, pedestrian crossing. Outside the sign shape: the grey plate.
inline constexpr int kSignKinds = 5;
Texture MakeSignTexture(uint64_t seed, int kind);
Texture MakeFoliageTexture(uint64_t seed);

// ---- harder worlds: plain, low-contrast surfaces ----
inline constexpr double kHouseStoreyMetres = 2.9;
inline constexpr double kHouseWallTileMetres = 4.0;  // 512 px: about 8 mm per texel
inline constexpr double kLawnTileMetres = 6.0;
inline constexpr double kHallWallTileMetres = 4.0;
inline constexpr double kHallFloorTileMetres = 4.8;    // 4 x 4 polished stone slabs of 1.2 m
inline constexpr double kHallCeilingTileMetres = 2.4;  // 4 x 4 acoustic panels of 0.6 m
// Suburban house wall: smooth render (stucco) with only faint large-scale shading and fine grain
// (RMS contrast a few percent), near white so the material tint sets the colour.
Texture MakeHouseWallTexture(uint64_t seed, int index);
// Mown lawn: green with low-contrast large patches and fine grain (no blades, soil or edges).
Texture MakeLawnTexture(uint64_t seed);
// Indoor: plain painted wall (faint roller marks), polished stone floor slabs (soft veins, thin
// light joints), acoustic ceiling panels (thin grid lines), a notice-board poster (index varies).
Texture MakeWallPaintTexture(uint64_t seed);
Texture MakePolishedFloorTexture(uint64_t seed);
Texture MakeCeilingTileTexture(uint64_t seed);
Texture MakePosterTexture(uint64_t seed, int index);  // 256 x 360 px for 0.7 m x 1.0 m

}  // namespace rovo
