// Scene folder writer (layout: scenes/FORMAT.md): textures as PNG, mesh arrays in geometry.bin,
// per-frame object poses in motion.bin, the rig trajectory, and scene.json last.

#include <tbb/parallel_for.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/image_file.h"
#include "datasets/io.h"
#include "rovo/version.h"
#include "scenes/scene.h"
#include "scenes/scene_io_internal.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace scene_io_internal;

json RigidToJson(const Rigid3& r) {
  const auto& q = r.rotation;
  return json{{"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
              {"translation", {r.translation.x(), r.translation.y(), r.translation.z()}}};
}

template <typename V>
json VecJson(const V& v) {
  json a = json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(static_cast<double>(v[i]));
  return a;
}

void AppendBytes(std::string& buffer, const void* data, size_t bytes) {
  buffer.append(static_cast<const char*>(data), bytes);
}

void WritePng(const std::string& path, const Texture& texture) {
  WritePng8(path, texture.width, texture.height, 3, texture.rgb, "rovo " ROVO_VERSION);
}

json LightsJson(const Scene& scene) {
  json lights = json::array();
  for (const Light& light : scene.lights) {
    if (light.object < -1 || light.object >= static_cast<int>(scene.objects.size())) {
      throw std::runtime_error("SaveScene: light '" + light.name + "': object index " + std::to_string(light.object) +
                               " out of range");
    }
    json jl = {{"name", light.name},
               {"position", VecJson(light.position)},
               {"intensity", VecJson(light.intensity)},
               {"range", light.range},
               {"object", light.object}};
    if (light.spot) {
      jl["spot"] = {{"direction", VecJson(light.spot_direction)},
                    {"angle_deg", light.spot_angle_deg},
                    {"blend", light.spot_blend}};
    }
    lights.push_back(jl);
  }
  return lights;
}

// scene.json's format, metadata, frame rate, rig preset, trajectory file and lighting.
json HeaderJson(const Scene& scene) {
  json root;
  root["format"] = "rovo-scene";
  root["format_version"] = kFormatVersion;
  root["metadata"] = {{"generator", scene.metadata.generator},
                      {"generator_version", scene.metadata.generator_version},
                      {"preset", scene.metadata.preset},
                      {"seed", scene.metadata.seed},
                      {"source", scene.metadata.source}};
  root["frame_rate"] = scene.frame_rate;
  root["rig_preset"] = scene.rig_preset;
  root["trajectory"] = kTrajectoryFile;
  const Lighting& l = scene.lighting;
  root["lighting"] = {{"preset", l.preset},
                      {"direction_to_sun", VecJson(l.direction_to_sun)},
                      {"sun_radiance", VecJson(l.sun_radiance)},
                      {"sun_angular_diameter_deg", l.sun_angular_diameter_deg},
                      {"sky_zenith", VecJson(l.sky_zenith)},
                      {"sky_horizon", VecJson(l.sky_horizon)},
                      {"ground_albedo", VecJson(l.ground_albedo)},
                      {"ambient", static_cast<double>(l.ambient)},
                      {"exposure", static_cast<double>(l.exposure)}};
  return root;
}

// Checks the textures, writes them as textures/NNN.png (in parallel) and returns their entries.
json WriteTextures(const Scene& scene, const std::string& dir) {
  json textures = json::array();
  std::vector<std::string> png_names(scene.textures.size());
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    if (t.width <= 0 || t.height <= 0 || t.rgb.size() != static_cast<size_t>(t.width) * t.height * 3) {
      throw std::runtime_error("SaveScene: texture " + std::to_string(i) + " ('" + t.name + "') has inconsistent size");
    }
    char name[64];
    std::snprintf(name, sizeof(name), "textures/%03zu.png", i);
    png_names[i] = name;
    textures.push_back({{"name", t.name}, {"file", name}, {"width", t.width}, {"height", t.height}});
  }
  // PNG encoding dominates saving; textures are independent files.
  tbb::parallel_for(size_t{0}, scene.textures.size(),
                    [&](size_t i) { WritePng((fs::path(dir) / png_names[i]).string(), scene.textures[i]); });
  return textures;
}

json MaterialsJson(const Scene& scene) {
  json materials = json::array();
  for (const Material& m : scene.materials) {
    json jm = {{"name", m.name}, {"base_color", VecJson(m.base_color)}, {"texture", m.texture}};
    // Optional fields are written only when set, so matte scenes keep their exact scene.json.
    if (m.IsEmissive()) jm["emission"] = VecJson(m.emission);
    if (m.specular > 0.0f) {
      jm["specular"] = static_cast<double>(m.specular);
      jm["shininess"] = static_cast<double>(m.shininess);
    }
    materials.push_back(jm);
  }
  return materials;
}

