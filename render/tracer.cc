#include "render/tracer.h"

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/timing.h"

namespace rovo {
namespace {

constexpr int kTile = 8;
constexpr int kTilePixels = kTile * kTile;
constexpr float kInvPi = 0.318309886f;

// splitmix64: the per-pixel hash behind the fixed sample patterns and the soft-shadow sun samples.
uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

float UnitFloat(uint64_t bits) { return static_cast<float>(bits >> 40) * (1.0f / 16777216.0f); }

float RadicalInverse2(uint32_t i) {
  i = (i << 16) | (i >> 16);
  i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
  i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
  i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
  return static_cast<float>(i) * (1.0f / 4294967296.0f);
}

// Second dimension of the Sobol (0,2)-sequence (generator: Pascal's triangle mod 2).
float Sobol2(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
    if (i & 1u) r ^= v;
  return static_cast<float>(r) * (1.0f / 4294967296.0f);
}

float Wrap01(float x) { return x - std::floor(x); }

// log2(x) for x > 0, per lane: exponent plus a quadratic in the mantissa m in [1, 2),
// log2(m) ~ (m - 1) (1.3465 - 0.3465 (m - 1)); exact at powers of two, |error| < 0.01,
// monotonic and continuous (a level-of-detail selector, not a math library).
__m128 FastLog2x4(__m128 x) {
  const __m128i bits = _mm_castps_si128(x);
  const __m128 exponent = _mm_cvtepi32_ps(
      _mm_sub_epi32(_mm_and_si128(_mm_srli_epi32(bits, 23), _mm_set1_epi32(0xff)), _mm_set1_epi32(127)));
  const __m128 m = _mm_sub_ps(
      _mm_castsi128_ps(_mm_or_si128(_mm_and_si128(bits, _mm_set1_epi32(0x007fffff)), _mm_set1_epi32(0x3f800000))),
      _mm_set1_ps(1.0f));
  return _mm_add_ps(exponent, _mm_mul_ps(m, _mm_sub_ps(_mm_set1_ps(1.3465f), _mm_mul_ps(_mm_set1_ps(0.3465f), m))));
}

constexpr int kSunSamples = 64;

// 65536-entry table linear [0, 1] -> 8-bit sRGB (rounded).
const std::array<uint8_t, 65536>& SrgbTable() {
  static const std::array<uint8_t, 65536> table = [] {
    std::array<uint8_t, 65536> t{};
    for (int i = 0; i < 65536; ++i) {
      t[i] = static_cast<uint8_t>(std::lround(LinearToSrgb(i / 65535.0f) * 255.0f));
    }
    return t;
  }();
  return table;
}

Eigen::Vector3f ToF(const Eigen::Vector3d& v) { return v.cast<float>(); }

}  // namespace

void SetFlushDenormals() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

// ---------------------------------------------------------------------------------------------
// CameraRays

Eigen::Vector2f CameraRays::SampleOffset(int s, int spp) {
  if (spp <= 1) return Eigen::Vector2f::Zero();
  const float n = static_cast<float>(spp);
  return Eigen::Vector2f((s + 0.5f) / n - 0.5f, Wrap01(RadicalInverse2(static_cast<uint32_t>(s)) + 0.5f / n) - 0.5f);
}

CameraRays CameraRays::Make(const Camera& camera, int threads, int spp) {
  CameraRays rays;
  rays.camera = camera;
  rays.width = camera.width;
  rays.height = camera.height;
  const size_t n = static_cast<size_t>(camera.width) * camera.height;
  rays.bearing.assign(n, Eigen::Vector3f::Zero());
  rays.valid.assign(n, 0);
  rays.pixel_angle.assign(n, 0.0f);
  auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y < r.end(); ++y) {
        for (int x = 0; x < camera.width; ++x) {
          const std::optional<Eigen::Vector3d> b = camera.Unproject(Eigen::Vector2d(x, y));
          if (!b || !camera.InFov(*b)) continue;
          const size_t i = static_cast<size_t>(y) * camera.width + x;
          rays.bearing[i] = b->normalized().cast<float>();
          rays.valid[i] = 1;
        }
      }
    });
  };
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute(run);
  } else {
    run();
  }
  // Angular pixel size: mean angle to the valid neighbours among right/left and down/up.
  auto angle = [&](size_t i, size_t j) {
    const Eigen::Vector3f& a = rays.bearing[i];
    const Eigen::Vector3f& b = rays.bearing[j];
    return std::atan2(a.cross(b).norm(), a.dot(b));
  };
  auto pixel_angles = [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y < r.end(); ++y) {
        for (int x = 0; x < camera.width; ++x) {
          const size_t i = static_cast<size_t>(y) * camera.width + x;
          if (!rays.valid[i]) continue;
          float sum = 0.0f;
          int count = 0;
          for (const int dx : {1, -1}) {
            const int nx = x + dx;
            if (nx < 0 || nx >= camera.width || !rays.valid[i + dx]) continue;
            sum += angle(i, i + dx);
            ++count;
            break;
          }
          for (const int dy : {1, -1}) {
            const int ny = y + dy;
            const size_t j = static_cast<size_t>(ny) * camera.width + x;
            if (ny < 0 || ny >= camera.height || !rays.valid[j]) continue;
            sum += angle(i, j);
            ++count;
            break;
          }
          // An isolated valid pixel: use the equidistant estimate max_fov / diameter.
          rays.pixel_angle[i] =
              count > 0 ? sum / count
                        : static_cast<float>(camera.max_fov_deg * M_PI / 180.0 / std::max(camera.width, camera.height));
        }
      }
    });
  };
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute(pixel_angles);
  } else {
    pixel_angles();
  }
  for (uint8_t v : rays.valid) rays.num_valid += v;
  if (spp > 1 && spp <= kMaxPrecomputedSpp) {
    rays.sample_spp = spp;
    rays.sample_bearing.assign(spp, std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Zero()));
    auto samples = [&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& r) {
        for (int s = 0; s < spp; ++s) {
          const Eigen::Vector2f offset = SampleOffset(s, spp);
          for (int y = r.begin(); y < r.end(); ++y) {
            for (int x = 0; x < camera.width; ++x) {
              const size_t i = static_cast<size_t>(y) * camera.width + x;
              if (!rays.valid[i]) continue;
              Eigen::Vector3f b;
              if (rays.SampleBearing(x + offset.x(), y + offset.y(), &b)) rays.sample_bearing[s][i] = b;
            }
          }
        }
      });
    };
    if (threads > 0) {
      tbb::task_arena arena(threads);
      arena.execute(samples);
    } else {
      samples();
    }
  }
  return rays;
}

