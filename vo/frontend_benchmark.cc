// Front-end speed at full size (rovo4: 4 x 1600x1532 ocam views) on textured synthetic images that
// move by one pixel per frame. Reports ms per frame by stage as counters (warp, track, detect,
// match), wall (ms_*) and process CPU time of all threads (cpu_ms_*), and the CPU time per frame
// (cpu_ms). Run: build/vo/rovo_vo_benchmark --benchmark_filter=Frontend
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "datasets/rig.h"
#include "tests/vo/blurred_noise.h"
#include "vo/frontend.h"
#include "vo/interview_matching.h"
#include "vo/opencv_threads.h"

namespace rovo {
namespace {

cv::Mat Texture(int width, int height, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image = BlurredNoise(width, height, rng);
  for (int k = 0; k < 3000; ++k) {
    cv::rectangle(image,
                  cv::Rect(rng.uniform(0, width), rng.uniform(0, height), rng.uniform(8, 50), rng.uniform(8, 50)),
                  cv::Scalar(rng.uniform(0, 255)), cv::FILLED);
  }
  return image;
}

void BM_FrontendFullSize(benchmark::State& state) {
  const Rig rig = MakeRigPreset("rovo4");
  FrontendOptions options;
  options.target_features_per_view = static_cast<int>(state.range(0));
  options.klt_window_px = static_cast<int>(state.range(1));
  options.klt_levels = static_cast<int>(state.range(2));
  options.projection.focal_scale = 0.01 * static_cast<double>(state.range(3));
  Frontend frontend(rig, options);
  std::vector<std::vector<cv::Mat>> frames(2);
  for (int i = 0; i < rig.NumCameras(); ++i) {
    const cv::Mat base = Texture(rig.cameras[i].camera.width + 4, rig.cameras[i].camera.height + 4, 100 + i);
    for (int k = 0; k < 2; ++k) {
      frames[k].push_back(base(cv::Rect(k, k, rig.cameras[i].camera.width, rig.cameras[i].camera.height)).clone());
    }
  }
  frontend.Process(frames[0]);
  double warp = 0, track = 0, detect = 0, match = 0;
  double cpu_warp = 0, cpu_track = 0, cpu_detect = 0, cpu_match = 0;
  int64_t iterations = 0, features = 0;
  const std::clock_t cpu_start = std::clock();  // process CPU time, all threads
  for (auto _ : state) {
    const FrontendFrame frame = frontend.Process(frames[(iterations + 1) % 2]);
    warp += frame.ms_warp;
    track += frame.ms_track;
    detect += frame.ms_detect;
    match += frame.ms_match;
    cpu_warp += frame.cpu_ms_warp;
    cpu_track += frame.cpu_ms_track;
    cpu_detect += frame.cpu_ms_detect;
    cpu_match += frame.cpu_ms_match;
    for (const auto& f : frame.features_per_camera) features += static_cast<int64_t>(f.size());
    ++iterations;
  }
  // CPU time of all threads per frame: on a loaded machine wall time says little; cpu_ms / 2 is the
  // wall time two free cores would need at perfect scaling.
  state.counters["cpu_ms"] = 1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / iterations;
  state.counters["ms_warp"] = warp / iterations;
  state.counters["ms_track"] = track / iterations;
  state.counters["ms_detect"] = detect / iterations;
  state.counters["ms_match"] = match / iterations;
  state.counters["cpu_ms_warp"] = cpu_warp / iterations;
  state.counters["cpu_ms_track"] = cpu_track / iterations;
  state.counters["cpu_ms_detect"] = cpu_detect / iterations;
  state.counters["cpu_ms_match"] = cpu_match / iterations;
  state.counters["features"] = static_cast<double>(features) / iterations;
  state.counters["warped_width"] = frontend.projection(0).width();
}
// Args: features per view, KLT window, KLT levels, focal scale in percent. The first row is the
// default configuration (FrontendOptions), the second the KLT window used before (21 px; vo/pyr_lk.h serves
// 15-px windows only, so this row runs OpenCV's LK).
BENCHMARK(BM_FrontendFullSize)
    ->ArgNames({"features", "window", "levels", "focal_pct"})
    ->Args({600, FrontendOptions{}.klt_window_px, FrontendOptions{}.klt_levels, 100})
    ->Args({600, 21, 3, 100})
    ->Args({600, 15, 2, 100})
    ->Args({600, 15, 3, 75})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

void BM_HybridWarpOneView(benchmark::State& state) {
  const Rig rig = MakeRigPreset("rovo4");
  const auto projections = HybridProjection::ForRig(rig);
  const cv::Mat image = Texture(rig.cameras[0].camera.width, rig.cameras[0].camera.height, 7);
  const ScopedOpenCvThreads serial_opencv;  // as in the front-end
  cv::Mat warped;
  for (auto _ : state) {
    projections[0].Warp(image, &warped);
    benchmark::DoNotOptimize(warped.data);
  }
  state.counters["warped_width"] = projections[0].width();
  state.counters["warped_height"] = projections[0].height();
}
BENCHMARK(BM_HybridWarpOneView)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same warp by cv::remap itself (the pixels Warp returns; vo/bilinear_remap.h).
void BM_HybridWarpOneViewOpenCv(benchmark::State& state) {
  const Rig rig = MakeRigPreset("rovo4");
  const auto projections = HybridProjection::ForRig(rig);
  const cv::Mat image = Texture(rig.cameras[0].camera.width, rig.cameras[0].camera.height, 7);
  const ScopedOpenCvThreads serial_opencv;
  cv::Mat warped;
  for (auto _ : state) {
    cv::remap(image, warped, projections[0].map_fixed(), projections[0].map_frac(), cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
    benchmark::DoNotOptimize(warped.data);
  }
}
BENCHMARK(BM_HybridWarpOneViewOpenCv)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same warp in bands of state.range(0) rows through WarpRows (RemapBilinearGray where the CPU has
// AVX2), one after the other on one thread (the front-end warps bands in parallel).
void BM_HybridWarpOneViewInBands(benchmark::State& state) {
  const Rig rig = MakeRigPreset("rovo4");
  const auto projections = HybridProjection::ForRig(rig);
  const cv::Mat image = Texture(rig.cameras[0].camera.width, rig.cameras[0].camera.height, 7);
  const int band = static_cast<int>(state.range(0));
  const ScopedOpenCvThreads serial_opencv;
  cv::Mat warped(projections[0].height(), projections[0].width(), CV_8UC1);
  for (auto _ : state) {
    for (int first = 0; first < warped.rows; first += band) {
      projections[0].WarpRows(image, first, std::min(first + band, warped.rows), &warped);
    }
    benchmark::DoNotOptimize(warped.data);
  }
}
BENCHMARK(BM_HybridWarpOneViewInBands)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Arg(32)
    ->Arg(64)
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Cost of (re)building one full-size camera's warp maps, as after an extrinsic update.
void BM_HybridMapsOneView(benchmark::State& state) {
  const Rig rig = MakeRigPreset("rovo4");
  const std::vector<HybridLayout> layouts = ComputeHybridLayouts(rig);
  for (auto _ : state) {
    const HybridProjection projection(rig.cameras[0].camera, rig.cameras[0].cam_from_rig, layouts[0]);
    benchmark::DoNotOptimize(projection.map_x().data);
  }
}
BENCHMARK(BM_HybridMapsOneView)->Unit(benchmark::kMillisecond)->UseRealTime();

// One ZNCC of filter 8's scan (inter-view uniqueness along the epipolar curve; about 5 % of the
// pipeline's CPU before it used SIMD rows): 11 px patches at 256 positions along one image row.
void BM_ZnccAlongRow(benchmark::State& state) {
  cv::Mat image(64, 640, CV_8UC1);
  cv::RNG(9).fill(image, cv::RNG::UNIFORM, 0, 256);
  const int side = static_cast<int>(state.range(0));
  std::vector<cv::Point> row;
  for (int x = 40; x < 40 + 256; ++x) row.emplace_back(x, 30);
  for (auto _ : state) {
    const auto zncc = ZnccAtPixels(image, {320, 32}, image, row, side);
    if (!zncc.back()) state.SkipWithError("flat or outside patch");
    benchmark::DoNotOptimize(zncc.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(row.size()));
}
BENCHMARK(BM_ZnccAlongRow)->Arg(11)->Arg(17);

}  // namespace
}  // namespace rovo
