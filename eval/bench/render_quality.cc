// The image-quality studies of `rovo bench render --quality`.
#include "eval/bench/render_quality.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/continuous_trajectory.h"
#include "render/timing.h"
#include "render/tracer.h"
#include "vo/stopwatch.h"

namespace rovo {
namespace {

double MeanAbsDiff(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, const std::vector<uint8_t>& valid) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < valid.size(); ++i) {
    if (!valid[i]) continue;
    for (int c = 0; c < 3; ++c) sum += std::abs(static_cast<int>(a[3 * i + c]) - static_cast<int>(b[3 * i + c]));
    n += 3;
  }
  return n ? sum / n : 0.0;
}

// Camera 0 at frame 0: its rays (pixel centres; sample bearings are interpolated during the render)
// and its pose.
struct FirstView {
  CameraRays rays;
  Rigid3 world_from_cam;
};

// Off-by-more-than-8-codes share of the valid pixels' values.
double ShareOffBy8(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, const std::vector<uint8_t>& valid) {
  size_t off = 0, n = 0;
  for (size_t i = 0; i < valid.size(); ++i) {
    if (!valid[i]) continue;
    for (int c = 0; c < 3; ++c) off += std::abs(a[3 * i + c] - b[3 * i + c]) > 8;
    n += 3;
  }
  return n ? static_cast<double>(off) / n : 0.0;
}

FirstView FirstViewOf(const Scene& scene, const Rig& rig, tbb::task_arena& arena) {
  FirstView view;
  arena.execute([&] { view.rays = CameraRays::Make(rig.cameras[0].camera); });
  view.world_from_cam = scene.rig_trajectory[0].world_from_rig * rig.cameras[0].cam_from_rig.Inverse();
  return view;
}

}  // namespace

void RunQualityStudy(const Scene& scene, const Rig& rig, Tracer& tracer, tbb::task_arena& arena) {
  constexpr int kSteps = 5;
  constexpr int kReferenceSpp = 32;
  const FirstView view = FirstViewOf(scene, rig, arena);
  const CameraRays& rays = view.rays;
  const Rigid3& world_from_cam = view.world_from_cam;
  const size_t centre = static_cast<size_t>(rays.height / 2) * rays.width + rays.width / 2;
  const double step_rad = 0.25 * rays.pixel_angle[centre];
  auto render_steps = [&](const ShadeSettings& settings) {
    std::vector<std::vector<uint8_t>> images;
    for (int k = 0; k < kSteps; ++k) {
      // Yaw about the camera's y axis (image columns shift by about k/4 px at the centre).
      const Rigid3 nudge = Rigid3::FromAxisAngle(Eigen::Vector3d(0, k * step_rad, 0), Eigen::Vector3d::Zero());
      CameraImage image;
      arena.execute([&] {
        tracer.SetFrame(0);
        tracer.Render(rays, world_from_cam * nudge, settings, &image);
      });
      images.push_back(std::move(image.rgb));
    }
    return images;
  };
  auto shimmer = [&](const std::vector<std::vector<uint8_t>>& images, const std::vector<std::vector<uint8_t>>& ref) {
    double sum = 0.0;
    size_t n = 0;
    for (int k = 1; k < kSteps; ++k) {
      for (size_t i = 0; i < rays.valid.size(); ++i) {
        if (!rays.valid[i]) continue;
        for (int c = 0; c < 3; ++c) {
          const int d_img = images[k][3 * i + c] - images[k - 1][3 * i + c];
          const int d_ref = ref[k][3 * i + c] - ref[k - 1][3 * i + c];
          sum += std::abs(d_img - d_ref);
          ++n;
        }
      }
    }
    return n ? sum / n : 0.0;
  };
  ShadeSettings reference_settings;
  reference_settings.spp = kReferenceSpp;
  reference_settings.lod_bias = 0.0f;
  const auto reference = render_steps(reference_settings);

  struct Variant {
    int spp;
    bool trilinear;
    float lod_bias;
    bool rotate;
  };
  const std::vector<Variant> variants = {
      {1, true, 0.0f, false},   {1, true, -0.5f, false},  {1, false, 0.0f, false}, {1, false, -0.5f, false},
      {2, true, -0.5f, false},  {2, false, -0.5f, false}, {2, true, -0.5f, true},  {4, true, -0.5f, false},
      {4, false, -0.5f, false}, {4, true, -0.5f, true},
  };
  std::printf(
      "\nanti-aliasing: camera 0 of frame 0, %dx%d, %d quarter-pixel yaw steps, reference %d spp "
      "(fixed pattern, trilinear, LOD bias 0); 8-bit units, mean over valid pixels and channels\n",
      rays.width, rays.height, kSteps, kReferenceSpp);
  std::printf("| spp | pattern | texture filter | LOD bias | mean abs error | shimmer | CPU s/view |\n");
  std::printf("|---:|---|---|---:|---:|---:|---:|\n");
  for (const Variant& v : variants) {
    ShadeSettings settings;
    settings.spp = v.spp;
    settings.trilinear = v.trilinear;
    settings.lod_bias = v.lod_bias;
    settings.rotate_pattern = v.rotate;
    const double cpu0 = CpuMs();
    const auto images = render_steps(settings);
    const double cpu = (CpuMs() - cpu0) / 1000.0 / kSteps;
    double error = 0.0;
    for (int k = 0; k < kSteps; ++k) error += MeanAbsDiff(images[k], reference[k], rays.valid);
    std::printf("| %d | %s | %s | %+.1f | %.3f | %.3f | %.3f |\n", v.spp,
                v.spp == 1 ? "centre" : (v.rotate ? "per-pixel rotated" : "fixed"),
                v.trilinear ? "trilinear" : "bilinear, nearest level", v.lod_bias, error / kSteps,
                shimmer(images, reference), cpu);
  }
  std::printf("(CPU s/view computes sub-pixel bearings on the fly; rovo render precomputes them per camera)\n");
}

