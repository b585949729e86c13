// Scene folder reader (layout: scenes/FORMAT.md); every error names the file and the field.

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/image_file.h"
#include "datasets/io.h"
#include "scenes/scene.h"
#include "scenes/scene_io_internal.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace scene_io_internal;

[[noreturn]] void Fail(const std::string& file, const std::string& field, const std::string& what) {
  throw std::runtime_error(file + ": " + field + ": " + what);
}

// Typed access to a JSON field with errors that name the file and the field path.
class Field {
 public:
  Field(const json& value, std::string file, std::string path)
      : value_(value), file_(std::move(file)), path_(std::move(path)) {}

  Field operator[](const char* key) const {
    if (!value_.is_object()) Fail(file_, path_, "expected an object");
    const std::string sub = path_.empty() ? key : path_ + "." + key;
    auto it = value_.find(key);
    if (it == value_.end()) Fail(file_, sub, "missing");
    return Field(*it, file_, sub);
  }
  bool Has(const char* key) const { return value_.is_object() && value_.contains(key); }
  Field operator[](size_t i) const { return Field(value_.at(i), file_, path_ + "[" + std::to_string(i) + "]"); }
  size_t ArraySize() const {
    if (!value_.is_array()) Fail(file_, path_, "expected an array");
    return value_.size();
  }
  double Number() const {
    if (!value_.is_number()) Fail(file_, path_, "expected a number");
    const double v = value_.get<double>();
    if (!std::isfinite(v)) Fail(file_, path_, "not finite");
    return v;
  }
  int64_t Int(int64_t lo, int64_t hi) const {
    if (!value_.is_number_integer()) Fail(file_, path_, "expected an integer");
    const int64_t v =
        value_.is_number_unsigned() ? static_cast<int64_t>(value_.get<uint64_t>()) : value_.get<int64_t>();
    if (v < lo || v > hi) {
      Fail(file_, path_,
           "value " + std::to_string(v) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return v;
  }
  uint64_t UInt64() const {
    if (!value_.is_number_unsigned() && !(value_.is_number_integer() && value_.get<int64_t>() >= 0)) {
      Fail(file_, path_, "expected a non-negative integer");
    }
    return value_.get<uint64_t>();
  }
  std::string String() const {
    if (!value_.is_string()) Fail(file_, path_, "expected a string");
    return value_.get<std::string>();
  }
  template <int N>
  Eigen::Matrix<double, N, 1> Vector() const {
    if (ArraySize() != N) Fail(file_, path_, "expected " + std::to_string(N) + " numbers");
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = (*this)[static_cast<size_t>(i)].Number();
    return v;
  }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }

 private:
  const json& value_;
  std::string file_, path_;
};

// Unit quaternion from stored x, y, z, w; normalizes only when not unit to 1e-9 (bit-exact round trips).
Eigen::Quaterniond QuaternionFromXyzw(double x, double y, double z, double w, const std::string& file,
                                      const std::string& field) {
  Eigen::Quaterniond q(w, x, y, z);
  const double n = q.norm();
  if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-3)
    Fail(file, field, "quaternion is not unit (norm " + std::to_string(n) + ")");
  if (std::abs(n - 1.0) > 1e-9) q.coeffs() /= n;
  return q;
}

Rigid3 RigidFromJson(const Field& f) {
  const Eigen::Vector4d q = f["rotation_xyzw"].Vector<4>();
  Rigid3 out;
  out.rotation = QuaternionFromXyzw(q[0], q[1], q[2], q[3], f.file(), f.path() + ".rotation_xyzw");
  out.translation = f["translation"].Vector<3>();
  return out;
}

// ---- TUM: datasets' parser, our quaternion handling (bit-exact round trips) ----

