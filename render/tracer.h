#pragma once
// The Embree fisheye ray tracer behind `rovo render`.
//
// Acceleration structure: all static objects (transformed to world) share one Embree scene built
// once with RTC_BUILD_QUALITY_HIGH. Each mesh used by a dynamic object gets its own object-space
// scene. A small top-level scene holds one identity instance of the static scene plus one instance
// per dynamic object; SetFrame() only updates the dynamic instances' world_from_object transforms
// and recommits the top level (the static BVH is never rebuilt).
//
// Camera rays: for camera c with pose world_from_rig at the frame,
//   world_from_cam = world_from_rig * cam_from_rig.Inverse(),
//   ray origin = world_from_cam.translation, direction = world_from_cam.rotation * bearing(uv),
// with bearing(uv) = Camera::Unproject(uv), precomputed at every pixel centre (CameraRays). A
// sub-pixel sample bearing is the normalized bilinear interpolation of the four surrounding
// pixel-centre bearings (exact Unproject near the image-circle edge); for the fixed sample
// pattern these are precomputed per camera too (CameraRays::Make with spp > 1). Pixels whose
// centre does not unproject are black, depth 0, mask 0. Scenes without dynamic objects are traced
// in the static scene directly (no instance level).
//
// Shading (linear RGB, then exposure and sRGB):
//   L = albedo * ( E_sun * max(0, n.s) * V / pi + ambient * E_sky(n) ),
//   albedo = material base colour * texture (trilinear mip lookup), n faces the viewer,
//   s = direction to the sun (jittered inside the sun disc per sample for soft shadows),
//   V = shadow-ray visibility, E_sky(n) = mix(ground, sky, (1 + n.z) / 2) with
//   sky = (zenith + horizon) / 2 and ground = ground_albedo * (E_sun * s.z / pi + sky).
// Rays that miss see the sky: mix(horizon, zenith, sqrt(d.z)) above the horizon and
// ground_albedo * horizon below.
// Texture level of detail: ray-cone footprint f = t * pixel_angle / max(|cos|, 0.1) / sqrt(spp)
// in metres, times texels per metre of the triangle, sqrt(A_uv / A_world) * sqrt(W * H).
//
// Samples: `spp` sub-pixel positions per pixel, box filter. Default pattern: the same N-rooks
// (Hammersley) offsets in every pixel, SampleOffset(s, spp) = ((s + 1/2) / N - 1/2,
// frac(radinv2(s) + 1/(2N)) - 1/2) (N = 2: the two diagonal quarter points, N = 4: a rotated
// grid). ShadeSettings::rotate_pattern instead adds a per-pixel hashed Cranley-Patterson
// rotation (aliasing traded for noise). With spp = 1 the sample is the pixel centre. Soft-shadow
// sun directions (spp > 1) come from a 64-point (0,2)-sequence on the sun disc: each pixel takes
// a hashed, spp-aligned block of spp consecutive points (stratified for power-of-two spp). Depth and mask
// always come from the pixel-centre ray. Every pixel's value depends only on its own samples, so
// images are identical for any thread count.

#include "datasets/camera.h"
#include "datasets/rigid3.h"
#include "render/texture.h"
#include "scenes/scene.h"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <vector>

namespace rovo {

// Per-camera precomputation: the pixel-centre bearings and angular pixel sizes.
struct CameraRays {
  Camera camera;
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector3f> bearing;  // unit, camera frame; zero where invalid
  std::vector<uint8_t> valid;            // 1 where the pixel centre unprojects
  std::vector<float> pixel_angle;        // radians between neighbouring pixel centres
  int num_valid = 0;

  // Bearings of the fixed sub-pixel samples: sample_bearing[s][pixel] for s < sample_spp
  // (zero where the sample does not unproject); empty unless Make() got 1 < spp <= kMaxPrecomputedSpp.
  static constexpr int kMaxPrecomputedSpp = 4;  // 12 bytes per pixel and sample; more are interpolated per render
  int sample_spp = 0;
  std::vector<std::vector<Eigen::Vector3f>> sample_bearing;

  // Unprojects every pixel centre (parallel, `threads` 0 = all cores); with 1 < spp <=
  // kMaxPrecomputedSpp also the bearings of the fixed `spp`-sample pattern.
  static CameraRays Make(const Camera& camera, int threads = 0, int spp = 1);
  // Bearing of the continuous pixel position (u, v); false outside the field of view.
  bool SampleBearing(float u, float v, Eigen::Vector3f* bearing_out) const;
  // Offset from the pixel centre, in pixels within [-1/2, 1/2)^2, of sample s of the fixed
  // `spp`-sample pattern (see the file comment); (0, 0) for spp = 1.
  static Eigen::Vector2f SampleOffset(int s, int spp);
};

// CameraRays::Make for each camera of a rig; cameras with identical intrinsics (model, size,
// parameters, FOV) share one computation (copied).
std::vector<CameraRays> MakeCameraRays(const std::vector<Camera>& cameras, int threads = 0, int spp = 1);

struct ShadeSettings {
  int spp = 1;
  bool shadows = true;
  bool soft_shadows = true;     // sample the sun disc (Lighting::sun_angular_diameter_deg)
  bool textures = true;
  bool trilinear = true;        // texture lookups blend two mip levels; false = bilinear on the nearest level
  bool rotate_pattern = false;  // per-pixel hashed rotation of the sample pattern (quality study)
  float lod_bias = -0.5f;       // added to the texture level of detail (measured: render/README.md)
  bool want_depth = false;      // fill CameraImage::depth
  bool want_mask = false;       // fill CameraImage::mask
  bool raw_cast_only = false;   // benchmark: intersect the camera rays, no shading, no output
  float noise_sigma = 0.0f;     // optional sensor noise (std. dev. in 8-bit units); 0 = off
  uint64_t noise_seed = 0;
  float vignetting = 0.0f;      // optional: gain = 1 - vignetting * (theta / theta_max)^2
};

struct CameraImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;      // sRGB, 3 bytes per pixel
  std::vector<float> depth;      // metres along the pixel-centre ray, 0 = no hit / outside FOV
  std::vector<uint16_t> mask;    // Object::id of the pixel-centre hit, 0 = static or none
};

class Tracer {
 public:
  // Builds the Embree scenes. `scene` must outlive the tracer. Throws std::invalid_argument naming
  // the mesh/object/material on inconsistent indices.
  explicit Tracer(const Scene& scene);
  ~Tracer();
  Tracer(const Tracer&) = delete;
  Tracer& operator=(const Tracer&) = delete;

  // Places the dynamic objects at trajectory frame `frame` and commits the top-level scene.
  void SetFrame(int frame);

  // Renders one camera at world_from_cam. Work is split into 8x8 tiles run by tbb::parallel_for in
  // the calling task arena. Sets flush-to-zero / denormals-are-zero in every worker.
  void Render(const CameraRays& rays, const Rigid3& world_from_cam, const ShadeSettings& settings,
              CameraImage* image) const;

  double static_build_seconds() const { return static_build_seconds_; }
  size_t num_static_triangles() const { return num_static_triangles_; }

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  double static_build_seconds_ = 0.0;
  size_t num_static_triangles_ = 0;
};

// Sets MXCSR flush-to-zero and denormals-are-zero for the calling thread.
void SetFlushDenormals();

}  // namespace rovo
