#include "vo/pyr_lk.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>
#include <vector>

#include "blurred_noise.h"

namespace rovo {
namespace {

// Smooth texture (blurred noise) with hard-edged blocks, so that gradients are both weak and at the
// Scharr filter's extremes.
cv::Mat Texture(int width, int height, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image = BlurredNoise(width, height, rng);
  for (int k = 0; k < 30; ++k) {
    const int x = rng.uniform(0, width - 12), y = rng.uniform(0, height - 12);
    image(cv::Rect(x, y, 12, 12)).setTo(k % 2 == 0 ? 255 : 0);
  }
  return image;
}

// `image` moved by (dx, dy) with its brightness scaled and offset.
cv::Mat Moved(const cv::Mat& image, double dx, double dy, double gain, double offset) {
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat moved;
  cv::warpAffine(image, moved, shift, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  moved.convertTo(moved, CV_8U, gain, offset);
  return moved;
}

struct Case {
  cv::Size window;
  int levels;
  cv::TermCriteria criteria;
  bool initial_flow;
};

// PyrLk against cv::calcOpticalFlowPyrLK on the same pyramids (`from`'s with its derivatives, or without
// them: PyrLk computes those of each window, OpenCV all of them): every point's coordinates bit for bit
// and every status. Returns the number of points tracked (status 1).
int ExpectSameAsOpenCvFor(const cv::Mat& from, const cv::Mat& to, const std::vector<cv::Point2f>& points,
                          const std::vector<cv::Point2f>& starts, const Case& c, bool from_derivatives) {
  SCOPED_TRACE(from_derivatives ? "pyramid with derivatives" : "pyramid without derivatives");
  std::vector<cv::Mat> from_pyramid, to_pyramid;
  cv::buildOpticalFlowPyramid(from, from_pyramid, c.window, c.levels, from_derivatives);
  cv::buildOpticalFlowPyramid(to, to_pyramid, c.window, c.levels);
  EXPECT_EQ(PyrLkApplies(from_pyramid, to_pyramid, c.window), __builtin_cpu_supports("avx2") != 0);
  const int flags = c.initial_flow ? cv::OPTFLOW_USE_INITIAL_FLOW : 0;
  std::vector<cv::Point2f> expected = starts, actual = starts;
  actual.resize(points.size());
  std::vector<uint8_t> expected_status, actual_status(points.size(), 7);
  cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, points, expected, expected_status, cv::noArray(), c.window,
                           c.levels, c.criteria, flags);
  PyrLk(from_pyramid, to_pyramid, points.data(), actual.data(), actual_status.data(), static_cast<int>(points.size()),
        c.window, c.levels, c.criteria, flags);
  int tracked = 0, differ = 0;
  for (size_t k = 0; k < points.size(); ++k) {
    tracked += expected_status[k];
    if (expected_status[k] != actual_status[k] || std::memcmp(&expected[k], &actual[k], sizeof(cv::Point2f)) != 0) {
      if (++differ <= 5) {
        ADD_FAILURE() << "point " << k << " at " << points[k] << ": OpenCV " << expected[k] << " status "
                      << int(expected_status[k]) << ", PyrLk " << actual[k] << " status " << int(actual_status[k]);
      }
    }
  }
  EXPECT_EQ(differ, 0) << "of " << points.size() << " points";
  return tracked;
}

int ExpectSameAsOpenCv(const cv::Mat& from, const cv::Mat& to, const std::vector<cv::Point2f>& points,
                       const std::vector<cv::Point2f>& starts, const Case& c) {
  const int tracked = ExpectSameAsOpenCvFor(from, to, points, starts, c, true);
  EXPECT_EQ(ExpectSameAsOpenCvFor(from, to, points, starts, c, false), tracked);
  return tracked;
}

std::vector<cv::Point2f> RandomPoints(int n, cv::Size size, int margin, cv::RNG& rng) {
  std::vector<cv::Point2f> points(n);
  for (cv::Point2f& p : points) {
    p = cv::Point2f(rng.uniform(static_cast<float>(-margin), static_cast<float>(size.width + margin)),
                    rng.uniform(static_cast<float>(-margin), static_cast<float>(size.height + margin)));
  }
  return points;
}

const cv::TermCriteria kTrackerCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);

TEST(PyrLk, SameAsOpenCvWithoutStarts) {
  const cv::Mat from = Texture(320, 240, 1);
  cv::RNG rng(11);
  // Points across the image and beyond its borders (lost at some levels or all).
  const std::vector<cv::Point2f> points = RandomPoints(3000, from.size(), 20, rng);
  for (const double dx : {0.0, 3.3, -17.6}) {
    const cv::Mat to = Moved(from, dx, 0.4 * dx + 1.7, 1.0, 0.0);
    const int tracked = ExpectSameAsOpenCv(from, to, points, {}, {cv::Size(15, 15), 3, kTrackerCriteria, false});
    EXPECT_GT(tracked, 1000) << "dx " << dx;
  }
}

TEST(PyrLk, SameAsOpenCvFromStarts) {
  const cv::Mat from = Texture(300, 260, 2);
  const cv::Mat to = Moved(from, 6.25, -4.5, 1.0, 0.0);
  cv::RNG rng(12);
  const std::vector<cv::Point2f> points = RandomPoints(3000, from.size(), 5, rng);
  std::vector<cv::Point2f> starts(points.size());
  for (size_t k = 0; k < points.size(); ++k)
    starts[k] = points[k] + cv::Point2f(6.25f + rng.uniform(-3.f, 3.f), -4.5f + rng.uniform(-3.f, 3.f));
  for (const int levels : {0, 1, 3}) {
    const int tracked =
        ExpectSameAsOpenCv(from, to, points, starts, {cv::Size(15, 15), levels, kTrackerCriteria, true});
    EXPECT_GT(tracked, 1000) << "levels " << levels;
  }
}

// Large mismatches (a brightness change) take the one-by-one float sums in OpenCV's order; small ones
// (no change) the exact integer sums. Other criteria and window heights.
TEST(PyrLk, SameAsOpenCvUnderBrightnessChangesAndOtherSettings) {
  const cv::Mat from = Texture(256, 256, 3);
  cv::RNG rng(13);
  const std::vector<cv::Point2f> points = RandomPoints(2000, from.size(), 2, rng);
  const cv::Mat brighter = Moved(from, 2.5, 1.25, 0.7, 70.0);
  const cv::Mat same = Moved(from, 0.0, 0.0, 1.0, 0.0);
  for (const cv::Mat* to : {&brighter, &same}) {
    ExpectSameAsOpenCv(from, *to, points, {}, {cv::Size(15, 15), 2, kTrackerCriteria, false});
    ExpectSameAsOpenCv(from, *to, points, {}, {cv::Size(15, 9), 2, kTrackerCriteria, false});
    ExpectSameAsOpenCv(from, *to, points, {},
                       {cv::Size(15, 31), 1, cv::TermCriteria(cv::TermCriteria::COUNT, 5, 0), false});
    ExpectSameAsOpenCv(from, *to, points, {},
                       {cv::Size(15, 15), 3, cv::TermCriteria(cv::TermCriteria::EPS, 0, 1e-6), false});
  }
}

// Derivatives computed per window at and beyond the image's edges: calcScharrDeriv's border rule (rows
// and columns reflected inside the image, zero outside it) on small images where most windows touch an
// edge, and on an image that is a view into a larger one, whose base level the pyramid keeps without a
// border of its own (the pixels around it are not the reflected ones).
TEST(PyrLk, DerivativesAtTheEdgesAsOpenCv) {
  cv::RNG rng(16);
  for (const cv::Size size : {cv::Size(40, 33), cv::Size(19, 64), cv::Size(70, 17)}) {
    const cv::Mat from = Texture(size.width, size.height, 6);
    const cv::Mat to = Moved(from, 1.5, -0.75, 1.0, 0.0);
    const std::vector<cv::Point2f> points = RandomPoints(800, size, 16, rng);
    ExpectSameAsOpenCv(from, to, points, {}, {cv::Size(15, 15), 1, kTrackerCriteria, false});
    ExpectSameAsOpenCv(from, to, points, {}, {cv::Size(15, 5), 0, kTrackerCriteria, false});
  }
  // The view's pixels beyond its edges are the larger image's, not reflections of its own: only here
  // does a window the fast path took one pixel too close to an edge read values calcScharrDeriv would not.
  const cv::Mat whole = Texture(260, 220, 7);
  const cv::Mat moved = Moved(whole, -2.25, 3.5, 1.0, 0.0);
  const cv::Rect inner(20, 18, 200, 170);
  const std::vector<cv::Point2f> points = RandomPoints(2000, inner.size(), 10, rng);
  const int tracked =
      ExpectSameAsOpenCv(whole(inner), moved(inner), points, {}, {cv::Size(15, 15), 2, kTrackerCriteria, false});
  EXPECT_GT(tracked, 1000);
}

// Images one and two pixels wide or high (calcScharrDeriv reflects onto the other pixel, or the same
// one), and windows three rows high.
TEST(PyrLk, TinyImagesAndLowWindowsAsOpenCv) {
  cv::RNG rng(17);
  for (const cv::Size size : {cv::Size(1, 30), cv::Size(2, 30), cv::Size(30, 1), cv::Size(30, 2), cv::Size(2, 2)}) {
    cv::Mat from(size, CV_8UC1), to(size, CV_8UC1);
    rng.fill(from, cv::RNG::UNIFORM, 0, 256);
    rng.fill(to, cv::RNG::UNIFORM, 0, 256);
    const std::vector<cv::Point2f> points = RandomPoints(200, size, 3, rng);
    ExpectSameAsOpenCv(from, to, points, {}, {cv::Size(15, 15), 0, kTrackerCriteria, false});
    ExpectSameAsOpenCv(from, to, points, {}, {cv::Size(15, 3), 0, kTrackerCriteria, false});
  }
  const cv::Mat from = Texture(160, 120, 9);
  const cv::Mat to = Moved(from, 1.25, 0.5, 1.0, 0.0);
  const std::vector<cv::Point2f> points = RandomPoints(1500, from.size(), 8, rng);
  EXPECT_GT(ExpectSameAsOpenCv(from, to, points, {}, {cv::Size(15, 3), 2, kTrackerCriteria, false}), 500);
}

// The pyramid BuildPyrLkPyramid builds: without derivatives where PyrLk computes them (AVX2, a window 15
// wide), else with them, as OpenCV needs them for every call.
TEST(PyrLk, BuildsThePyramidItTracksFrom) {
  const cv::Mat image = Texture(128, 96, 8);
  std::vector<cv::Mat> pyramid;
  EXPECT_EQ(BuildPyrLkPyramid(image, &pyramid, cv::Size(15, 15), 2), 2);
  const bool avx2 = __builtin_cpu_supports("avx2") != 0;
  EXPECT_EQ(pyramid.size(), avx2 ? 3u : 6u);
  EXPECT_EQ(PyrLkApplies(pyramid, pyramid, cv::Size(15, 15)), avx2);
  EXPECT_EQ(BuildPyrLkPyramid(image, &pyramid, cv::Size(21, 21), 2), 2);
  EXPECT_EQ(pyramid.size(), 6u);
}

// Where it does not apply (a 21-pixel window), PyrLk hands the points to OpenCV and writes its results
// into the caller's arrays.
TEST(PyrLk, FallsBackToOpenCvWhereItDoesNotApply) {
  const cv::Mat from = Texture(200, 160, 5);
  const cv::Mat to = Moved(from, 2.0, -1.5, 1.0, 0.0);
  const cv::Size window(21, 21);
  std::vector<cv::Mat> from_pyramid, to_pyramid;
  cv::buildOpticalFlowPyramid(from, from_pyramid, window, 2);
  cv::buildOpticalFlowPyramid(to, to_pyramid, window, 2);
  ASSERT_FALSE(PyrLkApplies(from_pyramid, to_pyramid, window));
  cv::RNG rng(15);
  const std::vector<cv::Point2f> points = RandomPoints(500, from.size(), 10, rng);
  std::vector<cv::Point2f> expected, actual(points.size());
  std::vector<uint8_t> expected_status, actual_status(points.size(), 7);
  cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, points, expected, expected_status, cv::noArray(), window, 2,
                           kTrackerCriteria, 0);
  PyrLk(from_pyramid, to_pyramid, points.data(), actual.data(), actual_status.data(), static_cast<int>(points.size()),
        window, 2, kTrackerCriteria, 0);
  EXPECT_EQ(actual_status, expected_status);
  ASSERT_EQ(actual.size(), expected.size());
  EXPECT_EQ(std::memcmp(actual.data(), expected.data(), actual.size() * sizeof(cv::Point2f)), 0);
  EXPECT_THROW(PyrLk(from_pyramid, to_pyramid, points.data(), actual.data(), actual_status.data(), 1, window, -1,
                     kTrackerCriteria, 0),
               std::invalid_argument);
}