Trajectory ParseSceneTum(const std::string& path) {
  Trajectory out;
  for (const TumLine& line : ParseTumText(ReadFile(path), path)) {
    const double* v = line.values;
    StampedPose pose;
    pose.timestamp = v[0];
    pose.world_from_rig.translation = Eigen::Vector3d(v[1], v[2], v[3]);
    pose.world_from_rig.rotation =
        QuaternionFromXyzw(v[4], v[5], v[6], v[7], path, "line " + std::to_string(line.line_number));
    out.push_back(pose);
  }
  return out;
}

class BufferCache {
 public:
  explicit BufferCache(std::string dir) : dir_(std::move(dir)) {}
  const std::string& Get(const std::string& name, const std::string& json_file, const std::string& field) {
    auto it = files_.find(name);
    if (it != files_.end()) return it->second;
    if (name.empty() || name.find("..") != std::string::npos || name[0] == '/') {
      Fail(json_file, field, "buffer name '" + name + "' must be a relative path inside the scene folder");
    }
    const std::string path = (fs::path(dir_) / name).string();
    if (!fs::exists(path)) Fail(json_file, field, "buffer file '" + path + "' does not exist");
    return files_.emplace(name, ReadFile(path)).first->second;
  }

 private:
  std::string dir_;
  std::map<std::string, std::string> files_;
};

// Copies `count` elements of `elem_bytes` from the buffer at `offset`, checking the range.
void CopyFromBuffer(const std::string& buffer, int64_t offset, size_t count, size_t elem_bytes, void* dst,
                    const std::string& json_file, const std::string& field, const std::string& buffer_name) {
  const size_t bytes = count * elem_bytes;
  if (offset < 0 || offset % 4 != 0) Fail(json_file, field, "offset must be a non-negative multiple of 4");
  if (static_cast<size_t>(offset) + bytes > buffer.size()) {
    Fail(json_file, field,
         "range [" + std::to_string(offset) + ", " + std::to_string(offset + bytes) + ") exceeds buffer '" +
             buffer_name + "' of " + std::to_string(buffer.size()) + " bytes");
  }
  if (bytes > 0) std::memcpy(dst, buffer.data() + offset, bytes);
}

// ---- textures ----

void ReadPng(const std::string& path, Texture& texture, const std::string& json_file, const std::string& field) {
  Image8 image;
  try {
    image = ReadPng8(path, {3, true});  // gray (+ alpha) replicated, alpha dropped
  } catch (const std::runtime_error& e) {
    Fail(json_file, field, std::string("cannot read texture: ") + e.what());
  }
  if (image.width != texture.width || image.height != texture.height) {
    Fail(json_file, field,
         "texture '" + path + "' is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
             ", scene.json says " + std::to_string(texture.width) + "x" + std::to_string(texture.height));
  }
  texture.rgb = std::move(image.pixels);
}

// ---- scene.json sections ----

// scene.json's metadata, frame rate, rig preset and lighting.
void ReadSceneHeader(const Field& root, const std::string& file, Scene* scene) {
  const Field meta = root["metadata"];
  scene->metadata.generator = meta["generator"].String();
  scene->metadata.generator_version = meta["generator_version"].String();
  scene->metadata.preset = meta["preset"].String();
  scene->metadata.seed = meta["seed"].UInt64();
  scene->metadata.source = meta["source"].String();
  scene->frame_rate = root["frame_rate"].Number();
  if (!(scene->frame_rate > 0)) Fail(file, "frame_rate", "must be positive");
  scene->rig_preset = root["rig_preset"].String();

  const Field jl = root["lighting"];
  Lighting& l = scene->lighting;
  l.preset = jl["preset"].String();
  l.direction_to_sun = jl["direction_to_sun"].Vector<3>();
  l.sun_radiance = jl["sun_radiance"].Vector<3>().cast<float>();
  l.sun_angular_diameter_deg = jl["sun_angular_diameter_deg"].Number();
  l.sky_zenith = jl["sky_zenith"].Vector<3>().cast<float>();
  l.sky_horizon = jl["sky_horizon"].Vector<3>().cast<float>();
  l.ground_albedo = jl["ground_albedo"].Vector<3>().cast<float>();
  l.ambient = static_cast<float>(jl["ambient"].Number());
  l.exposure = static_cast<float>(jl["exposure"].Number());
}