// Appends every mesh's arrays to `geometry` and returns the meshes' entries (offsets into it).
json MeshesJson(const Scene& scene, std::string& geometry) {
  json meshes = json::array();
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& m = scene.meshes[i];
    const size_t nv = m.positions.size(), nt = m.triangles.size();
    if (!m.uvs.empty() && m.uvs.size() != nv)
      throw std::runtime_error("SaveScene: mesh '" + m.name + "': uvs size != positions size");
    if (!m.triangle_materials.empty() && m.triangle_materials.size() != nt) {
      throw std::runtime_error("SaveScene: mesh '" + m.name + "': triangle_materials size != triangles size");
    }
    json jm = {{"name", m.name},
               {"material", m.material},
               {"buffer", kGeometryFile},
               {"vertex_count", nv},
               {"triangle_count", nt}};
    jm["positions_offset"] = geometry.size();
    AppendBytes(geometry, m.positions.data(), nv * 3 * sizeof(float));
    if (m.uvs.empty()) {
      jm["uvs_offset"] = -1;
    } else {
      jm["uvs_offset"] = geometry.size();
      AppendBytes(geometry, m.uvs.data(), nv * 2 * sizeof(float));
    }
    jm["triangles_offset"] = geometry.size();
    AppendBytes(geometry, m.triangles.data(), nt * 3 * sizeof(int32_t));
    if (m.triangle_materials.empty()) {
      jm["triangle_materials_offset"] = -1;
    } else {
      jm["triangle_materials_offset"] = geometry.size();
      AppendBytes(geometry, m.triangle_materials.data(), nt * sizeof(int32_t));
    }
    meshes.push_back(jm);
  }
  return meshes;
}

// Appends every dynamic object's per-frame poses to `motion` and returns the objects' entries.
json ObjectsJson(const Scene& scene, int frames, std::string& motion) {
  json objects = json::array();
  for (const Object& o : scene.objects) {
    json jo = {{"name", o.name}, {"mesh", o.mesh}, {"id", o.id}};
    if (o.IsDynamic()) {
      if (static_cast<int>(o.world_from_object_per_frame.size()) != frames) {
        throw std::runtime_error("SaveScene: object '" + o.name + "' has " +
                                 std::to_string(o.world_from_object_per_frame.size()) + " transforms for " +
                                 std::to_string(frames) + " frames");
      }
      jo["motion"] = {{"buffer", kMotionFile}, {"offset", motion.size()}, {"frames", frames}};
      for (const Rigid3& r : o.world_from_object_per_frame) {
        const double rec[7] = {r.rotation.x(),    r.rotation.y(),    r.rotation.z(),   r.rotation.w(),
                               r.translation.x(), r.translation.y(), r.translation.z()};
        AppendBytes(motion, rec, sizeof(rec));
      }
    } else {
      jo["world_from_object"] = RigidToJson(o.world_from_object);
    }
    objects.push_back(jo);
  }
  return objects;
}

}  // namespace

void SaveScene(const Scene& scene, const std::string& dir) {
  if (!HostIsLittleEndian()) throw std::runtime_error("SaveScene: big-endian hosts are not supported");
  EnsureWritableDir(dir);
  EnsureWritableDir((fs::path(dir) / "textures").string());
  const int frames = static_cast<int>(scene.rig_trajectory.size());

  json root = HeaderJson(scene);
  root["textures"] = WriteTextures(scene, dir);
  root["materials"] = MaterialsJson(scene);
  std::string geometry;
  root["meshes"] = MeshesJson(scene, geometry);
  std::string motion;
  root["objects"] = ObjectsJson(scene, frames, motion);
  if (!scene.lights.empty()) root["lights"] = LightsJson(scene);

  WriteFileAtomic((fs::path(dir) / kGeometryFile).string(), geometry);
  WriteFileAtomic((fs::path(dir) / kMotionFile).string(), motion);
  WriteFileAtomic((fs::path(dir) / kTrajectoryFile).string(), FormatTum(scene.rig_trajectory));
  // scene.json last: a folder with a scene.json is complete.
  WriteJsonFileAtomic((fs::path(dir) / "scene.json").string(), root);
}

}  // namespace rovo
