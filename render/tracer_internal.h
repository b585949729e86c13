#pragma once
// What the tracer's source files share (render/tracer.h is the interface): the scene state
// Tracer::Impl, the sampler's hashes, one Render call's job and tile buffers, and the steps of a tile.
// camera_rays.cc: pixel bearings and sample rays; scene_build.cc: the Embree scenes and frames;
// sky.cc: sun, sky and ambient terms; lights.cc: point and spot lights; shading.cc: the shading
// passes; film.cc: the resolve into an image; tracer.cc: tiles and Render.

#include <embree3/rtcore.h>
#include <xmmintrin.h>

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/tracer.h"

namespace rovo {
namespace tracer_internal {

constexpr int kTile = 8;
constexpr int kTilePixels = kTile * kTile;
constexpr float kInvPi = 0.318309886f;
constexpr int kSunSamples = 64;  // points of the soft-shadow sun-disc sequence
// Lanes (lights of the blocks near a hit, lit or not) a hit ranks or draws from; blocks that light
// nothing make room, and the lights beyond are added without a shadow ray.
constexpr int kMaxLightLanes = 256;
// A Blinn-Phong factor max(0, n.h)^m below this is taken as 0 (render/tracer.h).
constexpr float kNegligibleHighlight = 1e-7f;

// splitmix64: the per-pixel hash behind the fixed sample patterns and the soft-shadow sun samples.
inline uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

inline float UnitFloat(uint64_t bits) { return static_cast<float>(bits >> 40) * (1.0f / 16777216.0f); }

inline float RadicalInverse2(uint32_t i) {
  i = (i << 16) | (i >> 16);
  i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
  i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
  i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
  return static_cast<float>(i) * (1.0f / 4294967296.0f);
}

// Second dimension of the Sobol (0,2)-sequence (generator: Pascal's triangle mod 2).
inline float Sobol2(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
    if (i & 1u) r ^= v;
  return static_cast<float>(r) * (1.0f / 4294967296.0f);
}

inline float Wrap01(float x) { return x - std::floor(x); }

inline Eigen::Vector3f ToF(const Eigen::Vector3d& v) { return v.cast<float>(); }

}  // namespace tracer_internal

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

  RTCScene trace_scene = nullptr;                                         // static_scene when nothing moves, else top
  std::array<Eigen::Vector3f, tracer_internal::kSunSamples> sun_samples;  // unit directions inside the sun disc
  Eigen::Vector3f sun_dir, sun_e1, sun_e2;
  float sun_disc_radius = 0.0f;  // tan(angular diameter / 2)
  Eigen::Vector3f sky_mean, ground_irradiance;
  bool sun_on = true;  // false when sun_radiance is zero: no sun term, no sun shadow rays

  // Point and spot lights at the current frame, in world coordinates (render/tracer.h).
  struct ShadeLight {
    Eigen::Vector3f position = Eigen::Vector3f::Zero();
    Eigen::Vector3f intensity = Eigen::Vector3f::Zero();
    float inv_range2 = 0.0f;  // 1 / range^2; 0: no cut-off
    bool spot = false;
    Eigen::Vector3f spot_axis = Eigen::Vector3f::UnitZ();  // unit, world
    float spot_cos = -1.0f, spot_smooth = 0.0f;            // cos(angle / 2), (1 - spot_cos) * blend
  };
  std::vector<ShadeLight> lights;
  bool lights_move = false;  // some light rides on a dynamic object: re-placed on every SetFrame
  // Four lights in structure-of-arrays form, the unit of the lights' SSE loop (lights.cc). Unused
  // lanes have light = kNoLight and lie far outside their range.
  struct LightBlock {
    static constexpr uint32_t kNoLight = 0xffffffffu;
    alignas(16) float px[4], py[4], pz[4];
    float inv_range2[4];        // 0: no cut-off
    float ax[4], ay[4], az[4];  // spot axis (unit); 0 for point lights
    float spot_cos[4];          // cos(angle / 2); -2 for point lights
    float inv_smooth[4];        // 1 / ((1 - spot_cos) * blend); +inf without a blend
    float is_spot[4];           // all bits set for a spot, 0 for a point light
    float ir[4], ig[4], ib[4];  // intensity
    uint32_t light[4];          // index into lights
  };
  // The lights that may reach each cell of a 3-D grid of cubes (range sphere and spot cone), as
  // blocks of four (CSR lists, cell index (z * ny + y) * nx + x), and the lights without a range
  // (tested everywhere), as blocks too.
  struct LightGrid {
    float x0 = 0.0f, y0 = 0.0f, z0 = 0.0f, inv_cell = 1.0f;
    int nx = 0, ny = 0, nz = 0;
    std::vector<uint32_t> cell_begin;  // nx * ny * nz + 1, into blocks
    std::vector<LightBlock> blocks;
    std::vector<LightBlock> unbounded;
  } light_grid;
  // Per material: emission (r, g, b, 0), Blinn-Phong specular and shininess.
  bool any_emission = false;
  std::vector<std::array<float, 4>> material_emission;
  std::vector<float> material_specular, material_shininess;
  std::vector<float> material_highlight_floor;  // kNegligibleHighlight^(1 / shininess); 0 without a highlight

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

  // A triangle geometry of `mesh`, in world coordinates when world_from_object is given.
  RTCGeometry MakeTriangles(const Mesh& mesh, const Rigid3* world_from_object, RTCBuildQuality quality);
};

