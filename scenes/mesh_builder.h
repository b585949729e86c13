#pragma once
// Building blocks of the procedural generators (internal to scenes/): a triangle-mesh builder with
// per-triangle materials and helpers that append materials, meshes and static objects to a Scene.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "scenes/scene.h"

namespace rovo {

using Vec3f = Eigen::Vector3f;
using Vec2f = Eigen::Vector2f;

// Appends geometry to one mesh with per-triangle materials. Faces are counter-clockwise seen from
// the side their normal points to.
class MeshBuilder {
 public:
  explicit MeshBuilder(std::string name) { mesh_.name = std::move(name); }
  void Tri(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec2f& ua, const Vec2f& ub, const Vec2f& uc,
           int material) {
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
    auto uv = [&](double x, double y) -> Vec2f {
      return Vec2f(static_cast<float>(x / tile), static_cast<float>(-y / tile)) + offset;
    };
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
    Quad(P(a.x(), a.y(), z0), P(b.x(), b.y(), z0), P(b.x(), b.y(), z1), P(a.x(), a.y(), z1), {ua, v0}, {ub, v0},
         {ub, v1}, {ua, v1}, material);
  }
  // Block in front of a wall: along the wall d in [d0, d1] from `origin` in direction `along` (unit),
  // out of it n in [n0, n1] along the wall's outward normal (right of `along`), z in [z0, z1]. Five
  // faces (no back face, it touches the wall). The front face takes uv(d, z), so a block carrying
  // the wall's material continues the wall's texture; the side, top and bottom faces continue it
  // around the edges (their depth coordinate stretches d or z).
  void WallBlock(const Eigen::Vector2d& origin, const Eigen::Vector2d& along, double d0, double d1, double n0,
                 double n1, double z0, double z1, const std::function<Vec2f(double, double)>& uv, int material) {
    const Eigen::Vector2d normal(along.y(), -along.x());
    auto at = [&](double d, double n, double z) {
      const Eigen::Vector2d xy = origin + d * along + n * normal;
      return P(xy.x(), xy.y(), z);
    };
    const double depth = n1 - n0;
    // Front (outward), seen from outside: d0 left, d1 right.
    Quad(at(d0, n1, z0), at(d1, n1, z0), at(d1, n1, z1), at(d0, n1, z1), uv(d0, z0), uv(d1, z0), uv(d1, z1), uv(d0, z1),
         material);
    // Side at d0 (normal -along) and at d1 (normal +along).
    Quad(at(d0, n0, z0), at(d0, n1, z0), at(d0, n1, z1), at(d0, n0, z1), uv(d0 - depth, z0), uv(d0, z0), uv(d0, z1),
         uv(d0 - depth, z1), material);
    Quad(at(d1, n1, z0), at(d1, n0, z0), at(d1, n0, z1), at(d1, n1, z1), uv(d1, z0), uv(d1 + depth, z0),
         uv(d1 + depth, z1), uv(d1, z1), material);
    // Top (normal +z) and bottom (normal -z).
    Quad(at(d0, n0, z1), at(d0, n1, z1), at(d1, n1, z1), at(d1, n0, z1), uv(d0, z1 + depth), uv(d0, z1), uv(d1, z1),
         uv(d1, z1 + depth), material);
    Quad(at(d0, n1, z0), at(d0, n0, z0), at(d1, n0, z0), at(d1, n1, z0), uv(d0, z0), uv(d0, z0 - depth),
         uv(d1, z0 - depth), uv(d1, z0), material);
  }
  // Axis-aligned box; per-face materials in order -x, +x, -y, +y, top (bottom omitted unless
  // `bottom`, then it takes the -x material). UVs map each face's full extent to [0, 1] unless
  // tile > 0 (metres per texture tile).
  void Box(const Vec3f& lo, const Vec3f& hi, const int materials[5], float tile = 0, bool bottom = false) {
    auto uv = [&](float a, float b, float ext_a, float ext_b) {
      return tile > 0 ? Vec2f(a / tile, -b / tile) : Vec2f(a / ext_a, 1.0f - b / ext_b);
    };
    const Vec3f e = hi - lo;
    // -x face: seen from -x, u along -y.
    Quad(P(lo.x(), hi.y(), lo.z()), P(lo.x(), lo.y(), lo.z()), P(lo.x(), lo.y(), hi.z()), P(lo.x(), hi.y(), hi.z()),
         uv(0, 0, e.y(), e.z()), uv(e.y(), 0, e.y(), e.z()), uv(e.y(), e.z(), e.y(), e.z()), uv(0, e.z(), e.y(), e.z()),
         materials[0]);
    Quad(P(hi.x(), lo.y(), lo.z()), P(hi.x(), hi.y(), lo.z()), P(hi.x(), hi.y(), hi.z()), P(hi.x(), lo.y(), hi.z()),
         uv(0, 0, e.y(), e.z()), uv(e.y(), 0, e.y(), e.z()), uv(e.y(), e.z(), e.y(), e.z()), uv(0, e.z(), e.y(), e.z()),
         materials[1]);
    Quad(P(lo.x(), lo.y(), lo.z()), P(hi.x(), lo.y(), lo.z()), P(hi.x(), lo.y(), hi.z()), P(lo.x(), lo.y(), hi.z()),
         uv(0, 0, e.x(), e.z()), uv(e.x(), 0, e.x(), e.z()), uv(e.x(), e.z(), e.x(), e.z()), uv(0, e.z(), e.x(), e.z()),
         materials[2]);
    Quad(P(hi.x(), hi.y(), lo.z()), P(lo.x(), hi.y(), lo.z()), P(lo.x(), hi.y(), hi.z()), P(hi.x(), hi.y(), hi.z()),
         uv(0, 0, e.x(), e.z()), uv(e.x(), 0, e.x(), e.z()), uv(e.x(), e.z(), e.x(), e.z()), uv(0, e.z(), e.x(), e.z()),
         materials[3]);
    Quad(P(lo.x(), lo.y(), hi.z()), P(hi.x(), lo.y(), hi.z()), P(hi.x(), hi.y(), hi.z()), P(lo.x(), hi.y(), hi.z()),
         uv(0, 0, e.x(), e.y()), uv(e.x(), 0, e.x(), e.y()), uv(e.x(), e.y(), e.x(), e.y()), uv(0, e.y(), e.x(), e.y()),
         materials[4]);
    if (bottom) {
      Quad(P(lo.x(), lo.y(), lo.z()), P(lo.x(), hi.y(), lo.z()), P(hi.x(), hi.y(), lo.z()), P(hi.x(), lo.y(), lo.z()),
           uv(0, 0, e.x(), e.y()), uv(0, e.y(), e.x(), e.y()), uv(e.x(), e.y(), e.x(), e.y()),
           uv(e.x(), 0, e.x(), e.y()), materials[0]);
    }
  }
  // Vertical prism with a regular n-gon cross-section around `axis_centre`; axis along z (or along
  // y when `along_y`, for wheels). Sides tile the texture once around.
  void Prism(const Vec3f& centre, float radius, float z0, float z1, int n, int side_material, int cap_material,
             bool along_y = false) {
    auto at = [&](float ang, float h) {
      const float c = radius * std::cos(ang), s = radius * std::sin(ang);
      return along_y ? Vec3f(centre.x() + c, centre.y() + h, centre.z() + s)
                     : Vec3f(centre.x() + c, centre.y() + s, centre.z() + h);
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

  static Vec3f P(double x, double y, double z) {
    return Vec3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  }

 private:
  Mesh mesh_;
};

inline int AddMaterial(Scene& scene, const std::string& name, const Vec3f& color, int texture) {
  Material m;
  m.name = name;
  m.base_color = color;
  m.texture = texture;
  scene.materials.push_back(m);
  return static_cast<int>(scene.materials.size()) - 1;
}

inline int AddMesh(Scene& scene, Mesh mesh) {
  scene.meshes.push_back(std::move(mesh));
  return static_cast<int>(scene.meshes.size()) - 1;
}

inline void AddStatic(Scene& scene, const std::string& name, int mesh, const Rigid3& world_from_object) {
  Object o;
  o.name = name;
  o.mesh = mesh;
  o.world_from_object = world_from_object;
  scene.objects.push_back(o);
}

inline Rigid3 PlaceYaw(double x, double y, double yaw_rad, double z = 0.0) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())), Eigen::Vector3d(x, y, z));
}

}  // namespace rovo
