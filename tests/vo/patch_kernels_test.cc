#include "vo/patch_kernels.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "vo/cpu_dispatch.h"

namespace rovo {
namespace {

namespace internal = patch_kernels_internal;

// Uniform noise with saturated runs (0 and 255), so that the largest products and sums occur.
cv::Mat NoiseImage(int width, int height, uint64_t seed) {
  cv::Mat image(height, width, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  for (int k = 0; k < 40; ++k) {
    const int x = rng.uniform(0, width - 8), y = rng.uniform(0, height - 8);
    image(cv::Rect(x, y, 8, 8)).setTo(k % 2 == 0 ? 255 : 0);
  }
  return image;
}

// The reference rows as PatchSumsAgainst takes them: `side` values per row, zero-padded to 16.
std::vector<int16_t> ReferenceRows(const cv::Mat& image, int x0, int y0, int side) {
  std::vector<int16_t> rows(static_cast<size_t>(side) * kPatchRowPixels, 0);
  for (int r = 0; r < side; ++r) {
    for (int c = 0; c < side; ++c) rows[r * kPatchRowPixels + c] = image.at<uint8_t>(y0 + r, x0 + c);
  }
  return rows;
}

PatchSums DirectSums(const std::vector<int16_t>& a, const cv::Mat& image, int x0, int y0, int side) {
  PatchSums sums;
  for (int r = 0; r < side; ++r) {
    for (int c = 0; c < side; ++c) {
      const int32_t b = image.at<uint8_t>(y0 + r, x0 + c);
      sums.ab += a[r * kPatchRowPixels + c] * b;
      sums.b += b;
      sums.bb += b * b;
    }
  }
  return sums;
}

DiscMoments DirectMoments(const cv::Mat& image, int cx, int cy) {
  DiscMoments m;
  for (int dy = -kDiscRadius; dy <= kDiscRadius; ++dy) {
    for (int dx = -kDiscRadius; dx <= kDiscRadius; ++dx) {
      const int x = cx + dx, y = cy + dy;
      if (dx * dx + dy * dy > kDiscRadius * kDiscRadius || x < 0 || y < 0 || x >= image.cols || y >= image.rows) {
        continue;
      }
      m.m10 += dx * image.at<uint8_t>(y, x);
      m.m01 += dy * image.at<uint8_t>(y, x);
    }
  }
  return m;
}

void ExpectEqual(const PatchSums& expected, const PatchSums& actual, const char* what) {
  EXPECT_EQ(expected.ab, actual.ab) << what;
  EXPECT_EQ(expected.b, actual.b) << what;
  EXPECT_EQ(expected.bb, actual.bb) << what;
}

TEST(PatchKernels, PatchSumsAreTheDirectSumsForEverySide) {
  const cv::Mat image = NoiseImage(120, 90, 3);
  cv::RNG rng(11);
  for (int side = 1; side <= kPatchRowPixels; ++side) {
    for (int trial = 0; trial < 54; ++trial) {
      // The four corners of the area PatchSumsAgainst allows (its last row and column of patches), then random.
      const int last_x0 = image.cols - kPatchRowPixels, last_y0 = image.rows - side;
      const int x0 = trial < 4 ? (trial % 2) * last_x0 : rng.uniform(0, last_x0 + 1);
      const int y0 = trial < 4 ? (trial / 2) * last_y0 : rng.uniform(0, last_y0 + 1);
      // The reference from elsewhere in the image: its patch and the compared one differ.
      const std::vector<int16_t> a =
          ReferenceRows(image, rng.uniform(0, image.cols - side + 1), rng.uniform(0, image.rows - side + 1), side);
      const PatchSums expected = DirectSums(a, image, x0, y0, side);
      ExpectEqual(expected, PatchSumsAgainst(a.data(), image, x0, y0, side), "dispatched");
      ExpectEqual(expected, internal::PatchSumsPortable(a.data(), image, x0, y0, side), "portable");
      if (CpuHasAvx2()) {
        ExpectEqual(expected, internal::PatchSumsAvx2(a.data(), image, x0, y0, side), "avx2");
      }
    }
  }
}

TEST(PatchKernels, SaturatedPatchesKeepExactSums) {
  cv::Mat image(20, 40, CV_8UC1, cv::Scalar(255));
  const std::vector<int16_t> a = ReferenceRows(image, 0, 0, kPatchRowPixels);
  const PatchSums sums = PatchSumsAgainst(a.data(), image, 3, 2, kPatchRowPixels);
  EXPECT_EQ(sums.ab, 256 * 255 * 255);
  EXPECT_EQ(sums.b, 256 * 255);
  EXPECT_EQ(sums.bb, 256 * 255 * 255);
}

TEST(PatchKernels, DiscHalfWidthsAreTheDiscsRows) {
  EXPECT_EQ(DiscHalfWidth(0), kDiscRadius);
  EXPECT_EQ(DiscHalfWidth(kDiscRadius), 0);
  EXPECT_EQ(DiscHalfWidth(-9), 12);  // 15^2 - 9^2 = 144
  for (int dy = 0; dy <= kDiscRadius; ++dy) {
    const int h = DiscHalfWidth(dy);
    EXPECT_LE(h * h + dy * dy, kDiscRadius * kDiscRadius);
    EXPECT_GT((h + 1) * (h + 1) + dy * dy, kDiscRadius * kDiscRadius);
  }
}

TEST(PatchKernels, DiscMomentsAreTheDirectSumsEverywhere) {
  const cv::Mat image = NoiseImage(70, 50, 5);
  int avx2_checked = 0;
  for (int cy = -2; cy < image.rows + 2; ++cy) {
    for (int cx = -2; cx < image.cols + 2; ++cx) {
      const DiscMoments expected = DirectMoments(image, cx, cy);
      const DiscMoments at = DiscMomentsAt(image, cx, cy);
      const DiscMoments portable = internal::DiscMomentsPortable(image, cx, cy);
      ASSERT_EQ(expected.m10, at.m10) << cx << "," << cy;
      ASSERT_EQ(expected.m01, at.m01) << cx << "," << cy;
      ASSERT_EQ(expected.m10, portable.m10) << cx << "," << cy;
      ASSERT_EQ(expected.m01, portable.m01) << cx << "," << cy;
      if (CpuHasAvx2() && internal::DiscMomentsAvx2Fits(image, cx, cy)) {
        const DiscMoments avx2 = internal::DiscMomentsAvx2(image, cx, cy);
        ASSERT_EQ(expected.m10, avx2.m10) << cx << "," << cy;
        ASSERT_EQ(expected.m01, avx2.m01) << cx << "," << cy;
        ++avx2_checked;
      }
    }
  }
  if (CpuHasAvx2()) {
    EXPECT_GT(avx2_checked, 500);
  }
}

TEST(PatchKernels, DiscMomentsAvx2FitsOnlyWhereItsRowsAreInside) {
  const cv::Mat image(40, 40, CV_8UC1, cv::Scalar(0));
  EXPECT_TRUE(internal::DiscMomentsAvx2Fits(image, 15, 15));
  EXPECT_FALSE(internal::DiscMomentsAvx2Fits(image, 14, 15));
  EXPECT_TRUE(internal::DiscMomentsAvx2Fits(image, 23, 24));   // reads up to column 39
  EXPECT_FALSE(internal::DiscMomentsAvx2Fits(image, 24, 24));  // would read column 40
  EXPECT_FALSE(internal::DiscMomentsAvx2Fits(image, 20, 25));  // row 40
}

}  // namespace
}  // namespace rovo