std::vector<CameraRays> MakeCameraRays(const std::vector<Camera>& cameras, int threads, int spp) {
  std::vector<CameraRays> rays(cameras.size());
  for (size_t i = 0; i < cameras.size(); ++i) {
    const Camera& c = cameras[i];
    size_t same = i;
    for (size_t j = 0; j < i && same == i; ++j) {
      const Camera& o = cameras[j];
      if (o.model == c.model && o.width == c.width && o.height == c.height && o.params == c.params &&
          o.max_fov_deg == c.max_fov_deg)
        same = j;
    }
    rays[i] = same < i ? rays[same] : CameraRays::Make(c, threads, spp);
  }
  return rays;
}

bool CameraRays::SampleBearing(float u, float v, Eigen::Vector3f* bearing_out) const {
  const float x0f = std::floor(u), y0f = std::floor(v);
  const int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
  if (x0 >= 0 && y0 >= 0 && x0 + 1 < width && y0 + 1 < height) {
    const size_t i00 = static_cast<size_t>(y0) * width + x0;
    const size_t i10 = i00 + 1, i01 = i00 + width, i11 = i01 + 1;
    if (valid[i00] & valid[i10] & valid[i01] & valid[i11]) {
      const float ax = u - x0f, ay = v - y0f;
      const Eigen::Vector3f top = bearing[i00] + ax * (bearing[i10] - bearing[i00]);
      const Eigen::Vector3f bottom = bearing[i01] + ax * (bearing[i11] - bearing[i01]);
      *bearing_out = (top + ay * (bottom - top)).normalized();
      return true;
    }
  }
  const std::optional<Eigen::Vector3d> b = camera.Unproject(Eigen::Vector2d(u, v));
  if (!b || !camera.InFov(*b)) return false;
  *bearing_out = b->normalized().cast<float>();
  return true;
}

// ---------------------------------------------------------------------------------------------
// Tracer

struct Tracer::Impl {
  const Scene& scene;
  RTCDevice device = nullptr;
  RTCScene static_scene = nullptr;
  RTCScene top = nullptr;
  std::vector<RTCScene> mesh_scenes;    // per mesh, only for meshes of dynamic objects
  std::vector<int> static_geom_object;  // static geomID -> object index
  unsigned static_instance_id = RTC_INVALID_GEOMETRY_ID;
  std::vector<int> top_instance_object;  // top-level geomID -> object index (-1: static)
  std::vector<RTCGeometry> dynamic_instances;
  std::vector<int> dynamic_objects;
  std::vector<Eigen::Matrix3f> object_rotation;  // world_from_object rotation (static: identity)
  // Everything shading reads about a triangle, in one 32-byte record (one cache line per hit
  // instead of loads from triangles, uvs, triangle_materials and the UV scale).
  struct TriangleShade {
    float uv[6];             // u0, v0, u1, v1, u2, v2 (zero without uvs)
    float texels_per_metre;  // sqrt(A_uv / A_object) * MipTexture::TexelsPerUv; < 0: untextured
    int32_t material;
  };
  std::vector<std::vector<TriangleShade>> mesh_shade;  // per mesh and triangle
  std::vector<int> object_mesh;                        // object index -> mesh index
  std::vector<MipTexture> textures;
  // Shading records of a hit in one load: per static geomID and per object, its mesh's records.
  std::vector<const TriangleShade*> static_geom_shade;
  std::vector<const TriangleShade*> object_shade;
  // What shading needs of a material, 32 bytes (Material also carries its name).
  struct ShadeMaterial {
    alignas(16) float base_color[4];  // linear r, g, b, 0
    const MipTexture* texture;        // nullptr: untextured
  };
  std::vector<ShadeMaterial> shade_materials;

  RTCScene trace_scene = nullptr;                        // static_scene when nothing moves, else top
  std::array<Eigen::Vector3f, kSunSamples> sun_samples;  // unit directions inside the sun disc
  Eigen::Vector3f sun_dir, sun_e1, sun_e2;
  float sun_disc_radius = 0.0f;  // tan(angular diameter / 2)
  Eigen::Vector3f sky_mean, ground_irradiance;
  bool sun_on = true;  // false when sun_radiance is zero: no sun term, no sun shadow rays

  // Point and spot lights at the current frame, in world coordinates (render/tracer.h).
  struct ShadeLight {
    Eigen::Vector3f position = Eigen::Vector3f::Zero();
    Eigen::Vector3f intensity = Eigen::Vector3f::Zero();
    float rank_intensity = 0.0f;  // intensity.r + g + b
    float inv_range2 = 0.0f;      // 1 / range^2; 0: no cut-off
    bool spot = false;
    Eigen::Vector3f spot_axis = Eigen::Vector3f::UnitZ();  // unit, world
    float spot_cos = -1.0f, spot_smooth = 0.0f;            // cos(angle / 2), (1 - spot_cos) * blend
  };
  std::vector<ShadeLight> lights;
  bool lights_move = false;  // some light rides on a dynamic object: re-placed on every SetFrame
  // The lights whose range disc reaches each cell of a 2-D grid over x, y (CSR lists), and the
  // lights without a range (tested everywhere).
  struct LightGrid {
    float x0 = 0.0f, y0 = 0.0f, inv_cell = 1.0f;
    int nx = 0, ny = 0;
    std::vector<uint32_t> cell_begin;  // nx * ny + 1
    std::vector<uint32_t> items;
    std::vector<uint32_t> unbounded;
  } light_grid;
  // Per material: emission (r, g, b, 0), Blinn-Phong specular and shininess.
  bool any_emission = false;
  std::vector<std::array<float, 4>> material_emission;
  std::vector<float> material_specular, material_shininess;

  bool instances_move = false;  // SetFrameWindow gave the dynamic instances three time steps

  explicit Impl(const Scene& s) : scene(s) {}

  // Time step `step` of dynamic instance k (index into dynamic_instances).
  void SetInstanceTransform(size_t k, unsigned step, const Rigid3& world_from_object) {
    const Eigen::Matrix<double, 3, 4> m = world_from_object.Matrix3x4();
    float xfm[12];
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r) xfm[3 * c + r] = static_cast<float>(m(r, c));
    rtcSetGeometryTransform(dynamic_instances[k], step, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
  }

  // Steps of the Tracer constructor.
  void BuildShadeRecords();
  void BuildStaticScene(size_t* num_static_triangles, double* build_seconds);
  void BuildTopScene();
  void SetUpLighting();
  void SetUpLights();
  void PlaceLights(int frame);
  void BuildLightGrid();

  ~Impl() {
    if (top) rtcReleaseScene(top);
    if (static_scene) rtcReleaseScene(static_scene);
    for (RTCScene m : mesh_scenes)
      if (m) rtcReleaseScene(m);
    if (device) rtcReleaseDevice(device);
  }

  void CheckDevice(const char* what) const {
    const RTCError err = rtcGetDeviceError(device);
    if (err != RTC_ERROR_NONE)
      throw std::runtime_error(std::string("Embree error ") + std::to_string(err) + " in " + what);
  }