// The texture list and the PNGs it names.
void ReadTextures(const Field& root, const std::string& dir, const std::string& file, Scene* scene) {
  const Field jt = root["textures"];
  scene->textures.resize(jt.ArraySize());
  std::vector<std::string> png_paths(scene->textures.size());
  for (size_t i = 0; i < scene->textures.size(); ++i) {
    const Field f = jt[i];
    Texture& t = scene->textures[i];
    t.name = f["name"].String();
    t.width = static_cast<int>(f["width"].Int(1, 1 << 16));
    t.height = static_cast<int>(f["height"].Int(1, 1 << 16));
    const std::string png = f["file"].String();
    if (png.empty() || png[0] == '/' || png.find("..") != std::string::npos) {
      Fail(file, f.path() + ".file", "must be a relative path inside the scene folder");
    }
    png_paths[i] = (fs::path(dir) / png).string();
  }
  // PNG decoding dominates loading; the first failure (by TBB's rules) is rethrown here.
  tbb::parallel_for(size_t{0}, scene->textures.size(), [&](size_t i) {
    ReadPng(png_paths[i], scene->textures[i], file, "textures[" + std::to_string(i) + "].file");
  });
}

void ReadMaterials(const Field& root, Scene* scene) {
  const Field jmat = root["materials"];
  scene->materials.resize(jmat.ArraySize());
  for (size_t i = 0; i < scene->materials.size(); ++i) {
    const Field f = jmat[i];
    Material& m = scene->materials[i];
    m.name = f["name"].String();
    m.base_color = f["base_color"].Vector<3>().cast<float>();
    m.texture = static_cast<int>(f["texture"].Int(-1, static_cast<int64_t>(scene->textures.size()) - 1));
    if (f.Has("emission")) {
      m.emission = f["emission"].Vector<3>().cast<float>();
      if (m.emission.minCoeff() < 0.0f) Fail(f.file(), f.path() + ".emission", "must not be negative");
    }
    if (f.Has("specular")) {
      const double specular = f["specular"].Number();
      if (specular < 0.0 || specular > 1.0) Fail(f.file(), f.path() + ".specular", "must be in [0, 1]");
      m.specular = static_cast<float>(specular);
      const double shininess = f["shininess"].Number();
      if (specular > 0.0 && !(shininess > 0.0)) Fail(f.file(), f.path() + ".shininess", "must be positive");
      m.shininess = static_cast<float>(shininess);
    }
  }
}

// /lights (optional): point and spot lights; read after the objects they may ride on.
void ReadLights(const Field& root, Scene* scene) {
  if (!root.Has("lights")) return;
  const Field jl = root["lights"];
  scene->lights.resize(jl.ArraySize());
  for (size_t i = 0; i < scene->lights.size(); ++i) {
    const Field f = jl[i];
    Light& l = scene->lights[i];
    l.name = f["name"].String();
    l.position = f["position"].Vector<3>();
    l.intensity = f["intensity"].Vector<3>().cast<float>();
    if (l.intensity.minCoeff() < 0.0f) Fail(f.file(), f.path() + ".intensity", "must not be negative");
    l.range = f["range"].Number();
    if (l.range < 0.0) Fail(f.file(), f.path() + ".range", "must not be negative (0: no cut-off)");
    l.object = static_cast<int>(f["object"].Int(-1, static_cast<int64_t>(scene->objects.size()) - 1));
    if (!f.Has("spot")) continue;
    const Field fs = f["spot"];
    l.spot = true;
    l.spot_direction = fs["direction"].Vector<3>();
    if (!(l.spot_direction.norm() > 0.0)) Fail(f.file(), fs.path() + ".direction", "must not be zero");
    l.spot_angle_deg = fs["angle_deg"].Number();
    if (!(l.spot_angle_deg > 0.0 && l.spot_angle_deg <= 180.0))
      Fail(f.file(), fs.path() + ".angle_deg", "must be in (0, 180]");
    l.spot_blend = fs["blend"].Number();
    if (l.spot_blend < 0.0 || l.spot_blend > 1.0) Fail(f.file(), fs.path() + ".blend", "must be in [0, 1]");
  }
}

