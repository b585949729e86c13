// PyrLk against cv::calcOpticalFlowPyrLK on the front-end's settings (window 15, 3 levels, 20
// iterations, 0.03 px), 600 points of a textured 2417x985 image (the warped view's size) that moves by
// (3.4, -1.7) px; the same pyramids for both. BM_LkPyramid: the previous image's pyramid with its
// derivatives (cv::buildOpticalFlowPyramid's default) and without them (what BuildPyrLkPyramid builds
// where PyrLk applies), and BM_Lk600PointsComputedDerivatives PyrLk on the latter, so that pyramid + LK
// compare as the tracker's two ways. Run: build/vo/rovo_vo_benchmark --benchmark_filter=Lk
#include <benchmark/benchmark.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <vector>

#include "vo/pyr_lk.h"

namespace rovo {
namespace {

struct LkInput {
  cv::Mat image;
  std::vector<cv::Mat> from_pyramid, to_pyramid;
  std::vector<cv::Mat> from_pyramid_plain;  // without derivatives
  std::vector<cv::Point2f> points;
};

const LkInput& Input() {
  static const LkInput input = [] {
    cv::Mat noise(985, 2417, CV_8UC1);
    cv::RNG rng(5);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
    cv::Mat image;
    cv::GaussianBlur(noise, image, cv::Size(0, 0), 2.0);
    cv::normalize(image, image, 0, 255, cv::NORM_MINMAX);
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 3.4, 0, 1, -1.7);
    cv::Mat moved;
    cv::warpAffine(image, moved, shift, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
    LkInput in;
    in.image = image;
    cv::buildOpticalFlowPyramid(image, in.from_pyramid, cv::Size(15, 15), 3);
    cv::buildOpticalFlowPyramid(image, in.from_pyramid_plain, cv::Size(15, 15), 3, false);
    cv::buildOpticalFlowPyramid(moved, in.to_pyramid, cv::Size(15, 15), 3);
    for (int k = 0; k < 600; ++k)
      in.points.emplace_back(rng.uniform(20.f, image.cols - 20.f), rng.uniform(20.f, image.rows - 20.f));
    return in;
  }();
  return input;
}

// Arg 0: cv::calcOpticalFlowPyrLK, 1: PyrLk.
void BM_Lk600Points(benchmark::State& state) {
  const LkInput& in = Input();
  const cv::Size window(15, 15);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  std::vector<cv::Point2f> to(in.points.size());
  std::vector<uint8_t> status(in.points.size());
  cv::setNumThreads(1);
  for (auto _ : state) {
    if (state.range(0) == 0) {
      cv::calcOpticalFlowPyrLK(in.from_pyramid, in.to_pyramid, in.points, to, status, cv::noArray(), window, 3,
                               criteria, 0);
    } else {
      PyrLk(in.from_pyramid, in.to_pyramid, in.points.data(), to.data(), status.data(),
            static_cast<int>(in.points.size()), window, 3, criteria, 0);
    }
    benchmark::DoNotOptimize(to.data());
  }
}
BENCHMARK(BM_Lk600Points)->ArgName("pyr_lk")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// PyrLk from the pyramid without derivatives: each window's derivatives computed as it is extracted.
void BM_Lk600PointsComputedDerivatives(benchmark::State& state) {
  const LkInput& in = Input();
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  std::vector<cv::Point2f> to(in.points.size());
  std::vector<uint8_t> status(in.points.size());
  for (auto _ : state) {
    PyrLk(in.from_pyramid_plain, in.to_pyramid, in.points.data(), to.data(), status.data(),
          static_cast<int>(in.points.size()), cv::Size(15, 15), 3, criteria, 0);
    benchmark::DoNotOptimize(to.data());
  }
}
BENCHMARK(BM_Lk600PointsComputedDerivatives)->Unit(benchmark::kMicrosecond);

// Arg 1: with derivatives (cv::buildOpticalFlowPyramid's default), 0: without.
void BM_LkPyramid(benchmark::State& state) {
  const LkInput& in = Input();
  std::vector<cv::Mat> pyramid;
  cv::setNumThreads(1);
  for (auto _ : state) {
    cv::buildOpticalFlowPyramid(in.image, pyramid, cv::Size(15, 15), 3, state.range(0) != 0);
    benchmark::DoNotOptimize(pyramid.data());
  }
}
BENCHMARK(BM_LkPyramid)->ArgName("derivatives")->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace rovo