// A 32-spp reference gives every light in reach a shadow ray (kMaxShadowedLights, no share floor).
void RunLightQualityStudy(const Scene& scene, const Rig& rig, Tracer& tracer, tbb::task_arena& arena) {
  if (scene.lights.empty()) return;
  constexpr int kReferenceSpp = 32;
  const FirstView view = FirstViewOf(scene, rig, arena);
  const CameraRays& rays = view.rays;
  const Rigid3& world_from_cam = view.world_from_cam;
  auto render = [&](const ShadeSettings& settings, double* cpu_seconds) {
    CameraImage image;
    const double cpu0 = CpuMs();
    arena.execute([&] {
      tracer.SetFrame(0);
      tracer.Render(rays, world_from_cam, settings, &image);
    });
    if (cpu_seconds) *cpu_seconds = (CpuMs() - cpu0) / 1000.0;
    return image.rgb;
  };
  ShadeSettings reference_settings;
  reference_settings.spp = kReferenceSpp;
  reference_settings.max_shadowed_lights = kMaxShadowedLights;
  reference_settings.min_shadowed_share = 0.0f;
  const std::vector<uint8_t> reference = render(reference_settings, nullptr);
  struct Variant {
    int spp;
    bool sample;
    int max_shadowed;
    float share;
  };
  const std::vector<Variant> variants = {
      {2, false, 2, 0.0f}, {2, false, 2, 0.05f}, {2, false, 2, 0.1f}, {2, false, 2, 0.2f}, {2, false, 1, 0.1f},
      {2, false, 0, 0.0f}, {2, true, 0, 0.0f},   {2, true, 0, 0.1f},  {4, false, 2, 0.1f}, {4, true, 0, 0.1f}};
  std::printf(
      "\npoint and spot lights: camera 0 of frame 0, %dx%d, reference %d spp with a shadow ray to every light in "
      "reach (up to 8 per hit); 8-bit units over valid pixels and channels; off > 8: share of values off by more than "
      "8 codes\n",
      rays.width, rays.height, kReferenceSpp);
  std::printf(
      "| spp | shadow rays | share floor | mean abs error | off > 8 | CPU s/view |\n|---:|---|---:|---:|---:|---:|\n");
  for (const Variant& v : variants) {
    ShadeSettings settings;
    settings.spp = v.spp;
    settings.sample_lights = v.sample;
    settings.max_shadowed_lights = v.max_shadowed;
    settings.min_shadowed_share = v.share;
    double cpu = 0.0;
    const std::vector<uint8_t> image = render(settings, &cpu);
    const std::string rays_text =
        v.sample ? "one to a drawn light per sample"
                 : (v.max_shadowed == 0 ? "none" : "the " + std::to_string(v.max_shadowed) + " strongest");
    std::printf("| %d | %s | %.2f | %.3f | %.4f | %.3f |\n", v.spp, rays_text.c_str(), v.share,
                MeanAbsDiff(image, reference, rays.valid), ShareOffBy8(image, reference, rays.valid), cpu);
  }
}

