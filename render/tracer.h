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
// Shading (linear RGB, then exposure and sRGB; with ShadeSettings::linear_output the linear RGB
// goes to the sensor model, render/sensor.h):
//   L = albedo * ( E_sun * max(0, n.s) * V / pi + ambient * E_sky(n) ),
//   albedo = material base colour * texture (trilinear mip lookup), n faces the viewer,
//   s = direction to the sun (jittered inside the sun disc per sample for soft shadows),
//   V = shadow-ray visibility, E_sky(n) = mix(ground, sky, (1 + n.z) / 2) with
//   sky = (zenith + horizon) / 2 and ground = ground_albedo * (E_sun * s.z / pi + sky).
// Point and spot lights (Scene::lights, intensity I in linear RGB W/sr-like units, position p at
// the frame, for objects that move: world_from_object(frame) * position) add, at a hit x with unit
// normal n facing the viewer, view direction v (towards the camera), l = (p - x) / d, d = |p - x|:
//   L += (albedo / pi + ks * (m + 8) / (8 pi) * max(0, n.h)^m) * I * max(0, n.l) / d^2 * A * W * V,
//   h = normalize(l + v), ks = Material::specular, m = Material::shininess (Blinn-Phong, normalized;
//   max(0, n.h)^m is taken as 0 below 1e-7),
//   A = 1 for a point light; for a spot with axis a, c = -l.a, c0 = cos(angle / 2),
//       s = (1 - c0) * blend: A = 0 if c <= c0, else c * smoothstep((c - c0) / s) if c - c0 < s,
//       else c (Cycles 3.4's spot_light_attenuation, so Blender spots keep their look),
//   W = (1 - (d / range)^4)^2 for d < range, 0 beyond (W = 1 when range = 0),
//   V = shadow-ray visibility towards p (stopped 1 mm short of it).
// Light choice: the lights that reach a hit are those with w_i > 0, w_i = r + g + b of the term above
// without V. Per hit, the ShadeSettings::max_shadowed_lights (default 2) with the largest w_i whose
// share w_i / sum_j w_j is at least ShadeSettings::min_shadowed_share (default 0) get a shadow ray
// each; the others are added without one (V = 1), which keeps the image continuous where the
// ranking changes. With ShadeSettings::sample_lights (a study setting: noisier at equal spp, see
// render/README.md) each sample casts one shadow ray instead, to a light drawn among those at or above
// the share with probability p_i = w_i / sum w (inverse CDF in grid order at u = frac((s + 1/2) / spp
// + r_p), r_p a hashed per-pixel offset: stratified over the pixel's samples), adding its term / p_i.
// Where more than 256 lights in the blocks near a hit (lit or not, after dropping blocks that light
// nothing) would be ranked, the further ones are added without a shadow ray. Lights are found
// through a 3-D grid of cubes listing the lights that may reach each cube (range sphere, spot cone);
// lights without a range are tested at every hit. A material's emission (radiance) is added to every
// hit on it. The sun term is skipped when sun_radiance is zero. A Blender point or spot lamp of power
// P watts is I = colour * P / (4 pi).
// The raw-cast benchmark (ShadeSettings::raw_cast_only) casts no light shadow rays.
// Rays that miss see the sky: mix(horizon, zenith, sqrt(d.z)) above the horizon and
// ground_albedo * horizon below. With ShadeSettings::sun_disc they also see the sun, an HDR disc
// of angular radius r (half of Lighting::sun_angular_diameter_deg) seen through the pixel's
// footprint, a Gaussian of standard deviation f = pixel_angle / 2 (per axis):
//   L_sun(d) = E_sun / (2 pi s^2) * exp(-|d - s_dir|^2 / (2 s^2)),  s^2 = r^2 / 4 + f^2,
// zero where |d - s_dir|^2 >= 50 s^2 (d unit ray direction, s_dir unit direction to the sun). Over
// the sphere it integrates to E_sun (the sun's irradiance) at any image size and sample count, so
// the small auto-exposure meter render sees the same sun as the image. With ShadeSettings::
// sun_aureole the sky above the horizon also brightens around the sun, after the forward term of
// the CIE standard clear sky's scattering indicatrix (ISO 15469 / CIE S 011, c = 10, d = -3):
//   L_sky'(d) = L_sky(d) * (1 + k * exp(-3 gamma)),  k = 10 * min(1, Y(E_sun) / (pi * Y(sky_horizon))),
// gamma the angle from d to the sun (radians) and Y the luminance: 11x the sky's radiance at the
// sun, 2.5x at 20 deg; k shrinks when the sky outshines the sun (overcast presets). It is seen, it
// lights no surface.
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
// always come from the pixel-centre ray. Every pixel's value depends only on its own samples (with
// AdaptiveSampling also on how many its tile's pixels decide to take), so images are identical for any
// thread count.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "datasets/camera.h"
#include "datasets/rigid3.h"
#include "render/texture.h"
#include "scenes/scene.h"

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
  // Sample s of adaptive sampling's order for a power-of-two spp >= 2 (AdaptiveSampling): offset from
  // the pixel centre in [-1/2, 1/2)^2 and, in *stratum, its stratum in [0, 1) for the exposure time and
  // the light choice. Samples come in pairs mirrored through the pixel centre (2j and 2j + 1); on the
  // grid of N = spp strata per axis, pair j's first sample is at column bitrev_{m-1}(j) xor (N/4 - 1)
  // and row bitrev_m(j xor j/2) xor (N/4 - 1) (m = log2 N; masks 0 for N = 2), centres of strata. So
  // every prefix of 2^k samples, and each half of it, has one sample per 1/2^k of each axis and is
  // centred on the pixel, and the N strata are the fixed pattern's (s + 1/2) / N.
  static Eigen::Vector2f AdaptiveSample(int s, int spp, float* stratum);
};