  RTCGeometry MakeTriangles(const Mesh& mesh, const Rigid3* world_from_object, RTCBuildQuality quality) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), mesh.positions.size()));
    const Eigen::Matrix3f rot = world_from_object ? Eigen::Matrix3f(world_from_object->RotationMatrix().cast<float>())
                                                  : Eigen::Matrix3f(Eigen::Matrix3f::Identity());
    const Eigen::Vector3f trans = world_from_object ? ToF(world_from_object->translation) : Eigen::Vector3f::Zero();
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
};

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

// Textures, per-triangle shading records (UV-to-object area ratio; rigid transforms keep areas),
// the per-object and per-material shading tables.
void Tracer::Impl::BuildShadeRecords() {
  textures.reserve(scene.textures.size());
  for (const Texture& tex : scene.textures) textures.emplace_back(tex);

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

// Lighting constants: sun frame and disc samples, sky mean, ground irradiance.
void Tracer::Impl::SetUpLighting() {
  const Lighting& light = scene.lighting;
  const Eigen::Vector3d s =
      light.direction_to_sun.norm() > 0 ? light.direction_to_sun.normalized() : Eigen::Vector3d::UnitZ();
  sun_dir = s.cast<float>();
  const Eigen::Vector3f helper = std::abs(sun_dir.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  sun_e1 = sun_dir.cross(helper).normalized();
  sun_e2 = sun_dir.cross(sun_e1);
  sun_disc_radius = static_cast<float>(std::tan(0.5 * light.sun_angular_diameter_deg * M_PI / 180.0));
  sky_mean = 0.5f * (light.sky_zenith + light.sky_horizon);
  ground_irradiance =
      light.ground_albedo.cwiseProduct(light.sun_radiance * std::max(0.0f, sun_dir.z()) * kInvPi + sky_mean);
  // Sun-disc directions: point i of the (0,2)-sequence (radinv2(i), sobol2(i)) mapped to the disc
  // of radius tan(diameter / 2) around sun_dir (uniform in area).
  for (int i = 0; i < kSunSamples; ++i) {
    const float radius = sun_disc_radius * std::sqrt(RadicalInverse2(static_cast<uint32_t>(i)));
    const float phi = 6.2831853f * Sobol2(static_cast<uint32_t>(i));
    sun_samples[i] = (sun_dir + radius * (std::cos(phi) * sun_e1 + std::sin(phi) * sun_e2)).normalized();
  }
  sun_on = light.sun_radiance.maxCoeff() > 0.0f;
  SetUpLights();
}

// Per-material emission and specular tables; the lights' constant parts (world-fixed lights are
// placed here, lights on objects by PlaceLights).
void Tracer::Impl::SetUpLights() {
  material_emission.assign(scene.materials.size(), {0.0f, 0.0f, 0.0f, 0.0f});
  material_specular.assign(scene.materials.size(), 0.0f);
  material_shininess.assign(scene.materials.size(), 0.0f);
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    if (mat.IsEmissive()) any_emission = true;
    material_emission[m] = {mat.emission.x(), mat.emission.y(), mat.emission.z(), 0.0f};
    material_specular[m] = mat.specular;
    material_shininess[m] = mat.shininess;
  }
  lights.resize(scene.lights.size());
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& in = scene.lights[i];
    if (in.object >= static_cast<int>(scene.objects.size()))
      throw std::invalid_argument("light '" + in.name + "': object index " + std::to_string(in.object) +
                                  " out of range");
    ShadeLight& l = lights[i];
    l.intensity = in.intensity;
    l.rank_intensity = in.intensity.sum();
    l.inv_range2 = in.range > 0.0 ? static_cast<float>(1.0 / (in.range * in.range)) : 0.0f;
    l.spot = in.spot;
    if (in.spot) {
      const double c0 = std::cos(0.5 * in.spot_angle_deg * M_PI / 180.0);
      l.spot_cos = static_cast<float>(c0);
      l.spot_smooth = static_cast<float>((1.0 - c0) * in.spot_blend);
    }
    if (in.object >= 0 && scene.objects[in.object].IsDynamic()) lights_move = true;
  }
  if (!lights.empty()) PlaceLights(0);
}

// World positions and spot axes of the lights at `frame` (objects that move: their pose at the
// frame), then the light grid.
void Tracer::Impl::PlaceLights(int frame) {
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& in = scene.lights[i];
    Rigid3 world_from_light_frame = Rigid3::Identity();
    if (in.object >= 0) {
      const Object& obj = scene.objects[in.object];
      if (!obj.IsDynamic()) {
        world_from_light_frame = obj.world_from_object;
      } else if (frame >= 0 && frame < static_cast<int>(obj.world_from_object_per_frame.size())) {
        world_from_light_frame = obj.world_from_object_per_frame[frame];
      }
    }
    ShadeLight& l = lights[i];
    l.position = (world_from_light_frame * in.position).cast<float>();
    if (in.spot) l.spot_axis = (world_from_light_frame.rotation * in.spot_direction).normalized().cast<float>();
  }
  BuildLightGrid();
}