void RunBlurQualityStudy(const Scene& scene, const Rig& rig, Tracer& tracer, tbb::task_arena& arena,
                         double shutter_ms) {
  if (scene.rig_trajectory.size() < 3) throw std::invalid_argument("--blur-quality: the scene needs 3 frames");
  constexpr int kReferenceSpp = 64;
  const ContinuousTrajectory rig_motion(Trajectory(scene.rig_trajectory.begin(), scene.rig_trajectory.begin() + 3));
  CameraRays rays;
  arena.execute([&] { rays = CameraRays::Make(rig.cameras[0].camera); });
  const double half_window_s = 0.5 * shutter_ms / 1000.0;
  Rigid3 world_from_cam;
  const CameraMotion motion = MakeCameraMotion(rig_motion, 1, rig.cameras[0].cam_from_rig, half_window_s, 0.0,
                                               shutter_ms, 0.0, rays.height, &world_from_cam);
  auto render = [&](const ShadeSettings& settings, double* cpu_seconds, int64_t* samples) {
    CameraImage image;
    const double cpu0 = CpuMs();
    arena.execute([&] {
      tracer.SetFrameWindow(1, half_window_s);
      tracer.Render(rays, world_from_cam, settings, &image, &motion);
    });
    if (cpu_seconds) *cpu_seconds = (CpuMs() - cpu0) / 1000.0;
    if (samples) *samples = image.samples;
    return image.rgb;
  };
  ShadeSettings reference_settings;
  reference_settings.spp = kReferenceSpp;
  const std::vector<uint8_t> reference = render(reference_settings, nullptr, nullptr);
  struct Variant {
    int spp;
    float threshold_codes;  // < 0: fixed
  };
  const std::vector<Variant> variants = {{2, -1.0f}, {4, -1.0f}, {8, -1.0f}, {16, -1.0f}, {8, 4.0f},
                                         {8, 8.0f},  {8, 12.0f}, {16, 8.0f}, {16, 12.0f}};
  std::printf(
      "\nmotion blur: camera 0 of frame 1, %dx%d, global shutter %.1f ms, reference %d spp; 8-bit units over valid "
      "pixels and channels; off > 8: share of values off by more than 8 codes; adaptive: from %d samples, doubling "
      "while the means of their halves differ by more than the threshold\n",
      rays.width, rays.height, shutter_ms, kReferenceSpp, AdaptiveSampling().min_spp);
  std::printf(
      "| spp | sampling | mean spp | mean abs error | off > 8 | CPU s/view |\n|---:|---|---:|---:|---:|---:|\n");
  for (const Variant& v : variants) {
    ShadeSettings settings;
    settings.spp = v.spp;
    settings.adaptive.enabled = v.threshold_codes >= 0.0f;
    settings.adaptive.threshold = v.threshold_codes / 255.0f;
    double cpu = 0.0;
    int64_t samples = 0;
    const std::vector<uint8_t> image = render(settings, &cpu, &samples);
    char sampling[64];
    if (settings.adaptive.enabled)
      std::snprintf(sampling, sizeof(sampling), "adaptive, threshold %.0f codes", v.threshold_codes);
    else
      std::snprintf(sampling, sizeof(sampling), "fixed");
    std::printf("| %d | %s | %.2f | %.3f | %.4f | %.3f |\n", v.spp, sampling,
                static_cast<double>(samples) / std::max(1, rays.num_valid), MeanAbsDiff(image, reference, rays.valid),
                ShareOffBy8(image, reference, rays.valid), cpu);
  }
}

}  // namespace rovo