// The camera rays of each camera of a rig; cameras with identical intrinsics share one table.
using RigCameraRays = std::vector<std::shared_ptr<const CameraRays>>;

// CameraRays::Make for each camera of a rig; cameras with identical intrinsics (model, size,
// parameters, FOV) share one computation and one table.
RigCameraRays MakeCameraRays(const std::vector<Camera>& cameras, int threads = 0, int spp = 1);

// Upper bound of ShadeSettings::max_shadowed_lights (sizes the per-tile shadow-ray buffers).
inline constexpr int kMaxShadowedLights = 8;

// Adaptive sampling (ShadeSettings::adaptive): a pixel takes min_spp samples, then doubles its count
// while its samples so far disagree, up to ShadeSettings::spp. At the end of each stage (min_spp,
// 2 min_spp, ... samples) the pixel compares the means of the stage's two halves (with min_spp = 2 its
// two samples): it goes on when they differ by more than `threshold` after the encoding
// sqrt(clamp(output_scale * Y, 0, 1)) (Y the luminance, Rec. 709; output_scale takes linear radiance
// to the output's full scale, 0: Lighting::exposure, the default path's), or when a 4-neighbour in its
// 8x8 tile's do. sqrt stands for the output's gamma, so `threshold` is about 8-bit codes / 255.
// Samples come in CameraRays::AdaptiveSample's order (offset and stratum of sample s): every prefix and
// half of 2^k samples is stratified in the pixel and in the exposure and centred on the pixel, so a
// pixel that stops early is not shifted. With a shutter sample s is at the exposure fraction
// frac(stratum_s + r_p) (r_p as in CameraMotion); the light choice's uniform is rotated the same way.
// The texture level of detail stays that of spp samples (pixels that stop early filter less).
// Applies where AdaptiveApplies, with no rotated pattern and not the raw cast; the decisions are per
// tile, so images do not depend on the thread count.
struct AdaptiveSampling {
  bool enabled = false;
  int min_spp = 2;            // a power of two >= 2
  float threshold = 0.0f;     // difference of the halves' means in sqrt-encoded output units
  float output_scale = 0.0f;  // linear radiance -> output full scale; 0: Lighting::exposure
};

// Whether `adaptive` applies to a render of `spp` samples per pixel: enabled, spp a power of two in
// (min_spp, 64], min_spp a power of two >= 2 (Tracer::Render also needs no rotated pattern and not the
// raw cast).
bool AdaptiveApplies(const AdaptiveSampling& adaptive, int spp);