TEST(PyrLk, AppliesOnlyWhereItMatchesOpenCv) {
  const cv::Mat image = Texture(128, 128, 4);
  std::vector<cv::Mat> with, without;
  cv::buildOpticalFlowPyramid(image, with, cv::Size(15, 15), 2);
  cv::buildOpticalFlowPyramid(image, without, cv::Size(15, 15), 2, false);
  const bool avx2 = __builtin_cpu_supports("avx2") != 0;
  EXPECT_EQ(PyrLkApplies(with, with, cv::Size(15, 15)), avx2);
  EXPECT_EQ(PyrLkApplies(with, without, cv::Size(15, 15)), avx2);
  EXPECT_EQ(PyrLkApplies(without, with, cv::Size(15, 15)), avx2);  // the derivatives computed per window
  EXPECT_FALSE(PyrLkApplies(with, with, cv::Size(21, 21)));
  EXPECT_FALSE(PyrLkApplies(with, with, cv::Size(15, 33)));
  std::vector<cv::Mat> flat;  // a border of 3 rows: too little for a window 31 high
  cv::buildOpticalFlowPyramid(image, flat, cv::Size(15, 3), 2);
  EXPECT_EQ(PyrLkApplies(flat, flat, cv::Size(15, 3)), avx2);
  EXPECT_FALSE(PyrLkApplies(flat, flat, cv::Size(15, 31)));
  std::vector<cv::Mat> colour;
  cv::Mat bgr;
  cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  cv::buildOpticalFlowPyramid(bgr, colour, cv::Size(15, 15), 2);
  EXPECT_FALSE(PyrLkApplies(colour, colour, cv::Size(15, 15)));
}

}  // namespace
}  // namespace rovo
