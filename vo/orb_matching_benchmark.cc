// MutualRatioOrbMatches against the two cv::BFMatcher::knnMatch calls it replaces (the reference, in
// the same run), on 6000 x 6000 descriptors as in the start-up calibration's later passes.
// Run: build/vo/rovo_vo_benchmark --benchmark_filter=OrbMatch
#include <benchmark/benchmark.h>

#include <opencv2/features2d.hpp>

#include "vo/orb_matching.h"

namespace rovo {
namespace {

cv::Mat RandomDescriptors(int n, uint64_t seed) {
  cv::Mat d(n, 32, CV_8U);
  cv::RNG rng(seed);
  rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  return d;
}

void BM_OrbMatchMutualRatio(benchmark::State& state) {
  const cv::Mat a = RandomDescriptors(static_cast<int>(state.range(0)), 1);
  const cv::Mat b = RandomDescriptors(static_cast<int>(state.range(0)), 2);
  for (auto _ : state) benchmark::DoNotOptimize(MutualRatioOrbMatches(a, b, 0.8, 80));
}
BENCHMARK(BM_OrbMatchMutualRatio)->Arg(3000)->Arg(6000)->Unit(benchmark::kMillisecond);

void BM_OrbMatchBfMatcherReference(benchmark::State& state) {
  const cv::Mat a = RandomDescriptors(static_cast<int>(state.range(0)), 1);
  const cv::Mat b = RandomDescriptors(static_cast<int>(state.range(0)), 2);
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  for (auto _ : state) {
    std::vector<std::vector<cv::DMatch>> ab, ba;
    matcher.knnMatch(a, b, ab, 2);
    matcher.knnMatch(b, a, ba, 2);
    benchmark::DoNotOptimize(ab.data());
    benchmark::DoNotOptimize(ba.data());
  }
}
BENCHMARK(BM_OrbMatchBfMatcherReference)->Arg(3000)->Arg(6000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rovo
