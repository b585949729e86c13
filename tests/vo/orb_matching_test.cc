// MutualRatioOrbMatches against cv::BFMatcher's knnMatch (k = 2) both ways with the same ratio,
// distance and mutual tests: the same matches on descriptors with near copies and random rows.
#include "vo/orb_matching.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/features2d.hpp>

namespace rovo {
namespace {

std::vector<std::pair<int, int>> Reference(const cv::Mat& a, const cv::Mat& b, double max_ratio, int max_distance) {
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> ab, ba;
  matcher.knnMatch(a, b, ab, 2);
  matcher.knnMatch(b, a, ba, 2);
  auto best = [&](const std::vector<cv::DMatch>& m) {
    if (m.empty() || m[0].distance > max_distance) return -1;
    if (m.size() > 1 && m[0].distance > max_ratio * m[1].distance) return -1;
    return m[0].trainIdx;
  };
  std::vector<std::pair<int, int>> out;
  for (int i = 0; i < static_cast<int>(ab.size()); ++i) {
    const int j = best(ab[i]);
    if (j >= 0 && best(ba[j]) == i) out.emplace_back(i, j);
  }
  return out;
}

// `n` rows of b: the first `copies` are rows of a (in shuffled order) with 0..max_flips bits flipped,
// the rest random.
cv::Mat NearCopies(const cv::Mat& a, int n, int copies, int max_flips, cv::RNG& rng) {
  cv::Mat b(n, 32, CV_8U);
  rng.fill(b, cv::RNG::UNIFORM, 0, 256);
  for (int k = 0; k < copies; ++k) {
    a.row(rng.uniform(0, a.rows)).copyTo(b.row(k));
    const int flips = rng.uniform(0, max_flips + 1);
    for (int f = 0; f < flips; ++f) {
      const int bit = rng.uniform(0, 256);
      b.at<uint8_t>(k, bit / 8) ^= static_cast<uint8_t>(1 << (bit % 8));
    }
  }
  return b;
}

TEST(OrbMatching, SameMatchesAsTwoBfMatcherCalls) {
  cv::RNG rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    cv::Mat a(700 + 100 * trial, 32, CV_8U);
    rng.fill(a, cv::RNG::UNIFORM, 0, 256);
    const cv::Mat b = NearCopies(a, 900, 500, 20 + 20 * trial, rng);
    for (double ratio : {0.7, 0.8, 1.0}) {
      const auto ours = MutualRatioOrbMatches(a, b, ratio, 80);
      const auto reference = Reference(a, b, ratio, 80);
      EXPECT_EQ(ours, reference) << "trial " << trial << " ratio " << ratio;
      EXPECT_GT(ours.size(), 50u);
    }
  }
}

TEST(OrbMatching, DistanceBoundAndDegenerateInputs) {
  cv::RNG rng(11);
  cv::Mat a(200, 32, CV_8U);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  const cv::Mat b = NearCopies(a, 200, 200, 30, rng);
  for (const auto& [i, j] : MutualRatioOrbMatches(a, b, 1.0, 10))
    EXPECT_LE(cv::norm(a.row(i), b.row(j), cv::NORM_HAMMING), 10);
  EXPECT_EQ(MutualRatioOrbMatches(a, b, 1.0, 10), Reference(a, b, 1.0, 10));
  EXPECT_TRUE(MutualRatioOrbMatches(a.rowRange(0, 1), b, 0.8, 80).empty());
  EXPECT_TRUE(MutualRatioOrbMatches(cv::Mat(), b, 0.8, 80).empty());
  EXPECT_THROW(MutualRatioOrbMatches(cv::Mat(5, 16, CV_8U, cv::Scalar(0)), b, 0.8, 80), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