namespace tracer_internal {

// A tile's rays and the shading state between its passes (structures of arrays; colours are SSE
// registers (r, g, b, 0): every lane operation is the scalar one, so results do not depend on it).
// A hit casts at most one sun and kMaxShadowedLights light shadow rays.
constexpr int kMaxShadowRays = kTilePixels * (1 + kMaxShadowedLights);

struct alignas(64) TileBuffers {
  RTCRayHit rayhit[kTilePixels];
  RTCRay shadow[kMaxShadowRays];
  RTCRay shadow_scratch[kMaxShadowRays];   // the shadow rays not cast as packets, contiguous
  int pixel[kTilePixels];                  // tile-local pixel index of each ray
  int shadow_pixel[kMaxShadowRays];        // tile-local pixel index of each shadow ray
  uint32_t shadow_target[kMaxShadowRays];  // what each shadow ray is cast towards: 0 the sun, i + 1 light i
  __m128 direct[kMaxShadowRays];           // the light each shadow ray lets through (sun: albedo * E_sun * cos / pi)
  __m128 sum[kTilePixels];                 // linear radiance sums per pixel
  int count[kTilePixels];
  float pixel_time[kTilePixels];  // ray time of each pixel's ray in the current pass (CameraMotion)
  // Adaptive sampling (AdaptiveSampling): pixels still taking samples, and their sums and counts at
  // the end of the current stage's first half.
  uint8_t active[kTilePixels];
  __m128 sum_half[kTilePixels];
  int count_half[kTilePixels];
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

inline void InitRay(RTCRayHit* rh, const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float time = 0.0f) {
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

inline __m128 Load3(const Eigen::Vector3f& v) { return _mm_setr_ps(v.x(), v.y(), v.z(), 0.0f); }

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
  float inv_spp = 1.0f, inv_sqrt_spp = 1.0f;
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
  std::array<float, 64> adaptive_stratum{};  // adaptive sampling: sample s's time and light-choice stratum
  int tiles_x = 0, tiles_y = 0;
  // Adaptive sampling (AdaptiveSampling) of this call: on, the first stage's sample count, the
  // spread threshold and the factor to output full scale.
  bool adaptive = false;
  int min_spp = 1;
  float adaptive_threshold = 0.0f, output_scale = 1.0f;
  mutable std::atomic<int64_t> samples{0};  // camera-ray samples traced (CameraImage::samples)
};

// The stratum of sample s in [0, 1) in the order of adaptive sampling (CameraRays::AdaptiveSample; else
// the samples take (s + 1/2) / spp).
inline float AdaptiveStratum(const RenderJob& job, int s) { return job.adaptive_stratum[s]; }

// One tile's pixel rectangle.
struct TileRect {
  int tx0, ty0, tw, th;
  size_t Pixel(const RenderJob& job, int local) const {
    return static_cast<size_t>(ty0 + local / kTile) * job.width + tx0 + local % kTile;
  }
};

// camera_rays.cc: the camera rays of sample s (-1 or spp == 1: pixel centres) of the tile's valid
// pixels into tb.rayhit / tb.pixel; returns their count.
int MakeSampleRays(const RenderJob& job, const TileRect& t, int s, bool is_centre, TileBuffers& tb);

// sky.cc: the sky, sun and ambient constants of one Render call.
void SetSkyTerms(const Tracer::Impl& d, const ShadeSettings& settings, RenderJob* job);
// sky.cc: the radiance a miss along unit `dir` sees from pixel pi (sky, aureole, sun disc).
__m128 MissRadiance(const RenderJob& job, const Eigen::Vector3f& dir, size_t pi);

// Appends a shadow ray from `org` along unit `dir` over (tnear, tfar) that adds `direct` to pixel
// `local` when nothing blocks it.
inline void PushShadowRay(TileBuffers& tb, int* num_shadow, const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                          float tnear, float tfar, int local, __m128 direct, uint32_t target) {
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
  tb.shadow_target[*num_shadow] = target;
  tb.direct[*num_shadow] = direct;
  ++*num_shadow;
}

// lights.cc: point and spot lights at hit h (formula and light choice: render/tracer.h): with
// ShadeSettings::sample_lights one light drawn at `u` in [0, 1) gets a shadow ray from
// `shadow_origin`, else the `max_shadowed_lights` strongest do and the others are added at once.
void AddPointLights(const RenderJob& job, int h, const Eigen::Vector3f& x, const Eigen::Vector3f& view,
                    const Eigen::Vector3f& shadow_origin, float offset, float u, int local, TileBuffers& tb,
                    int* num_shadow);

// shading.cc: the three shading passes of a sample (see there).
void GatherHits(const RenderJob& job, const TileRect& t, int n, TileBuffers& tb, int* num_hits_out,
                int* num_textured_out);
void ApplyTextures(const RenderJob& job, int num_textured, TileBuffers& tb);
int AmbientAndShadowRays(const RenderJob& job, const TileRect& t, int s, int num_hits, TileBuffers& tb);

// film.cc: sizes and clears the image's buffers for a render of width x height.
void PrepareImage(const ShadeSettings& settings, int width, int height, CameraImage* image);
// film.cc: box filter, exposure (or the linear output), vignetting, encoding of the tile.
void ResolveTile(const RenderJob& job, const TileRect& t, const TileBuffers& tb);

}  // namespace tracer_internal
}  // namespace rovo