// One mesh of /meshes: its arrays from the named buffer, checked (finite vertices, indices in range).
Mesh ReadMesh(const Field& f, BufferCache& buffers, const std::string& file, int64_t num_materials) {
  Mesh m;
  m.name = f["name"].String();
  m.material = static_cast<int>(f["material"].Int(0, num_materials - 1));
  const std::string buffer_name = f["buffer"].String();
  const std::string& buffer = buffers.Get(buffer_name, file, f.path() + ".buffer");
  const int64_t nv = f["vertex_count"].Int(0, INT32_MAX);
  const int64_t nt = f["triangle_count"].Int(0, INT32_MAX);
  // Counts the buffer cannot hold fail before anything is allocated for them.
  if (static_cast<size_t>(nv) * 3 * sizeof(float) > buffer.size()) {
    Fail(file, f.path() + ".vertex_count",
         std::to_string(nv) + " vertices do not fit in buffer '" + buffer_name + "' of " +
             std::to_string(buffer.size()) + " bytes");
  }
  if (static_cast<size_t>(nt) * 3 * sizeof(int32_t) > buffer.size()) {
    Fail(file, f.path() + ".triangle_count",
         std::to_string(nt) + " triangles do not fit in buffer '" + buffer_name + "' of " +
             std::to_string(buffer.size()) + " bytes");
  }
  m.positions.resize(nv);
  CopyFromBuffer(buffer, f["positions_offset"].Int(0, INT64_MAX), nv, 3 * sizeof(float), m.positions.data(), file,
                 f.path() + ".positions_offset", buffer_name);
  const int64_t uv_offset = f["uvs_offset"].Int(-1, INT64_MAX);
  if (uv_offset >= 0) {
    m.uvs.resize(nv);
    CopyFromBuffer(buffer, uv_offset, nv, 2 * sizeof(float), m.uvs.data(), file, f.path() + ".uvs_offset", buffer_name);
  }
  m.triangles.resize(nt);
  CopyFromBuffer(buffer, f["triangles_offset"].Int(0, INT64_MAX), nt, 3 * sizeof(int32_t), m.triangles.data(), file,
                 f.path() + ".triangles_offset", buffer_name);
  const int64_t tm_offset = f["triangle_materials_offset"].Int(-1, INT64_MAX);
  if (tm_offset >= 0) {
    m.triangle_materials.resize(nt);
    CopyFromBuffer(buffer, tm_offset, nt, sizeof(int32_t), m.triangle_materials.data(), file,
                   f.path() + ".triangle_materials_offset", buffer_name);
  }
  for (size_t k = 0; k < m.positions.size(); ++k) {
    if (!m.positions[k].allFinite())
      Fail(file, f.path() + ".positions_offset", "vertex " + std::to_string(k) + " is not finite");
  }
  for (size_t k = 0; k < m.triangles.size(); ++k) {
    const Eigen::Vector3i& tri = m.triangles[k];
    if (tri.minCoeff() < 0 || tri.maxCoeff() >= nv) {
      Fail(file, f.path() + ".triangles_offset",
           "triangle " + std::to_string(k) + " has a vertex index outside [0, " + std::to_string(nv) + ")");
    }
  }
  for (size_t k = 0; k < m.triangle_materials.size(); ++k) {
    if (m.triangle_materials[k] < 0 || m.triangle_materials[k] >= num_materials) {
      Fail(file, f.path() + ".triangle_materials_offset",
           "triangle " + std::to_string(k) + " has material " + std::to_string(m.triangle_materials[k]) +
               " outside [0, " + std::to_string(num_materials) + ")");
    }
  }
  return m;
}