// Cells of about half the median range (at least 1 m, at most 1024 x 1024 cells) over the range
// discs of the lights that have a range.
void Tracer::Impl::BuildLightGrid() {
  LightGrid& g = light_grid;
  g = LightGrid();
  std::vector<float> ranges;
  Eigen::Vector2f lo(std::numeric_limits<float>::max(), std::numeric_limits<float>::max()), hi = -lo;
  for (uint32_t i = 0; i < lights.size(); ++i) {
    const ShadeLight& l = lights[i];
    if (l.inv_range2 <= 0.0f) {
      g.unbounded.push_back(i);
      continue;
    }
    const float r = 1.0f / std::sqrt(l.inv_range2);
    ranges.push_back(r);
    lo = lo.cwiseMin(l.position.head<2>() - Eigen::Vector2f::Constant(r));
    hi = hi.cwiseMax(l.position.head<2>() + Eigen::Vector2f::Constant(r));
  }
  if (ranges.empty()) return;
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  float cell = std::max(1.0f, 0.5f * ranges[ranges.size() / 2]);
  cell = std::max(cell, std::max(hi.x() - lo.x(), hi.y() - lo.y()) / 1024.0f);
  g.x0 = lo.x();
  g.y0 = lo.y();
  g.inv_cell = 1.0f / cell;
  g.nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) * g.inv_cell)));
  g.ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) * g.inv_cell)));
  // Two passes over the lights' cell rectangles: count, then fill.
  std::vector<uint32_t> count(static_cast<size_t>(g.nx) * g.ny + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (uint32_t i = 0; i < lights.size(); ++i) {
      const ShadeLight& l = lights[i];
      if (l.inv_range2 <= 0.0f) continue;
      const float r = 1.0f / std::sqrt(l.inv_range2);
      const int cx0 = std::clamp(static_cast<int>((l.position.x() - r - g.x0) * g.inv_cell), 0, g.nx - 1);
      const int cx1 = std::clamp(static_cast<int>((l.position.x() + r - g.x0) * g.inv_cell), 0, g.nx - 1);
      const int cy0 = std::clamp(static_cast<int>((l.position.y() - r - g.y0) * g.inv_cell), 0, g.ny - 1);
      const int cy1 = std::clamp(static_cast<int>((l.position.y() + r - g.y0) * g.inv_cell), 0, g.ny - 1);
      for (int cy = cy0; cy <= cy1; ++cy)
        for (int cx = cx0; cx <= cx1; ++cx) {
          const size_t c = static_cast<size_t>(cy) * g.nx + cx;
          if (pass == 0)
            ++count[c + 1];
          else
            g.items[g.cell_begin[c] + count[c]++] = i;
        }
    }
    if (pass == 0) {
      for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
      g.cell_begin = count;
      g.items.resize(count.back());
      std::fill(count.begin(), count.end(), 0);
    }
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

namespace {

// A tile's rays and the shading state between its passes (structures of arrays; colours are SSE
// registers (r, g, b, 0): every lane operation is the scalar one, so results do not depend on it).
// A hit casts at most one sun and kMaxShadowedLights light shadow rays.
constexpr int kMaxShadowRays = kTilePixels * (1 + kMaxShadowedLights);

struct alignas(64) TileBuffers {
  RTCRayHit rayhit[kTilePixels];
  RTCRay shadow[kMaxShadowRays];
  int pixel[kTilePixels];            // tile-local pixel index of each ray
  int shadow_pixel[kMaxShadowRays];  // tile-local pixel index of each shadow ray
  __m128 direct[kMaxShadowRays];     // the light each shadow ray lets through (sun: albedo * E_sun * cos / pi)
  __m128 sum[kTilePixels];           // linear radiance sums per pixel
  int count[kTilePixels];
  float pixel_time[kTilePixels];  // ray time of each pixel's ray in the current pass (CameraMotion)
  // The hits of the current sample pass, compacted.
  int hit_ray[kTilePixels];
  Eigen::Vector3f normal[kTilePixels];  // unit, facing the ray
  __m128 albedo[kTilePixels];           // base colour, then times the texture
  int material[kTilePixels];            // material index (emission and specular of point lights)
  // The hits with a texture lookup, compacted (index into the hit arrays).
  int textured_hit[kTilePixels];
  const MipTexture* texture[kTilePixels];
  float tex_u[kTilePixels], tex_v[kTilePixels];
  alignas(16) float tex_lod[kTilePixels];
  __m128 texel[kTilePixels];  // the filtered texture colour
};

void InitRay(RTCRayHit* rh, const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float time = 0.0f) {
  rh->ray.org_x = origin.x();
  rh->ray.org_y = origin.y();
  rh->ray.org_z = origin.z();
  rh->ray.tnear = 0.0f;
  rh->ray.dir_x = dir.x();
  rh->ray.dir_y = dir.y();
  rh->ray.dir_z = dir.z();
  rh->ray.time = time;
  rh->ray.tfar = std::numeric_limits<float>::infinity();
  rh->ray.mask = 0xffffffffu;
  rh->ray.id = 0;
  rh->ray.flags = 0;
  rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

__m128 Load3(const Eigen::Vector3f& v) { return _mm_setr_ps(v.x(), v.y(), v.z(), 0.0f); }

// What every tile of one Render call reads: the inputs and the per-call constants.
struct RenderJob {
  RenderJob(const Tracer::Impl& d_in, const CameraRays& rays_in, const ShadeSettings& settings_in,
            CameraImage* image_in)
      : d(d_in),
        rays(rays_in),
        settings(settings_in),
        image(image_in),
        width(rays_in.width),
        height(rays_in.height),
        raw(settings_in.raw_cast_only) {}
  const Tracer::Impl& d;
  const CameraRays& rays;
  const ShadeSettings& settings;
  CameraImage* image;
  int width, height;
  bool raw;
  Eigen::Matrix3f world_from_cam_rot = Eigen::Matrix3f::Identity();
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  // Timing (CameraMotion): null for the default; `moving` when rays differ in time and pose.
  const CameraMotion* motion = nullptr;
  bool moving = false;
  float row_time_scale = 0.0f;  // readout / (height - 1)
  int spp = 1;
  float inv_sqrt_spp = 1.0f;
  float theta_max = 0.0f;
  bool precomputed_samples = false, soft_sun = false, textures = false;
  // A pixel's sun samples: the block of `spp` consecutive points of the (0,2)-sequence starting at
  // a hashed multiple of spp (an elementary-interval-stratified set for power-of-two spp <= 64).
  uint32_t spp_u = 1;
  __m128 sky_horizon{}, sky_delta{}, sky_ground{}, ambient_ground{}, ambient_delta{}, sun_radiance{};
  // ShadeSettings::sun_disc with a sun: misses see it; sun_var = r^2 / 4 (r: angular radius, radians).
  bool sun_disc = false;
  float sun_var = 0.0f;
  // ShadeSettings::sun_aureole with a sun: k of the aureole (render/tracer.h), else 0.
  float aureole_k = 0.0f;
  // exposure / (samples of a pixel): a pixel has at most spp samples.
  std::vector<float> exposure_over_count;
  std::array<Eigen::Vector2f, 64> offsets{};
  int tiles_x = 0, tiles_y = 0;
};

// One tile's pixel rectangle.
struct TileRect {
  int tx0, ty0, tw, th;
  size_t Pixel(const RenderJob& job, int local) const {
    return static_cast<size_t>(ty0 + local / kTile) * job.width + tx0 + local % kTile;
  }
};

// A camera ray of a moving camera (render/tracer.h, CameraMotion): the time of sample s of pixel
// pi in row y (s < 0: the pixel centre at the row's mid-exposure), and the pose at that time.
void InitMovingRay(const RenderJob& job, size_t pi, int y, int s, const Eigen::Vector3f& bearing, RTCRayHit* rh) {
  const CameraMotion& m = *job.motion;
  float time = m.time_mid + (static_cast<float>(y) - 0.5f * static_cast<float>(job.height - 1)) * job.row_time_scale;
  if (s >= 0 && job.spp > 1 && m.shutter > 0.0f) {
    const float w = Wrap01((s + 0.5f) / static_cast<float>(job.spp) + UnitFloat(Mix64(pi * 0xd1b54a32d192ed03ull + 3)));
    time += (w - 0.5f) * m.shutter;
  }
  time = std::clamp(time, 0.0f, 1.0f);
  const float f = time * static_cast<float>(m.rotation.size() - 1);
  const size_t k = std::min(static_cast<size_t>(f), m.rotation.size() - 2);
  const float a = f - static_cast<float>(k);
  const Eigen::Matrix3f rot = m.rotation[k] + a * (m.rotation[k + 1] - m.rotation[k]);
  const Eigen::Vector3f org = m.origin[k] + a * (m.origin[k + 1] - m.origin[k]);
  InitRay(rh, org, rot * bearing, time);
}

// The camera rays of sample s (-1 or spp == 1: pixel centres) of the tile's valid pixels into
// tb.rayhit / tb.pixel; returns their count.
int MakeSampleRays(const RenderJob& job, const TileRect& t, int s, bool is_centre, TileBuffers& tb) {
  const CameraRays& rays = job.rays;
  const int spp = job.spp;
  int n = 0;
  for (int ly = 0; ly < t.th; ++ly) {
    const size_t row = static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0;
    for (int lx = 0; lx < t.tw; ++lx) {
      const size_t pi = row + lx;
      if (!rays.valid[pi]) continue;
      Eigen::Vector3f bearing;
      if (is_centre) {
        bearing = rays.bearing[pi];
      } else if (job.precomputed_samples) {
        bearing = rays.sample_bearing[s][pi];
        if (bearing.x() == 0.0f && bearing.y() == 0.0f && bearing.z() == 0.0f) continue;
      } else {
        Eigen::Vector2f offset;
        if (job.settings.rotate_pattern) {
          const uint64_t h = Mix64(pi * 0x632be59bd9b4e019ull + 1);
          offset.x() = Wrap01((s + 0.5f) / spp + UnitFloat(h)) - 0.5f;
          offset.y() = Wrap01(RadicalInverse2(static_cast<uint32_t>(s)) + UnitFloat(Mix64(h))) - 0.5f;
        } else {
          offset = s < 64 ? job.offsets[s] : CameraRays::SampleOffset(s, spp);
        }
        if (!rays.SampleBearing(t.tx0 + lx + offset.x(), t.ty0 + ly + offset.y(), &bearing)) continue;
      }
      if (job.moving) {
        InitMovingRay(job, pi, t.ty0 + ly, is_centre ? -1 : s, bearing, &tb.rayhit[n]);
        tb.pixel_time[ly * kTile + lx] = tb.rayhit[n].ray.time;
      } else {
        InitRay(&tb.rayhit[n], job.origin, job.world_from_cam_rot * bearing, job.motion ? job.motion->time_mid : 0.0f);
      }
      tb.pixel[n] = ly * kTile + lx;
      ++n;
    }
  }
  return n;
}

// Depth and object id of the pixel-centre hits.
void WriteDepthAndMask(const RenderJob& job, const TileRect& t, int n, const TileBuffers& tb) {
  const Tracer::Impl& d = job.d;
  for (int r = 0; r < n; ++r) {
    const RTCRayHit& rh = tb.rayhit[r];
    const size_t pi = t.Pixel(job, tb.pixel[r]);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    if (job.settings.want_depth) job.image->depth[pi] = rh.ray.tfar;
    if (job.settings.want_mask) {
      const unsigned inst = rh.hit.instID[0];
      const int obj = inst != RTC_INVALID_GEOMETRY_ID && d.top_instance_object[inst] >= 0
                          ? d.top_instance_object[inst]
                          : d.static_geom_object[rh.hit.geomID];
      job.image->mask[pi] = d.scene.objects[obj].id;
    }
  }
}

// Shading pass 1: misses take the sky; hits get their facing unit normal, base colour and texture
// coordinates and level of detail (compacted lists). Sets the hit and textured-hit counts.
void GatherHits(const RenderJob& job, const TileRect& t, int n, TileBuffers& tb, int* num_hits_out,
                int* num_textured_out) {
  const Tracer::Impl& d = job.d;
  const bool raw = job.raw;
  int num_hits = 0, num_textured = 0;
  for (int r = 0; r < n; ++r) {
    const RTCRayHit& rh = tb.rayhit[r];
    const int local = tb.pixel[r];
    const Eigen::Vector3f dir(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      if (!raw) {
        // Sky: mix(horizon, zenith, sqrt(d.z)) above the horizon, ground_albedo * horizon below.
        __m128 sky = dir.z() >= 0.0f
                         ? _mm_add_ps(job.sky_horizon, _mm_mul_ps(_mm_set1_ps(std::sqrt(dir.z())), job.sky_delta))
                         : job.sky_ground;
        if (job.aureole_k > 0.0f && dir.z() >= 0.0f) {
          // The circumsolar aureole: gamma = 2 asin(|d - s_dir| / 2).
          const float gamma = 2.0f * std::asin(std::min(1.0f, 0.5f * (dir - d.sun_dir).norm()));
          sky = _mm_mul_ps(sky, _mm_set1_ps(1.0f + job.aureole_k * std::exp(-3.0f * gamma)));
        }
        if (job.sun_disc) {
          // The HDR sun through the pixel footprint (render/tracer.h): E_sun exp(-c2 / 2s2) / (2 pi s2).
          const float c2 = (dir - d.sun_dir).squaredNorm();
          const float f = 0.5f * job.rays.pixel_angle[t.Pixel(job, local)];
          const float s2 = job.sun_var + f * f;
          if (c2 < 50.0f * s2)
            sky = _mm_add_ps(
                sky, _mm_mul_ps(job.sun_radiance, _mm_set1_ps(std::exp(-c2 / (2.0f * s2)) * (0.5f * kInvPi) / s2)));
        }
        tb.sum[local] = _mm_add_ps(tb.sum[local], sky);
        ++tb.count[local];
      }
      continue;
    }
    const int h = num_hits++;
    tb.hit_ray[h] = r;
    const unsigned inst = rh.hit.instID[0];
    Eigen::Vector3f normal(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    const Tracer::Impl::TriangleShade* shade;
    if (inst == RTC_INVALID_GEOMETRY_ID) {
      shade = d.static_geom_shade[rh.hit.geomID];
    } else {
      const int obj =
          d.top_instance_object[inst] >= 0 ? d.top_instance_object[inst] : d.static_geom_object[rh.hit.geomID];
      normal = d.object_rotation[obj] * normal;
      shade = d.object_shade[obj];
    }
    const float nlen2 = normal.squaredNorm();
    normal = nlen2 > 0.0f ? Eigen::Vector3f(normal / std::sqrt(nlen2)) : Eigen::Vector3f(-dir);
    const float facing = normal.dot(dir);  // after the flip n.d = -|facing| exactly
    if (facing > 0.0f) normal = -normal;
    tb.normal[h] = normal;
    if (raw) continue;
    const Tracer::Impl::TriangleShade& ts = shade[rh.hit.primID];
    const Tracer::Impl::ShadeMaterial& mat = d.shade_materials[ts.material];
    tb.albedo[h] = _mm_load_ps(mat.base_color);
    tb.material[h] = ts.material;
    if (!job.textures || ts.texels_per_metre < 0.0f) continue;
    const float bu = rh.hit.u, bv = rh.hit.v, bw = 1.0f - bu - bv;
    const int k = num_textured++;
    tb.textured_hit[k] = h;
    tb.texture[k] = mat.texture;
    tb.tex_u[k] = bw * ts.uv[0] + bu * ts.uv[2] + bv * ts.uv[4];
    tb.tex_v[k] = bw * ts.uv[1] + bu * ts.uv[3] + bv * ts.uv[5];
    // Ray-cone footprint in metres, then in texels of level 0.
    const size_t pi = t.Pixel(job, local);
    const float cos_view = std::max(facing > 0.0f ? facing : -facing, 0.1f);  // -normal.dot(dir)
    const float texels = rh.ray.tfar * job.rays.pixel_angle[pi] / cos_view * job.inv_sqrt_spp * ts.texels_per_metre;
    tb.tex_lod[k] = texels;  // turned into the level of detail below, four at a time
  }
  *num_hits_out = num_hits;
  *num_textured_out = num_textured;
}

// Shading pass 2: the texture lookups (a tight loop keeps several independent texel loads in flight).
void ApplyTextures(const RenderJob& job, int num_textured, TileBuffers& tb) {
  // lod = FastLog2(texels) + bias where texels > 0, else 0.
  for (int k = num_textured; k % 4 != 0; ++k) tb.tex_lod[k] = 0.0f;
  const __m128 bias = _mm_set1_ps(job.settings.lod_bias);
  for (int k = 0; k < num_textured; k += 4) {
    const __m128 texels = _mm_load_ps(tb.tex_lod + k);
    _mm_store_ps(tb.tex_lod + k,
                 _mm_and_ps(_mm_cmpgt_ps(texels, _mm_setzero_ps()), _mm_add_ps(FastLog2x4(texels), bias)));
  }
  MipTexture::SampleBatch(tb.texture, tb.tex_u, tb.tex_v, tb.tex_lod, num_textured, tb.texel, job.settings.trilinear);
  for (int k = 0; k < num_textured; ++k) {
    const int h = tb.textured_hit[k];
    tb.albedo[h] = _mm_mul_ps(tb.albedo[h], tb.texel[k]);
  }
}

// Appends a shadow ray from `org` along unit `dir` over (tnear, tfar) that adds `direct` to pixel
// `local` when nothing blocks it.
void PushShadowRay(TileBuffers& tb, int* num_shadow, const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                   float tnear, float tfar, int local, __m128 direct) {
  RTCRay& sr = tb.shadow[*num_shadow];
  sr.org_x = org.x();
  sr.org_y = org.y();
  sr.org_z = org.z();
  sr.dir_x = dir.x();
  sr.dir_y = dir.y();
  sr.dir_z = dir.z();
  sr.tnear = tnear;
  sr.tfar = tfar;
  sr.mask = 0xffffffffu;
  sr.time = 0.0f;
  sr.id = 0;
  sr.flags = 0;
  tb.shadow_pixel[*num_shadow] = local;
  tb.direct[*num_shadow] = direct;
  ++*num_shadow;
}

// The lights that may reach world point x: the grid cell's list (empty outside the grid), then the
// lights without a range.
template <typename F>
void ForEachLightNear(const Tracer::Impl::LightGrid& g, const Eigen::Vector3f& x, F&& visit) {
  if (g.nx > 0) {
    const float fx = (x.x() - g.x0) * g.inv_cell, fy = (x.y() - g.y0) * g.inv_cell;
    if (fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny)) {
      const size_t c = static_cast<size_t>(static_cast<int>(fy)) * g.nx + static_cast<int>(fx);
      for (uint32_t k = g.cell_begin[c]; k < g.cell_begin[c + 1]; ++k) visit(g.items[k]);
    }
  }
  for (uint32_t i : g.unbounded) visit(i);
}

// Point and spot lights at hit h (formula: render/tracer.h): the `max_shadowed_lights` strongest
// get a shadow ray from `shadow_origin`; the others are added to the pixel at once.
void AddPointLights(const RenderJob& job, int h, const Eigen::Vector3f& x, const Eigen::Vector3f& view,
                    const Eigen::Vector3f& shadow_origin, float offset, int local, TileBuffers& tb, int* num_shadow) {
  const Tracer::Impl& d = job.d;
  const Eigen::Vector3f& n = tb.normal[h];
  const int material = tb.material[h];
  const float ks = d.material_specular[material], shininess = d.material_shininess[material];
  const __m128 diffuse = _mm_mul_ps(tb.albedo[h], _mm_set1_ps(kInvPi));
  const int k_max = job.settings.shadows ? std::clamp(job.settings.max_shadowed_lights, 0, kMaxShadowedLights) : 0;
  struct Candidate {
    float rank;
    uint32_t light;
    __m128 direct;
  };
  Candidate best[kMaxShadowedLights];
  int num_best = 0;
  ForEachLightNear(d.light_grid, x, [&](uint32_t i) {
    const Tracer::Impl::ShadeLight& l = d.lights[i];
    const Eigen::Vector3f to = l.position - x;
    const float d2 = to.squaredNorm();
    float weight = 1.0f;  // A * W
    if (l.inv_range2 > 0.0f) {
      const float q = d2 * l.inv_range2;
      if (q >= 1.0f) return;
      weight = (1.0f - q * q) * (1.0f - q * q);
    }
    const float n_dot_to = n.dot(to);
    if (n_dot_to <= 0.0f || !(d2 > 1e-12f)) return;  // behind the surface: no square root needed
    const float inv_d = 1.0f / std::sqrt(d2);
    const Eigen::Vector3f to_light = to * inv_d;
    const float cos_light = n_dot_to * inv_d;
    if (l.spot) {
      const float c = -to_light.dot(l.spot_axis);
      if (c <= l.spot_cos) return;
      const float t = c - l.spot_cos;
      float a = c;
      if (t < l.spot_smooth) {
        const float u = t / l.spot_smooth;
        a *= u * u * (3.0f - 2.0f * u);
      }
      weight *= a;
    }
    const float geometry = weight * cos_light / d2;
    __m128 brdf = diffuse;
    if (ks > 0.0f) {
      const float nh = std::max(0.0f, n.dot((to_light + view).normalized()));
      brdf = _mm_add_ps(brdf, _mm_set1_ps(ks * (shininess + 8.0f) * (kInvPi / 8.0f) * std::pow(nh, shininess)));
    }
    Candidate c{l.rank_intensity * geometry, i,
                _mm_mul_ps(brdf, _mm_mul_ps(Load3(l.intensity), _mm_set1_ps(geometry)))};
    if (num_best < k_max) {
      best[num_best++] = c;
      return;
    }
    int weakest = -1;
    for (int b = 0; b < num_best; ++b)
      if (best[b].rank < (weakest < 0 ? c.rank : best[weakest].rank)) weakest = b;
    if (weakest >= 0) std::swap(c, best[weakest]);
    tb.sum[local] = _mm_add_ps(tb.sum[local], c.direct);  // beyond the shadowed ones: V = 1
  });
  for (int b = 0; b < num_best; ++b) {
    const Eigen::Vector3f to = d.lights[best[b].light].position - shadow_origin;
    const float dist = to.norm();
    if (!(dist > offset + 1e-3f)) continue;
    PushShadowRay(tb, num_shadow, shadow_origin, to / dist, offset, dist - 1e-3f, local, best[b].direct);
  }
}

// Shading pass 3: ambient light, emission, point and spot lights, and the shadow rays of the lit
// hits (sun sample of sample s; lights) into tb.shadow with their direct light; returns the shadow
// ray count. Without shadows the direct light is added at once.
int AmbientAndShadowRays(const RenderJob& job, const TileRect& t, int s, int num_hits, TileBuffers& tb) {
  const Tracer::Impl& d = job.d;
  const bool raw = job.raw;
  int num_shadow = 0;
  for (int h = 0; h < num_hits; ++h) {
    const RTCRayHit& rh = tb.rayhit[tb.hit_ray[h]];
    const int local = tb.pixel[tb.hit_ray[h]];
    const Eigen::Vector3f& normal = tb.normal[h];
    __m128 albedo = _mm_setzero_ps();
    const Eigen::Vector3f dir(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z);
    const Eigen::Vector3f origin(rh.ray.org_x, rh.ray.org_y, rh.ray.org_z);  // per ray with CameraMotion
    const float tfar = rh.ray.tfar;
    const float offset = 1e-4f * (1.0f + tfar);
    if (!raw) {
      albedo = tb.albedo[h];
      // Ambient: hemisphere mix of sky and ground by the normal's elevation.
      const float up = 0.5f * (1.0f + normal.z());
      tb.sum[local] = _mm_add_ps(
          tb.sum[local],
          _mm_mul_ps(albedo, _mm_add_ps(job.ambient_ground, _mm_mul_ps(_mm_set1_ps(up), job.ambient_delta))));
      ++tb.count[local];
      if (d.any_emission)
        tb.sum[local] = _mm_add_ps(tb.sum[local], _mm_loadu_ps(d.material_emission[tb.material[h]].data()));
      if (!d.lights.empty()) {
        const Eigen::Vector3f x = origin + tfar * dir;
        AddPointLights(job, h, x, -dir, x + offset * normal, offset, local, tb, &num_shadow);
      }
    }
    if (!d.sun_on) continue;
    const Eigen::Vector3f* to_sun = &d.sun_dir;
    if (job.soft_sun) {
      const size_t pi = t.Pixel(job, local);
      to_sun = &d.sun_samples[(static_cast<uint32_t>(Mix64(pi * 0x9e3779b97f4a7c15ull + 7)) * job.spp_u +
                               static_cast<uint32_t>(s)) &
                              (kSunSamples - 1)];
    }
    const float cos_sun = normal.dot(*to_sun);
    if (cos_sun <= 0.0f) continue;
    const __m128 direct =
        raw ? albedo : _mm_mul_ps(_mm_mul_ps(albedo, job.sun_radiance), _mm_set1_ps(cos_sun * kInvPi));
    if (!job.settings.shadows) {
      if (!raw) tb.sum[local] = _mm_add_ps(tb.sum[local], direct);
      continue;
    }
    const Eigen::Vector3f shadow_origin = origin + tfar * dir + offset * normal;
    PushShadowRay(tb, &num_shadow, shadow_origin, *to_sun, offset, std::numeric_limits<float>::infinity(), local,
                  direct);
  }
  return num_shadow;
}

// Optional vignetting: 1 - vignetting * (theta / theta_max)^2 at pixel pi, at least 0.
float VignettingGain(const RenderJob& job, size_t pi) {
  const Eigen::Vector3f& b = job.rays.bearing[pi];
  const float theta = std::atan2(std::hypot(b.x(), b.y()), b.z());
  const float rel = theta / job.theta_max;
  return std::max(0.0f, 1.0f - job.settings.vignetting * rel * rel);
}

// The linear resolve (ShadeSettings::linear_output): box filter times the vignetting gain, no
// exposure, no clamp; pixels without samples are 0.
void ResolveTileLinear(const RenderJob& job, const TileRect& t, const TileBuffers& tb) {
  for (int ly = 0; ly < t.th; ++ly) {
    const size_t row = static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0;
    for (int lx = 0; lx < t.tw; ++lx) {
      const int local = ly * kTile + lx;
      float* out = job.image->linear.data() + (row + lx) * 3;
      if (tb.count[local] == 0) {
        out[0] = out[1] = out[2] = 0.0f;
        continue;
      }
      float gain = 1.0f / static_cast<float>(tb.count[local]);
      if (job.settings.vignetting > 0.0f) gain *= VignettingGain(job, row + lx);
      alignas(16) float c[4];
      _mm_store_ps(c, _mm_mul_ps(tb.sum[local], _mm_set1_ps(gain)));
      out[0] = c[0];
      out[1] = c[1];
      out[2] = c[2];
    }
  }
}

// Resolve: box filter, exposure, optional vignetting, sRGB. The encoding clamps to [0, 1]
// (NaN -> 0) and reads the 64k table at round(65535 x).
void ResolveTile(const RenderJob& job, const TileRect& t, const TileBuffers& tb) {
  const ShadeSettings& settings = job.settings;
  if (settings.linear_output) {
    ResolveTileLinear(job, t, tb);
    return;
  }
  const auto& srgb = SrgbTable();
  const __m128 one = _mm_set1_ps(1.0f), scale = _mm_set1_ps(65535.0f), half = _mm_set1_ps(0.5f);
  for (int ly = 0; ly < t.th; ++ly) {
    uint8_t* out = job.image->rgb.data() + (static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0) * 3;
    for (int lx = 0; lx < t.tw; ++lx, out += 3) {
      const int local = ly * kTile + lx;
      if (tb.count[local] == 0) {
        out[0] = out[1] = out[2] = 0;
        continue;
      }
      const size_t pi = static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0 + lx;
      float gain = job.exposure_over_count[tb.count[local]];
      if (settings.vignetting > 0.0f) gain *= VignettingGain(job, pi);
      const __m128 c = _mm_min_ps(_mm_max_ps(_mm_mul_ps(tb.sum[local], _mm_set1_ps(gain)), _mm_setzero_ps()), one);
      const __m128i i4 = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(c, scale), half));
      const int index[3] = {_mm_cvtsi128_si32(i4), _mm_cvtsi128_si32(_mm_shuffle_epi32(i4, 1)),
                            _mm_cvtsi128_si32(_mm_shuffle_epi32(i4, 2))};
      for (int k = 0; k < 3; ++k) out[k] = srgb[index[k]];
    }
  }
}

// One tile: a pixel-centre pass for depth and masks (shared with the only sample when spp == 1),
// then per sample the camera rays, the three shading passes and the shadow rays; then the resolve.
// The raw cast computes the same shadow rays (it needs the normal and the sun sample) but no
// albedo, texture, sky or ambient term.
void RenderTile(const RenderJob& job, int tile, TileBuffers& tb) {
  const Tracer::Impl& d = job.d;
  const ShadeSettings& settings = job.settings;
  const int spp = job.spp;
  const bool raw = job.raw;
  TileRect t;
  t.tx0 = (tile % job.tiles_x) * kTile;
  t.ty0 = (tile / job.tiles_x) * kTile;
  t.tw = std::min(kTile, job.width - t.tx0);
  t.th = std::min(kTile, job.height - t.ty0);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  // Shadow rays towards a wide sun disc are not coherent; Embree 3.13's coherent stream path
  // never returned for such rays (a 30-degree overcast sun hung the render), so they go
  // through the incoherent path.
  RTCIntersectContext shadow_context;
  rtcInitIntersectContext(&shadow_context);
  shadow_context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  for (int i = 0; i < kTilePixels; ++i) {
    tb.sum[i] = _mm_setzero_ps();
    tb.count[i] = 0;
  }

  const bool centre_pass = settings.want_depth || settings.want_mask;
  for (int s = (centre_pass && spp > 1) ? -1 : 0; s < spp; ++s) {
    const bool is_centre = s < 0 || spp == 1;
    const int n = MakeSampleRays(job, t, s, is_centre, tb);
    if (n == 0) continue;
    rtcIntersect1M(d.trace_scene, &context, tb.rayhit, static_cast<unsigned>(n), sizeof(RTCRayHit));
    if (is_centre && !raw && centre_pass) WriteDepthAndMask(job, t, n, tb);
    if (s < 0) continue;  // the extra centre pass only feeds depth and masks

    int num_hits = 0, num_textured = 0;
    GatherHits(job, t, n, tb, &num_hits, &num_textured);
    if (num_textured > 0) ApplyTextures(job, num_textured, tb);
    const int num_shadow = AmbientAndShadowRays(job, t, s, num_hits, tb);
    if (num_shadow == 0) continue;
    if (job.motion) {  // shadow rays at their camera ray's time (moving objects)
      for (int k = 0; k < num_shadow; ++k)
        tb.shadow[k].time = job.moving ? tb.pixel_time[tb.shadow_pixel[k]] : job.motion->time_mid;
    }
    rtcOccluded1M(d.trace_scene, &shadow_context, tb.shadow, static_cast<unsigned>(num_shadow), sizeof(RTCRay));
    if (raw) continue;
    for (int k = 0; k < num_shadow; ++k) {
      // Embree sets tfar to -inf for occluded rays.
      if (tb.shadow[k].tfar >= 0.0f) tb.sum[tb.shadow_pixel[k]] = _mm_add_ps(tb.sum[tb.shadow_pixel[k]], tb.direct[k]);
    }
  }
  if (!raw) ResolveTile(job, t, tb);
}

}  // namespace

