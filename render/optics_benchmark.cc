// Cost of the lens optics (render/optics.h) per full-size camera image (rovo4, 1600x1532), one thread:
// each effect alone and the realistic profile. A frame of the rig is four such images.
// Run: build/render/rovo_render_benchmark
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <random>
#include <vector>

#include "datasets/rig.h"
#include "render/optics.h"
#include "render/tracer.h"

namespace rovo {
namespace {

const CameraRays& Rays() {
  static const CameraRays rays = CameraRays::Make(MakeRigPreset("rovo4").cameras[0].camera, 1, 1);
  return rays;
}

// The realistic profile with only effect `which` on (0 blur, 1 lateral colour, 2 vignetting, 3 glare,
// 4 all).
OpticsSettings Effect(int which) {
  OpticsSettings s = OpticsProfile("realistic");
  if (which == 4) return s;
  if (which != 0) s.mtf50_centre = s.mtf50_rim = 0.0;
  if (which != 1) s.lateral_ca_red = s.lateral_ca_blue = 0.0;
  if (which != 2) s.falloff_angle_scale = 0.0, s.rim_illumination = 1.0;
  if (which != 3) s.veiling_glare = 0.0;
  return s;
}

void BM_OpticsApply(benchmark::State& state) {
  const CameraRays& rays = Rays();
  const LensOptics lens(Effect(static_cast<int>(state.range(0))), rays.camera, rays.bearing, rays.valid, 1.0);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> image(rays.valid.size() * 3);
  for (float& v : image) v = u(rng);
  tbb::task_arena one(1);
  for (auto _ : state) {
    std::vector<float> work = image;
    one.execute([&] { lens.Apply(&work); });
    benchmark::DoNotOptimize(work.data());
  }
}
// 0 blur, 1 lateral colour, 2 vignetting, 3 glare, 4 the realistic profile.
BENCHMARK(BM_OpticsApply)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

// The copy of the image that BM_OpticsApply makes on every iteration (subtract it).
void BM_ImageCopy(benchmark::State& state) {
  std::vector<float> image(Rays().valid.size() * 3, 0.5f);
  for (auto _ : state) {
    std::vector<float> work = image;
    benchmark::DoNotOptimize(work.data());
  }
}
BENCHMARK(BM_ImageCopy)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rovo