struct ShadeSettings {
  int spp = 1;
  bool shadows = true;
  bool soft_shadows = true;  // sample the sun disc (Lighting::sun_angular_diameter_deg)
  bool textures = true;
  bool trilinear = true;        // texture lookups blend two mip levels; false = bilinear on the nearest level
  bool rotate_pattern = false;  // per-pixel hashed rotation of the sample pattern (quality study)
  float lod_bias = -0.5f;       // added to the texture level of detail (measured: render/README.md)
  bool want_depth = false;      // fill CameraImage::depth
  bool want_mask = false;       // fill CameraImage::mask
  bool raw_cast_only = false;   // benchmark: intersect the camera rays, no shading, no output
  float vignetting = 0.0f;      // optional: gain = 1 - vignetting * (theta / theta_max)^2
  // The sensor model's input (render/sensor.h): fill CameraImage::linear with the box-filtered
  // scene radiance times the vignetting gain (no Lighting::exposure, no encoding) instead of rgb.
  bool linear_output = false;
  // Misses see the sun as well as the sky (the HDR sun of the sensor model, formula above).
  bool sun_disc = false;
  // Misses above the horizon see the circumsolar aureole (formula above); needs a sun.
  bool sun_aureole = false;
  // Point and spot lights (the file comment, "Light choice"): per hit, the max_shadowed_lights
  // strongest lights whose share of the hit's unshadowed light is at least min_shadowed_share get a
  // shadow ray each, the others are added without one; with sample_lights, one shadow ray per sample
  // to a light drawn among those at or above the share instead.
  bool sample_lights = false;
  float min_shadowed_share = 0.0f;
  int max_shadowed_lights = 2;  // in [0, kMaxShadowedLights]
  // Adaptive sampling (AdaptiveSampling): `spp` is the most a pixel takes.
  AdaptiveSampling adaptive;
};

// Time-dependent camera pose of one Render call (motion blur, rolling shutter, trigger offsets;
// the rules are in datasets/FORMAT.md, section "Timing"). Times are ray times in [0, 1], Embree's
// RTCRay::time, spanning the frame's time window set by Tracer::SetFrameWindow. Row v (0 = top) of
// the image is exposed around tau_v = time_mid + (v / (H - 1) - 1/2) * readout; sample s of pixel
// p (spp > 1) is at tau_v + (w - 1/2) * shutter with w = frac((s + 1/2) / spp + r_p) (with adaptive
// sampling frac(stratum_s + r_p), AdaptiveSampling), r_p a hashed
// per-pixel rotation (stratified in time, uncorrelated between pixels); the pixel-centre ray
// (depth, masks, and the only sample when spp = 1) is at tau_v. The ray at time tau starts at
// origin(tau) along rotation(tau) * bearing, both linearly interpolated in the table below. With
// shutter = readout = 0 every ray is at time_mid and uses Render's world_from_cam.
struct CameraMotion {
  float time_mid = 0.5f;  // ray time of the mid-exposure of the image's middle row
  float readout = 0.0f;   // rolling shutter: top-to-bottom readout, in ray-time units
  float shutter = 0.0f;   // exposure interval, in ray-time units
  // world_from_cam at ray times k / (n - 1), k = 0 .. n - 1 (n >= 2 unless shutter = readout = 0).
  std::vector<Eigen::Matrix3f> rotation;
  std::vector<Eigen::Vector3f> origin;
};

struct CameraImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;    // sRGB, 3 bytes per pixel (empty with ShadeSettings::linear_output)
  std::vector<float> linear;   // ShadeSettings::linear_output: linear RGB radiance, 3 floats per pixel
  std::vector<uint8_t> gray;   // a grayscale sensor's output, 1 byte per pixel (render/sensor.h)
  std::vector<float> depth;    // metres along the pixel-centre ray, 0 = no hit / outside FOV
  std::vector<uint16_t> mask;  // Object::id of the pixel-centre hit, 0 = static or none
  int64_t samples = 0;         // camera-ray samples traced (without the depth/mask centre pass)
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
  // Motion of the dynamic objects over the window [t - half_window_s, t + half_window_s] around
  // trajectory frame `frame` at time t: three Embree time steps (ray time 0, 1/2, 1) with each
  // object's pose at those times (PoseAtTime, render/timing.h); Embree interpolates the 3x4
  // matrices linearly between steps. half_window_s <= 0 is SetFrame(frame). Lights on objects are
  // placed at t.
  void SetFrameWindow(int frame, double half_window_s);

  // Renders one camera at world_from_cam. Work is split into 8x8 tiles run by tbb::parallel_for in
  // the calling task arena. Sets flush-to-zero / denormals-are-zero in every worker.
  // With `motion`, rays take their times and poses from it (CameraMotion) and world_from_cam is
  // the pose at motion->time_mid.
  void Render(const CameraRays& rays, const Rigid3& world_from_cam, const ShadeSettings& settings, CameraImage* image,
              const CameraMotion* motion = nullptr) const;

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
