// Buildings of the street scenes: walls with storefronts, facade relief lined up with the painted
// windows, balconies, awnings, rooflines and rooftop structures; suburban houses.

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "scenes/city_internal.h"

namespace rovo::city_internal {
namespace {

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
  const int window_margin_px = (f.bay_px - f.win_w_px) / 2;  // whole pixels, as the texture draws it
  for (int t = tile_first; t <= tile_last; ++t)
    for (int k = 0; k < fl.bays; ++k) {
      const double x0 = 1024.0 * t + k * f.bay_px;
      f.bay_edges.push_back(d_of_px(x0));
      f.window_centres.push_back(d_of_px(x0 + window_margin_px + 0.5 * f.win_w_px));
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

HouseMaterials AddHouseMaterials(Scene& scene, const CityTextures& t) {
  HouseMaterials hm;
  hm.glass = AddMaterial(scene, "house_window", {0.08f, 0.1f, 0.13f}, -1);
  hm.frame = AddMaterial(scene, "house_frame", {0.85f, 0.85f, 0.83f}, -1);
  hm.door = AddMaterial(scene, "house_door", {0.25f, 0.15f, 0.1f}, -1);
  hm.plinth = AddMaterial(scene, "house_plinth", {0.55f, 0.55f, 0.55f}, t.concrete);
  return hm;
}

}  // namespace

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

}  // namespace rovo::city_internal
