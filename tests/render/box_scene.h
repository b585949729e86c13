#pragma once
// Calibration scene for the render tests: a closed box room with checker-textured faces whose ray
// intersections are known in closed form, optionally with a moving cube (a dynamic object).
//
// Room: x in [-4, 4], y in [-3, 3], z in [0, 3] (metres, world frame). Face ids (Object::id, seen
// in masks): 1 floor z=0, 2 ceiling z=3, 3 wall x=-4, 4 wall x=+4, 5 wall y=-3, 6 wall y=+3.
// Mover (id 7): axis-aligned cube of half-size 0.3 m centred at MoverCentre(frame).

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <string>

#include "datasets/rig.h"
#include "scenes/scene.h"

namespace rovo::testing {

inline constexpr double kRoomMin[3] = {-4.0, -3.0, 0.0};
inline constexpr double kRoomMax[3] = {4.0, 3.0, 3.0};
inline constexpr double kMoverHalf = 0.3;

inline Eigen::Vector3d MoverCentre(int frame) { return Eigen::Vector3d(2.0, 1.5 - 0.25 * frame, 1.2); }

inline Eigen::Vector3d RigPosition(int frame) { return Eigen::Vector3d(-0.5 + 0.1 * frame, -0.2, 1.4); }

// 32x32 checker of 8x8-texel squares; `tint` selects a colour per face.
inline Texture MakeChecker(const std::string& name, int tint) {
  Texture tex;
  tex.name = name;
  tex.width = 32;
  tex.height = 32;
  tex.rgb.resize(32 * 32 * 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const bool dark = ((x / 8) + (y / 8)) % 2 == 0;
      for (int c = 0; c < 3; ++c) {
        const int base = dark ? 40 : 220;
        tex.rgb[(y * 32 + x) * 3 + c] = static_cast<uint8_t>(c == tint % 3 ? base : base * 3 / 4);
      }
    }
  return tex;
}

// A quad mesh (two triangles) with corners a, b, c, d (counter-clockwise seen from inside), UVs in
// metres along the edges (one checker texture period per 2 m).
inline Mesh MakeQuad(const std::string& name, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                     const Eigen::Vector3f& c, const Eigen::Vector3f& d, int material) {
  Mesh mesh;
  mesh.name = name;
  mesh.positions = {a, b, c, d};
  const float w = (b - a).norm() / 2.0f, h = (d - a).norm() / 2.0f;
  mesh.uvs = {{0.0f, 0.0f}, {w, 0.0f}, {w, h}, {0.0f, h}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.material = material;
  return mesh;
}

inline Mesh MakeCube(const std::string& name, float half, int material) {
  Mesh mesh;
  mesh.name = name;
  for (int i = 0; i < 8; ++i)
    mesh.positions.emplace_back((i & 1) ? half : -half, (i & 2) ? half : -half, (i & 4) ? half : -half);
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    mesh.triangles.emplace_back(f[0], f[1], f[2]);
    mesh.triangles.emplace_back(f[0], f[2], f[3]);
  }
  mesh.material = material;
  return mesh;
}

inline Scene MakeBoxScene(int frames, bool with_mover) {
  Scene scene;
  scene.metadata.preset = "test_box";
  scene.metadata.generator_version = "test";
  scene.metadata.seed = 7;
  scene.rig_preset = "omnimvs4";
  const float x0 = kRoomMin[0], y0 = kRoomMin[1], z0 = kRoomMin[2];
  const float x1 = kRoomMax[0], y1 = kRoomMax[1], z1 = kRoomMax[2];
  using V = Eigen::Vector3f;
  const V corners[6][4] = {
      {V(x0, y0, z0), V(x1, y0, z0), V(x1, y1, z0), V(x0, y1, z0)},  // floor
      {V(x0, y0, z1), V(x0, y1, z1), V(x1, y1, z1), V(x1, y0, z1)},  // ceiling
      {V(x0, y0, z0), V(x0, y1, z0), V(x0, y1, z1), V(x0, y0, z1)},  // x = -4
      {V(x1, y0, z0), V(x1, y0, z1), V(x1, y1, z1), V(x1, y1, z0)},  // x = +4
      {V(x0, y0, z0), V(x0, y0, z1), V(x1, y0, z1), V(x1, y0, z0)},  // y = -3
      {V(x0, y1, z0), V(x1, y1, z0), V(x1, y1, z1), V(x0, y1, z1)},  // y = +3
  };
  const char* names[6] = {"floor", "ceiling", "wall_xm", "wall_xp", "wall_ym", "wall_yp"};
  for (int f = 0; f < 6; ++f) {
    scene.textures.push_back(MakeChecker(std::string("checker_") + names[f], f));
    Material mat;
    mat.name = names[f];
    mat.base_color = Eigen::Vector3f(0.9f, 0.9f, 0.9f);
    mat.texture = f;
    scene.materials.push_back(mat);
    scene.meshes.push_back(MakeQuad(names[f], corners[f][0], corners[f][1], corners[f][2], corners[f][3], f));
    Object obj;
    obj.name = names[f];
    obj.mesh = f;
    obj.id = static_cast<uint16_t>(f + 1);
    scene.objects.push_back(obj);
  }
  if (with_mover) {
    Material mat;
    mat.name = "mover";
    mat.base_color = Eigen::Vector3f(0.8f, 0.1f, 0.1f);
    scene.materials.push_back(mat);
    scene.meshes.push_back(MakeCube("mover", static_cast<float>(kMoverHalf), 6));
    Object obj;
    obj.name = "mover";
    obj.mesh = 6;
    obj.id = 7;
    for (int i = 0; i < frames; ++i)
      obj.world_from_object_per_frame.push_back(Rigid3(Eigen::Quaterniond::Identity(), MoverCentre(i)));
    scene.objects.push_back(obj);
  }
  scene.lighting.direction_to_sun = Eigen::Vector3d(0.3, 0.2, 0.9);
  scene.frame_rate = 10.0;
  for (int i = 0; i < frames; ++i) {
    StampedPose pose;
    pose.timestamp = i / scene.frame_rate;
    pose.world_from_rig =
        Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitZ())), RigPosition(i));
    scene.rig_trajectory.push_back(pose);
  }
  return scene;
}

