// The scene's content hash: every field that reaches a rendered image, in a fixed order.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "datasets/io.h"
#include "scenes/scene.h"

namespace rovo {
namespace {

class Hasher {
 public:
  void Bytes(const void* data, size_t size) {
    state_ = std::strtoull(HashHex(data, size, state_).c_str(), nullptr, 16);
  }
  void Str(const std::string& s) {
    U64(s.size());
    Bytes(s.data(), s.size());
  }
  void U64(uint64_t v) { Bytes(&v, sizeof(v)); }
  void F64(double v) { Bytes(&v, sizeof(v)); }
  void Rigid(const Rigid3& r) {
    const double q[4] = {r.rotation.x(), r.rotation.y(), r.rotation.z(), r.rotation.w()};
    Bytes(q, sizeof(q));
    Bytes(r.translation.data(), sizeof(double) * 3);
  }
  template <typename T>
  void Vec(const std::vector<T>& v) {
    U64(v.size());
    if (!v.empty()) Bytes(v.data(), v.size() * sizeof(T));
  }
  std::string Hex() const {
    char buf[17];
    std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(state_));
    return buf;
  }

 private:
  uint64_t state_ = 0;
};

// Metadata, frame rate, rig preset and lighting.
void HashHeader(const Scene& scene, Hasher& h) {
  h.Str("rovo-scene-1");
  h.Str(scene.metadata.generator);
  h.Str(scene.metadata.preset);
  h.U64(scene.metadata.seed);
  h.Str(scene.metadata.source);
  h.F64(scene.frame_rate);
  h.Str(scene.rig_preset);
  const Lighting& l = scene.lighting;
  h.Str(l.preset);
  h.Bytes(l.direction_to_sun.data(), sizeof(double) * 3);
  h.Bytes(l.sun_radiance.data(), sizeof(float) * 3);
  h.F64(l.sun_angular_diameter_deg);
  h.Bytes(l.sky_zenith.data(), sizeof(float) * 3);
  h.Bytes(l.sky_horizon.data(), sizeof(float) * 3);
  h.Bytes(l.ground_albedo.data(), sizeof(float) * 3);
  h.Bytes(&l.ambient, sizeof(float));
  h.Bytes(&l.exposure, sizeof(float));
}

void HashTexturesAndMaterials(const Scene& scene, Hasher& h) {
  h.U64(scene.textures.size());
  for (const Texture& t : scene.textures) {
    h.Str(t.name);
    h.U64(static_cast<uint64_t>(t.width));
    h.U64(static_cast<uint64_t>(t.height));
    h.Vec(t.rgb);
  }
  h.U64(scene.materials.size());
  for (const Material& m : scene.materials) {
    h.Str(m.name);
    h.Bytes(m.base_color.data(), sizeof(float) * 3);
    h.U64(static_cast<uint64_t>(static_cast<int64_t>(m.texture)));
    // Emission and specular enter only when set (matte scenes keep their hash).
    if (m.IsEmissive()) h.Bytes(m.emission.data(), sizeof(float) * 3);
    if (m.specular > 0.0f) {
      h.Bytes(&m.specular, sizeof(float));
      h.Bytes(&m.shininess, sizeof(float));
    }
  }
}

// Meshes and objects (static poses or one pose per frame).
void HashGeometry(const Scene& scene, Hasher& h) {
  h.U64(scene.meshes.size());
  for (const Mesh& m : scene.meshes) {
    h.Str(m.name);
    h.U64(static_cast<uint64_t>(m.material));
    h.Vec(m.positions);
    h.Vec(m.uvs);
    h.Vec(m.triangles);
    h.Vec(m.triangle_materials);
  }
  h.U64(scene.objects.size());
  for (const Object& o : scene.objects) {
    h.Str(o.name);
    h.U64(static_cast<uint64_t>(o.mesh));
    h.U64(o.id);
    h.U64(o.IsDynamic() ? 1 : 0);
    if (o.IsDynamic()) {
      h.U64(o.world_from_object_per_frame.size());
      for (const Rigid3& r : o.world_from_object_per_frame) h.Rigid(r);
    } else {
      h.Rigid(o.world_from_object);
    }
  }
}

void HashTrajectory(const Scene& scene, Hasher& h) {
  h.U64(scene.rig_trajectory.size());
  for (const StampedPose& p : scene.rig_trajectory) {
    h.F64(p.timestamp);
    h.Rigid(p.world_from_rig);
  }
}

void HashLights(const Scene& scene, Hasher& h) {
  if (!scene.lights.empty()) {  // scenes without lights keep their hash
    h.U64(scene.lights.size());
    for (const Light& l : scene.lights) {
      h.Str(l.name);
      h.Bytes(l.position.data(), sizeof(double) * 3);
      h.Bytes(l.intensity.data(), sizeof(float) * 3);
      h.F64(l.range);
      h.U64(static_cast<uint64_t>(static_cast<int64_t>(l.object)));
      h.U64(l.spot ? 1 : 0);
      if (l.spot) {
        h.Bytes(l.spot_direction.data(), sizeof(double) * 3);
        h.F64(l.spot_angle_deg);
        h.F64(l.spot_blend);
      }
    }
  }
}

}  // namespace

std::string SceneHash(const Scene& scene) {
  Hasher h;
  HashHeader(scene, h);
  HashTexturesAndMaterials(scene, h);
  HashGeometry(scene, h);
  HashTrajectory(scene, h);
  HashLights(scene, h);
  return h.Hex();
}

}  // namespace rovo