void Tracer::Render(const CameraRays& rays, const Rigid3& world_from_cam, const ShadeSettings& settings,
                    CameraImage* image, const CameraMotion* motion) const {
  const Impl& d = *impl_;
  const int width = rays.width, height = rays.height;
  const size_t num_pixels = static_cast<size_t>(width) * height;
  const bool raw = settings.raw_cast_only;
  if (!raw) {
    image->width = width;
    image->height = height;
    // The resolve writes every pixel (black outside the image circle): no clearing needed.
    if (settings.linear_output) {
      if (image->linear.size() != num_pixels * 3) image->linear.assign(num_pixels * 3, 0.0f);
      image->rgb.clear();
    } else {
      if (image->rgb.size() != num_pixels * 3) image->rgb.assign(num_pixels * 3, 0);
      image->linear.clear();
    }
    image->gray.clear();
    if (settings.want_depth)
      image->depth.assign(num_pixels, 0.0f);
    else
      image->depth.clear();
    if (settings.want_mask)
      image->mask.assign(num_pixels, 0);
    else
      image->mask.clear();
  }
  const int spp = std::max(1, settings.spp);
  const Lighting& light = d.scene.lighting;
  RenderJob job(d, rays, settings, image);
  job.world_from_cam_rot = world_from_cam.RotationMatrix().cast<float>();
  job.origin = ToF(world_from_cam.translation);
  job.motion = motion;
  job.moving = motion && (motion->shutter > 0.0f || motion->readout > 0.0f);
  if (job.moving && (motion->rotation.size() < 2 || motion->origin.size() != motion->rotation.size()))
    throw std::invalid_argument("CameraMotion: a moving camera needs at least two poses");
  job.row_time_scale = job.moving && height > 1 ? motion->readout / static_cast<float>(height - 1) : 0.0f;
  job.spp = spp;
  job.inv_sqrt_spp = 1.0f / std::sqrt(static_cast<float>(spp));
  job.theta_max = static_cast<float>(0.5 * rays.camera.max_fov_deg * M_PI / 180.0);
  job.precomputed_samples = !settings.rotate_pattern && rays.sample_spp == spp;
  job.soft_sun = settings.soft_shadows && d.sun_disc_radius > 0.0f && spp > 1;
  job.textures = settings.textures;
  job.spp_u = static_cast<uint32_t>(spp);
  job.sky_horizon = Load3(light.sky_horizon);
  job.sky_delta = Load3(light.sky_zenith - light.sky_horizon);
  job.sky_ground = Load3(light.ground_albedo.cwiseProduct(light.sky_horizon));
  job.ambient_ground = Load3(light.ambient * d.ground_irradiance);
  job.ambient_delta = Load3(light.ambient * (d.sky_mean - d.ground_irradiance));
  job.sun_radiance = Load3(light.sun_radiance);
  job.sun_disc = settings.sun_disc && light.sun_radiance.maxCoeff() > 0.0f;
  const float sun_radius = static_cast<float>(0.5 * light.sun_angular_diameter_deg * M_PI / 180.0);
  job.sun_var = 0.25f * sun_radius * sun_radius;
  if (settings.sun_aureole && light.sun_radiance.maxCoeff() > 0.0f) {
    auto luminance = [](const Eigen::Vector3f& c) { return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z(); };
    const float sky = static_cast<float>(M_PI) * luminance(light.sky_horizon);
    job.aureole_k = 10.0f * (sky > 0.0f ? std::min(1.0f, luminance(light.sun_radiance) / sky) : 1.0f);
  }
  job.exposure_over_count.assign(spp + 1, 0.0f);
  for (int c = 1; c <= spp; ++c) job.exposure_over_count[c] = light.exposure / static_cast<float>(c);
  for (int s = 0; s < std::min(spp, 64); ++s) job.offsets[s] = CameraRays::SampleOffset(s, spp);
  job.tiles_x = (width + kTile - 1) / kTile;
  job.tiles_y = (height + kTile - 1) / kTile;

  const int num_tiles = job.tiles_x * job.tiles_y;
  tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 16), [&](const tbb::blocked_range<int>& range) {
    SetFlushDenormals();
    thread_local std::unique_ptr<TileBuffers> buffers;
    if (!buffers) buffers = std::make_unique<TileBuffers>();
    for (int tile = range.begin(); tile < range.end(); ++tile) RenderTile(job, tile, *buffers);
  });
}

}  // namespace rovo