// One object of /objects: a static pose or `frames` poses from a motion buffer.
Object ReadObject(const Field& f, BufferCache& buffers, const std::string& file, int64_t num_meshes, int64_t frames) {
  Object o;
  o.name = f["name"].String();
  o.mesh = static_cast<int>(f["mesh"].Int(0, num_meshes - 1));
  o.id = static_cast<uint16_t>(f["id"].Int(0, 65535));
  const bool has_static = f.Has("world_from_object"), has_motion = f.Has("motion");
  if (has_static == has_motion) Fail(file, f.path(), "needs exactly one of world_from_object or motion");
  if (has_static) {
    o.world_from_object = RigidFromJson(f["world_from_object"]);
    return o;
  }
  const Field fm = f["motion"];
  const std::string buffer_name = fm["buffer"].String();
  const std::string& buffer = buffers.Get(buffer_name, file, fm.path() + ".buffer");
  const int64_t n = fm["frames"].Int(1, INT32_MAX);
  if (n != frames) {
    Fail(file, fm.path() + ".frames",
         std::to_string(n) + " transforms but the trajectory has " + std::to_string(frames) + " poses");
  }
  std::vector<double> rec(static_cast<size_t>(n) * 7);
  CopyFromBuffer(buffer, fm["offset"].Int(0, INT64_MAX), static_cast<size_t>(n), 7 * sizeof(double), rec.data(), file,
                 fm.path() + ".offset", buffer_name);
  o.world_from_object_per_frame.resize(n);
  for (int64_t k = 0; k < n; ++k) {
    const double* r = &rec[k * 7];
    Rigid3& x = o.world_from_object_per_frame[k];
    x.rotation = QuaternionFromXyzw(r[0], r[1], r[2], r[3], file, fm.path() + " frame " + std::to_string(k));
    x.translation = Eigen::Vector3d(r[4], r[5], r[6]);
    if (!x.translation.allFinite()) Fail(file, fm.path(), "frame " + std::to_string(k) + " translation is not finite");
  }
  return o;
}

}  // namespace

Scene LoadScene(const std::string& dir) {
  if (!HostIsLittleEndian()) throw std::runtime_error("LoadScene: big-endian hosts are not supported");
  const std::string file = (fs::path(dir) / "scene.json").string();
  const json doc = ReadJsonFile(file);
  const Field root(doc, file, "");
  if (root["format"].String() != "rovo-scene") Fail(file, "format", "expected \"rovo-scene\"");
  const int64_t version = root["format_version"].Int(1, 1000);
  if (version != kFormatVersion) Fail(file, "format_version", "unsupported version " + std::to_string(version));

  Scene scene;
  ReadSceneHeader(root, file, &scene);
  const std::string trajectory_name = root["trajectory"].String();
  const std::string trajectory_path = (fs::path(dir) / trajectory_name).string();
  if (!fs::exists(trajectory_path)) Fail(file, "trajectory", "file '" + trajectory_path + "' does not exist");
  scene.rig_trajectory = ParseSceneTum(trajectory_path);
  const int64_t frames = static_cast<int64_t>(scene.rig_trajectory.size());
  ReadTextures(root, dir, file, &scene);
  ReadMaterials(root, &scene);

  BufferCache buffers(dir);
  const Field jmesh = root["meshes"];
  scene.meshes.resize(jmesh.ArraySize());
  for (size_t i = 0; i < scene.meshes.size(); ++i)
    scene.meshes[i] = ReadMesh(jmesh[i], buffers, file, static_cast<int64_t>(scene.materials.size()));
  const Field jo = root["objects"];
  scene.objects.resize(jo.ArraySize());
  for (size_t i = 0; i < scene.objects.size(); ++i)
    scene.objects[i] = ReadObject(jo[i], buffers, file, static_cast<int64_t>(scene.meshes.size()), frames);
  ReadLights(root, &scene);
  return scene;
}

}  // namespace rovo
