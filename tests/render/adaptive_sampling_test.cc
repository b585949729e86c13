// Adaptive sampling (render/tracer.h, AdaptiveSampling): where a pixel's samples agree it stops at
// the first stage, where they spread (an edge, a blurred edge) it takes them all, and the images stay
// close to the fixed count's at a fraction of its samples.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/render.h"
#include "render/timing.h"
#include "render/tracer.h"
#include "tests/render/edge_scene.h"

namespace rovo {
namespace {

using testing::EdgeRender;

// Adaptive sampling from 2 to `spp` samples at `threshold_codes`.
void MakeAdaptive(EdgeRender* r, int spp, float threshold_codes) {
  r->settings.spp = spp;
  r->settings.adaptive.enabled = true;
  r->settings.adaptive.min_spp = 2;
  r->settings.adaptive.threshold = threshold_codes / 255.0f;
}

double MeanSpp(const EdgeRender& r, const CameraImage& image) {
  return static_cast<double>(image.samples) / r.rays.num_valid;
}

// Mean absolute difference of the linear images (red channel) over the pixels both have.
double MeanAbsDiff(const CameraImage& a, const CameraImage& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.linear.size(); i += 3) sum += std::abs(a.linear[i] - b.linear[i]);
  return sum / static_cast<double>(a.linear.size() / 3);
}

// The still camera sees flat colour everywhere but along the edge: 2 samples almost everywhere.
TEST(AdaptiveSampling, StillFlatPixelsStopAtTheFirstStage) {
  EdgeRender r(8);
  MakeAdaptive(&r, 8, 8.0f);
  const CameraImage image = r.Render(0.0, 0.0, 0.0);
  const double spp = MeanSpp(r, image);
  EXPECT_GE(spp, 2.0);
  EXPECT_LT(spp, 2.2);
  std::printf("still: %.3f samples per pixel\n", spp);
}

// A negative threshold keeps every pixel: all 8 samples (but where a sub-pixel sample leaves the
// field of view at the rim).
TEST(AdaptiveSampling, NegativeThresholdTakesEverySample) {
  EdgeRender r(8);
  MakeAdaptive(&r, 8, -1.0f);
  const CameraImage image = r.Render(0.0, 20.0, 0.0);
  EXPECT_GT(MeanSpp(r, image), 7.9);
  EXPECT_LE(MeanSpp(r, image), 8.0);
}

// A 20 ms shutter blurs the edge over about 8 px: there the pixels take more samples, and the image
// is as close to a 64-sample reference as the fixed 8 samples' image, far closer than 2 samples'.
TEST(AdaptiveSampling, BlurredEdgeGetsTheSamplesItNeeds) {
  EdgeRender reference(64), fixed2(2), fixed8(8), adaptive(8), still(8);
  MakeAdaptive(&adaptive, 8, 8.0f);
  MakeAdaptive(&still, 8, 8.0f);
  const CameraImage ref = reference.Render(0.0, 20.0, 0.0);
  const CameraImage a2 = fixed2.Render(0.0, 20.0, 0.0);
  const CameraImage a8 = fixed8.Render(0.0, 20.0, 0.0);
  const CameraImage ad = adaptive.Render(0.0, 20.0, 0.0);
  const double spp_blur = MeanSpp(adaptive, ad), spp_still = MeanSpp(still, still.Render(0.0, 0.0, 0.0));
  EXPECT_GT(spp_blur, spp_still + 0.05);
  EXPECT_LT(spp_blur, 3.0);
  const double e2 = MeanAbsDiff(a2, ref), e8 = MeanAbsDiff(a8, ref), ead = MeanAbsDiff(ad, ref);
  EXPECT_LT(ead, 0.5 * e2);
  EXPECT_LT(ead, 1.5 * e8);
  std::printf("blurred edge: %.3f samples per pixel (still %.3f); error 2 spp %.2e, 8 spp %.2e, adaptive %.2e\n",
              spp_blur, spp_still, e2, e8, ead);
}

// The decisions are per tile: the image is the same on one thread and on two.
TEST(AdaptiveSampling, SameImageOnAnyThreadCount) {
  EdgeRender r(8);
  MakeAdaptive(&r, 8, 8.0f);
  CameraImage one, two;
  tbb::task_arena(1).execute([&] { one = r.Render(0.0, 20.0, 0.0); });
  tbb::task_arena(2).execute([&] { two = r.Render(0.0, 20.0, 0.0); });
  EXPECT_EQ(one.linear, two.linear);
  EXPECT_EQ(one.samples, two.samples);
}

// The order of the samples: every prefix of 2^k samples and each half of it has one sample in each
// 1/2^k of either axis (and of the strata), its offsets average to the pixel centre, and all N strata are
// the fixed pattern's (s + 1/2) / N.
TEST(AdaptiveSampling, EveryPrefixIsStratifiedAndCentred) {
  for (int spp = 2; spp <= 64; spp *= 2) {
    std::vector<Eigen::Vector2f> offset(spp);
    std::vector<float> stratum(spp);
    for (int s = 0; s < spp; ++s) offset[s] = CameraRays::AdaptiveSample(s, spp, &stratum[s]);
    const auto stratified = [&](int begin, int n) {
      std::set<int> xs, ys, ts;
      for (int s = begin; s < begin + n; ++s) {
        xs.insert(static_cast<int>(std::floor((offset[s].x() + 0.5f) * n)));
        ys.insert(static_cast<int>(std::floor((offset[s].y() + 0.5f) * n)));
        ts.insert(static_cast<int>(std::floor(stratum[s] * n)));
      }
      return static_cast<int>(xs.size()) == n && static_cast<int>(ys.size()) == n && static_cast<int>(ts.size()) == n;
    };
    for (int n = 2; n <= spp; n *= 2) {
      EXPECT_TRUE(stratified(0, n)) << "spp " << spp << ", prefix " << n;
      if (n >= 4) {
        EXPECT_TRUE(stratified(0, n / 2) && stratified(n / 2, n / 2)) << "spp " << spp << ", halves of " << n;
      }
      Eigen::Vector2f mean = Eigen::Vector2f::Zero();
      for (int s = 0; s < n; ++s) mean += offset[s];
      EXPECT_LT(mean.norm() / n, 1e-6f) << "spp " << spp << ", prefix " << n;
    }
    std::vector<float> sorted = stratum;
    std::sort(sorted.begin(), sorted.end());
    for (int s = 0; s < spp; ++s) EXPECT_FLOAT_EQ(sorted[s], (s + 0.5f) / spp);
  }
}

// rovo render: auto turns it on exactly where motion blur takes the default spp.
TEST(AdaptiveSampling, RenderModes) {
  RenderOptions options;
  EXPECT_TRUE(RenderAdaptiveSampling(options, kDefaultBlurSpp, true).enabled);
  EXPECT_FALSE(RenderAdaptiveSampling(options, kDefaultBlurSpp, false).enabled);  // --spp 8 given
  EXPECT_FALSE(RenderAdaptiveSampling(options, kDefaultSpp, true).enabled);
  EXPECT_FLOAT_EQ(RenderAdaptiveSampling(options, kDefaultBlurSpp, true).threshold,
                  static_cast<float>(kAdaptiveThresholdCodes / 255.0));
  options.adaptive = "on";
  options.adaptive_threshold_codes = 3.0;
  const auto expect_error = [&](int spp, const std::string& text) {
    try {
      RenderAdaptiveSampling(options, spp, false);
      ADD_FAILURE() << "expected an error naming " << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  expect_error(16, "needs timing");  // the record would have nowhere to go
  options.timing.shutter_ms = 10.0;
  const AdaptiveSampling on = RenderAdaptiveSampling(options, 16, false);
  EXPECT_TRUE(on.enabled);
  EXPECT_EQ(on.min_spp, kDefaultSpp);
  EXPECT_FLOAT_EQ(on.threshold, 3.0f / 255.0f);
  expect_error(6, "--spp 6");
  expect_error(128, "--spp 128");
  options.adaptive = "off";
  EXPECT_FALSE(RenderAdaptiveSampling(options, kDefaultBlurSpp, true).enabled);
  options.adaptive = "sometimes";
  expect_error(kDefaultBlurSpp, "--adaptive");
}

}  // namespace
}  // namespace rovo
