// The tracer's scene build: index checks, shading records, the static and dynamic Embree
// scenes, and the placement of moving objects at a frame or over a frame's time window.
#include <tbb/parallel_for.h>

#include <chrono>
#include <exception>
#include <vector>

#include "render/timing.h"
#include "render/tracer_internal.h"

namespace rovo {

namespace {

// Index checks before anything is built: bad input fails with a message naming the culprit.
void ValidateSceneIndices(const Scene& scene) {
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    const std::string what = "mesh '" + mesh.name + "'";
    if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
      throw std::invalid_argument(what + ": uvs has " + std::to_string(mesh.uvs.size()) + " entries for " +
                                  std::to_string(mesh.positions.size()) + " positions");
    if (!mesh.triangle_materials.empty() && mesh.triangle_materials.size() != mesh.triangles.size())
      throw std::invalid_argument(what + ": triangle_materials size differs from triangles");
    for (const Eigen::Vector3i& tri : mesh.triangles)
      for (int k = 0; k < 3; ++k)
        if (tri[k] < 0 || tri[k] >= static_cast<int>(mesh.positions.size()))
          throw std::invalid_argument(what + ": triangle vertex index " + std::to_string(tri[k]) + " out of range");
    auto check_material = [&](int mat) {
      if (mat < 0 || mat >= static_cast<int>(scene.materials.size()))
        throw std::invalid_argument(what + ": material index " + std::to_string(mat) + " out of range");
    };
    check_material(mesh.material);
    for (int32_t mat : mesh.triangle_materials) check_material(mat);
  }
  for (const Material& mat : scene.materials)
    if (mat.texture >= static_cast<int>(scene.textures.size()) || mat.texture < -1)
      throw std::invalid_argument("material '" + mat.name + "': texture index " + std::to_string(mat.texture) +
                                  " out of range");
  for (const Object& obj : scene.objects)
    if (obj.mesh < 0 || obj.mesh >= static_cast<int>(scene.meshes.size()))
      throw std::invalid_argument("object '" + obj.name + "': mesh index " + std::to_string(obj.mesh) +
                                  " out of range");
}

}  // namespace

RTCGeometry Tracer::Impl::MakeTriangles(const Mesh& mesh, const Rigid3* world_from_object, RTCBuildQuality quality) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  float* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                3 * sizeof(float), mesh.positions.size()));
  const Eigen::Matrix3f rot = world_from_object ? Eigen::Matrix3f(world_from_object->RotationMatrix().cast<float>())
                                                : Eigen::Matrix3f(Eigen::Matrix3f::Identity());
  const Eigen::Vector3f trans =
      world_from_object ? tracer_internal::ToF(world_from_object->translation) : Eigen::Vector3f::Zero();
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Eigen::Vector3f p = rot * mesh.positions[i] + trans;
    vertices[3 * i + 0] = p.x();
    vertices[3 * i + 1] = p.y();
    vertices[3 * i + 2] = p.z();
  }
  unsigned* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                     3 * sizeof(unsigned), mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = static_cast<unsigned>(mesh.triangles[i][k]);
  }
  rtcSetGeometryBuildQuality(geom, quality);
  rtcCommitGeometry(geom);
  return geom;
}