// Nearest hit of the ray origin + t * dir (t > 0) with the room's faces; returns t and the face id.
inline bool IntersectRoom(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double* t_out, int* face_out) {
  double best = std::numeric_limits<double>::infinity();
  int best_face = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (dir[axis] == 0.0) continue;
    for (int side = 0; side < 2; ++side) {
      const double plane = side == 0 ? kRoomMin[axis] : kRoomMax[axis];
      const double t = (plane - origin[axis]) / dir[axis];
      if (!(t > 0.0) || t >= best) continue;
      best = t;
      // Face ids: z -> 1/2, x -> 3/4, y -> 5/6.
      best_face = (axis == 2 ? 1 : axis == 0 ? 3 : 5) + side;
    }
  }
  if (!std::isfinite(best)) return false;
  *t_out = best;
  *face_out = best_face;
  return true;
}

// Ray against the axis-aligned mover cube centred at `centre` (slab test); t of entry.
inline bool IntersectCube(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Eigen::Vector3d& centre,
                          double half, double* t_out) {
  double t_near = -std::numeric_limits<double>::infinity(), t_far = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = centre[axis] - half, hi = centre[axis] + half;
    if (dir[axis] == 0.0) {
      if (origin[axis] < lo || origin[axis] > hi) return false;
      continue;
    }
    double ta = (lo - origin[axis]) / dir[axis], tb = (hi - origin[axis]) / dir[axis];
    if (ta > tb) std::swap(ta, tb);
    t_near = std::max(t_near, ta);
    t_far = std::min(t_far, tb);
  }
  if (t_near > t_far || t_near <= 0.0) return false;
  *t_out = t_near;
  return true;
}

}  // namespace rovo::testing
