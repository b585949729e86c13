#pragma once
// The in-memory scene shared by scenes/ (which makes, loads and saves it) and render/ (which
// traces it). On-disk layout: scenes/FORMAT.md.
//
// World frame: REP-103 (x east/forward, y left, z up), metres. Object transforms are named
// world_from_object. Dynamic objects carry one transform per frame, at the same frame times as the
// rig trajectory.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "datasets/rigid3.h"
#include "datasets/trajectory.h"

namespace rovo {

// 8-bit sRGB texture, row-major, 3 bytes per pixel, row 0 at v = 0 (top of the image file).
struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
};

struct Material {
  std::string name;
  Eigen::Vector3f base_color{0.8f, 0.8f, 0.8f};  // linear RGB albedo (multiplies the texture)
  int texture = -1;                              // index into Scene::textures, -1 for none
  Eigen::Vector3f emission{0.0f, 0.0f, 0.0f};    // linear RGB radiance the surface emits (lamps)
  float specular = 0.0f;   // Blinn-Phong highlight of point lights: reflectance in [0, 1], 0 = matte
  float shininess = 0.0f;  // Blinn-Phong exponent (> 0 when specular > 0)
  bool IsEmissive() const { return emission.x() > 0.0f || emission.y() > 0.0f || emission.z() > 0.0f; }
};

// Triangle mesh in its object frame.
struct Mesh {
  std::string name;
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector2f> uvs;         // per vertex, or empty (no texture lookup)
  std::vector<Eigen::Vector3i> triangles;   // vertex indices, counter-clockwise
  std::vector<int32_t> triangle_materials;  // per triangle; empty: all use `material`
  int material = 0;                         // index into Scene::materials
};

struct Object {
  std::string name;
  int mesh = -1;                                    // index into Scene::meshes
  uint16_t id = 0;                                  // mask id; 0 = static background, >0 = dynamic object
  Rigid3 world_from_object;                         // used when frames is empty (static objects)
  std::vector<Rigid3> world_from_object_per_frame;  // dynamic objects: one per rig frame
  bool IsDynamic() const { return !world_from_object_per_frame.empty(); }
};

struct Lighting {
  std::string preset = "sunny";                     // "sunny", "cloudy", "sunset", or custom
  Eigen::Vector3d direction_to_sun{0.3, 0.2, 0.9};  // in world, need not be normalized
  Eigen::Vector3f sun_radiance{3.0f, 2.9f, 2.7f};   // linear RGB irradiance on a facing surface
  double sun_angular_diameter_deg = 0.53;           // > 0 gives soft shadows when sampled
  Eigen::Vector3f sky_zenith{0.25f, 0.45f, 0.9f};   // linear RGB radiance of the sky dome
  Eigen::Vector3f sky_horizon{0.7f, 0.8f, 0.95f};
  Eigen::Vector3f ground_albedo{0.3f, 0.3f, 0.3f};
  float ambient = 0.35f;  // sky/ambient light scale
  float exposure = 1.0f;  // linear scale before the sRGB curve
};

// A point light, optionally a spot (render/tracer.h gives the shading formula). Intensity is a
// radiant intensity in linear RGB (W/sr-like): a surface facing the light at distance d receives the
// irradiance intensity / d^2. A light with `object` >= 0 rides on that object: `position` and
// `spot_direction` are then in the object's frame and follow it from frame to frame.
struct Light {
  std::string name;
  Eigen::Vector3d position{0.0, 0.0, 0.0};         // world, or object frame when object >= 0
  Eigen::Vector3f intensity{0.0f, 0.0f, 0.0f};     // linear RGB radiant intensity (Blender power / 4 pi)
  double range = 0.0;                              // > 0: smooth cut-off, no light at d >= range; 0: none
  int object = -1;                                 // index into Scene::objects, -1 for a world-fixed light
  bool spot = false;                               // a cone instead of all directions
  Eigen::Vector3d spot_direction{0.0, 0.0, -1.0};  // cone axis (world or object frame), need not be unit
  double spot_angle_deg = 45.0;                    // full cone angle in (0, 180]
  double spot_blend = 0.0;                         // softness of the cone edge in [0, 1]
};

struct SceneMetadata {
  std::string generator = "rovo";
  std::string generator_version;
  std::string preset;  // procedural preset or "blender"
  uint64_t seed = 0;
  std::string source;  // e.g. the .blend file
};

struct Scene {
  SceneMetadata metadata;
  std::vector<Texture> textures;
  std::vector<Material> materials;
  std::vector<Mesh> meshes;
  std::vector<Object> objects;
  Lighting lighting;
  std::vector<Light> lights;  // point and spot lights besides the sun and sky (may be empty)
  double frame_rate = 10.0;
  Trajectory rig_trajectory;  // world_from_rig per frame (the ground truth)
  std::string rig_preset;     // rig the scene was made for ("" = caller chooses)
};

// Load/save the on-disk scene (scenes/FORMAT.md). Throw std::runtime_error naming file and field.
Scene LoadScene(const std::string& dir);
void SaveScene(const Scene& scene, const std::string& dir);
// Content hash of the scene (geometry, materials, textures, lighting, trajectory).
std::string SceneHash(const Scene& scene);

}  // namespace rovo