// Textures, per-triangle shading records (UV-to-object area ratio; rigid transforms keep areas),
// the per-object and per-material shading tables.
void Tracer::Impl::BuildShadeRecords() {
  // Each texture's pyramid is built on its own: in parallel, with the same result on any thread count
  // (and the same error: the first bad texture's).
  const size_t num_textures = scene.textures.size();
  textures.resize(num_textures);
  std::vector<std::exception_ptr> errors(num_textures);
  tbb::parallel_for(size_t{0}, num_textures, [&](size_t i) {
    try {
      textures[i] = MipTexture(scene.textures[i]);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  });
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);

  // Per-triangle shading records; UV-to-object area ratio (rigid transforms keep areas).
  mesh_shade.resize(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    std::vector<TriangleShade>& shade = mesh_shade[m];
    shade.resize(mesh.triangles.size());
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
      TriangleShade& ts = shade[i];
      ts.material = mesh.triangle_materials.empty() ? mesh.material : mesh.triangle_materials[i];
      std::fill(std::begin(ts.uv), std::end(ts.uv), 0.0f);
      ts.texels_per_metre = -1.0f;
      if (mesh.uvs.empty()) continue;
      const Eigen::Vector3i& tri = mesh.triangles[i];
      for (int k = 0; k < 3; ++k) {
        ts.uv[2 * k] = mesh.uvs[tri[k]].x();
        ts.uv[2 * k + 1] = mesh.uvs[tri[k]].y();
      }
      const int texture = scene.materials[ts.material].texture;
      if (texture < 0) continue;
      const float area = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                             .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]])
                             .norm();
      const Eigen::Vector2f e1 = mesh.uvs[tri[1]] - mesh.uvs[tri[0]];
      const Eigen::Vector2f e2 = mesh.uvs[tri[2]] - mesh.uvs[tri[0]];
      const float uv_area = std::abs(e1.x() * e2.y() - e1.y() * e2.x());
      ts.texels_per_metre = area > 0.0f ? std::sqrt(uv_area / area) * textures[texture].TexelsPerUv() : 0.0f;
    }
  }
  object_mesh.resize(scene.objects.size());
  object_shade.resize(scene.objects.size());
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    object_mesh[o] = scene.objects[o].mesh;
    object_shade[o] = mesh_shade[scene.objects[o].mesh].data();
  }
  shade_materials.resize(scene.materials.size());
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    ShadeMaterial& sm = shade_materials[m];
    for (int k = 0; k < 3; ++k) sm.base_color[k] = mat.base_color[k];
    sm.base_color[3] = 0.0f;
    sm.texture = mat.texture >= 0 ? &textures[mat.texture] : nullptr;
  }
}

