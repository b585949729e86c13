// Street furniture: street lights, trees, road signs and parked cars along the curbs.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scenes/city_internal.h"

namespace rovo::city_internal {

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

int AddSignMesh(Scene& scene, const CityMaterials& m, const CityTextures& t, int k) {
  MeshBuilder b("sign_" + std::to_string(k));
  const int m_face = AddMaterial(scene, "sign_" + std::to_string(k), {1, 1, 1}, t.sign + k);
  b.Prism({-0.05f, 0, 0}, 0.04f, 0.0f, 2.9f, 6, m.metal, m.metal);
  const int plate[5] = {m.metal, m_face, m.metal, m.metal, m.metal};
  b.Box({0.0f, -0.3f, 2.3f}, {0.025f, 0.3f, 2.9f}, plate);
  return AddMesh(scene, b.Finish());
}

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

}  // namespace rovo::city_internal