// The static BVH: every static object's triangles in world coordinates; a BVH per mesh of a
// dynamic object.
void Tracer::Impl::BuildStaticScene(size_t* num_static_triangles, double* build_seconds) {
  const auto start = std::chrono::steady_clock::now();
  static_scene = rtcNewScene(device);
  // Robust mode keeps the triangle test watertight along edges shared by separate meshes (a ray
  // exactly along a room corner must not slip through).
  rtcSetSceneFlags(static_scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(static_scene, RTC_BUILD_QUALITY_HIGH);
  object_rotation.assign(scene.objects.size(), Eigen::Matrix3f::Identity());
  mesh_scenes.assign(scene.meshes.size(), nullptr);
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& obj = scene.objects[o];
    const Mesh& mesh = scene.meshes[obj.mesh];
    if (mesh.triangles.empty()) continue;
    if (obj.IsDynamic()) {
      if (!mesh_scenes[obj.mesh]) {
        RTCScene ms = rtcNewScene(device);
        rtcSetSceneFlags(ms, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(ms, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry g = MakeTriangles(mesh, nullptr, RTC_BUILD_QUALITY_HIGH);
        rtcAttachGeometry(ms, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(ms);
        mesh_scenes[obj.mesh] = ms;
      }
      dynamic_objects.push_back(static_cast<int>(o));
      continue;
    }
    RTCGeometry g = MakeTriangles(mesh, &obj.world_from_object, RTC_BUILD_QUALITY_HIGH);
    const unsigned id = rtcAttachGeometry(static_scene, g);
    rtcReleaseGeometry(g);
    if (static_geom_object.size() <= id) static_geom_object.resize(id + 1, -1);
    static_geom_object[id] = static_cast<int>(o);
    *num_static_triangles += mesh.triangles.size();
  }
  rtcCommitScene(static_scene);
  static_geom_shade.assign(static_geom_object.size(), nullptr);
  for (size_t id = 0; id < static_geom_object.size(); ++id)
    if (static_geom_object[id] >= 0) static_geom_shade[id] = object_shade[static_geom_object[id]];
  *build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CheckDevice("building the static scene");
}

// The top-level scene: the static BVH as one instance plus an instance per dynamic object.
void Tracer::Impl::BuildTopScene() {
  top = rtcNewScene(device);
  rtcSetSceneFlags(top, static_cast<RTCSceneFlags>(RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST));
  rtcSetSceneBuildQuality(top, RTC_BUILD_QUALITY_LOW);
  {
    RTCGeometry inst = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, static_scene);
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
    rtcCommitGeometry(inst);
    static_instance_id = rtcAttachGeometry(top, inst);
    rtcReleaseGeometry(inst);
    top_instance_object.resize(static_instance_id + 1, -1);
  }
  for (int o : dynamic_objects) {
    RTCGeometry inst = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, mesh_scenes[scene.objects[o].mesh]);
    const unsigned id = rtcAttachGeometry(top, inst);
    if (top_instance_object.size() <= id) top_instance_object.resize(id + 1, -1);
    top_instance_object[id] = o;
    dynamic_instances.push_back(inst);  // the top scene holds a reference; kept for updates
    rtcReleaseGeometry(inst);
  }
}

Tracer::Tracer(const Scene& scene) : impl_(std::make_unique<Impl>(scene)) {
  Impl& d = *impl_;
  ValidateSceneIndices(scene);
  d.BuildShadeRecords();
  d.device = rtcNewDevice(nullptr);
  if (!d.device) throw std::runtime_error("cannot create the Embree device");
  d.BuildStaticScene(&num_static_triangles_, &static_build_seconds_);
  d.BuildTopScene();
  d.SetUpLighting();
  // The instance level only exists for moving objects: without them, trace the static BVH itself.
  d.trace_scene = d.dynamic_objects.empty() ? d.static_scene : d.top;

  SetFrame(0);
}

Tracer::~Tracer() = default;

void Tracer::SetFrame(int frame) {
  Impl& d = *impl_;
  for (size_t k = 0; k < d.dynamic_objects.size(); ++k) {
    const Object& obj = d.scene.objects[d.dynamic_objects[k]];
    if (frame < 0 || frame >= static_cast<int>(obj.world_from_object_per_frame.size()))
      throw std::out_of_range("object '" + obj.name + "': no transform for frame " + std::to_string(frame) + " (has " +
                              std::to_string(obj.world_from_object_per_frame.size()) + ")");
    const Rigid3& world_from_object = obj.world_from_object_per_frame[frame];
    if (d.instances_move) rtcSetGeometryTimeStepCount(d.dynamic_instances[k], 1);
    d.SetInstanceTransform(k, 0, world_from_object);
    rtcCommitGeometry(d.dynamic_instances[k]);
    d.object_rotation[d.dynamic_objects[k]] = world_from_object.RotationMatrix().cast<float>();
  }
  d.instances_move = false;
  if (d.lights_move) d.PlaceLights(frame);
  rtcCommitScene(d.top);
  d.CheckDevice("committing the top-level scene");
}

void Tracer::SetFrameWindow(int frame, double half_window_s) {
  Impl& d = *impl_;
  if (!(half_window_s > 0.0) || d.dynamic_objects.empty()) {
    SetFrame(frame);
    return;
  }
  const Trajectory& trajectory = d.scene.rig_trajectory;
  if (frame < 0 || frame >= static_cast<int>(trajectory.size()))
    throw std::out_of_range("trajectory: no frame " + std::to_string(frame) + " (has " +
                            std::to_string(trajectory.size()) + ")");
  const double t = trajectory[frame].timestamp;
  for (size_t k = 0; k < d.dynamic_objects.size(); ++k) {
    const Object& obj = d.scene.objects[d.dynamic_objects[k]];
    if (obj.world_from_object_per_frame.size() != trajectory.size())
      throw std::out_of_range("object '" + obj.name + "': " + std::to_string(obj.world_from_object_per_frame.size()) +
                              " transforms for a trajectory of " + std::to_string(trajectory.size()));
    rtcSetGeometryTimeStepCount(d.dynamic_instances[k], 3);
    for (int step = 0; step < 3; ++step)
      d.SetInstanceTransform(k, step,
                             PoseAtTime(trajectory, &obj.world_from_object_per_frame, t + (step - 1) * half_window_s));
    rtcCommitGeometry(d.dynamic_instances[k]);
    d.object_rotation[d.dynamic_objects[k]] = obj.world_from_object_per_frame[frame].RotationMatrix().cast<float>();
  }
  d.instances_move = true;
  if (d.lights_move) d.PlaceLights(frame);
  rtcCommitScene(d.top);
  d.CheckDevice("committing the top-level scene (motion)");
}

}  // namespace rovo
