#include "vo/patch_kernels.h"

#include <immintrin.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <opencv2/core/hal/intrin.hpp>

#include "vo/cpu_dispatch.h"

namespace rovo {
namespace {

// 16 x -1 then 16 x 0: a window of it starting at 16 - n keeps the first n lanes.
constexpr std::array<int16_t, 32> kKeep16 = {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
constexpr std::array<uint8_t, 32> kKeep8 = {255, 255, 255, 255, 255, 255, 255, 255,
                                            255, 255, 255, 255, 255, 255, 255, 255};

ROVO_TARGET_AVX2 int32_t SumLanes(__m256i v) {
  __m128i s = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, _MM_SHUFFLE(1, 0, 3, 2)));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtsi128_si32(s);
}

const std::array<int, kDiscRadius + 1>& HalfWidths() {
  static const std::array<int, kDiscRadius + 1> half = [] {
    std::array<int, kDiscRadius + 1> h{};
    for (int dy = 0; dy <= kDiscRadius; ++dy) {
      h[dy] = static_cast<int>(std::sqrt(double(kDiscRadius * kDiscRadius - dy * dy)));
    }
    return h;
  }();
  return half;
}

// Per |dy|: the 32 bytes from cx - 15 to cx + 16 weighted by dx (moment) and by 1 (sum) inside the disc's
// row, 0 outside it. maddubs pairs stay within int16 (2 * 255 * 15); the int32 accumulators within
// 31 rows * 31 * 255 * 15.
struct DiscRowWeights {
  std::array<std::array<int8_t, 32>, kDiscRadius + 1> moment{}, sum{};
};

const DiscRowWeights& RowWeights() {
  static const DiscRowWeights weights = [] {
    DiscRowWeights w;
    for (int dy = 0; dy <= kDiscRadius; ++dy) {
      for (int lane = 0; lane < 32; ++lane) {
        const int dx = lane - kDiscRadius;
        const bool in = std::abs(dx) <= HalfWidths()[dy];
        w.moment[dy][lane] = static_cast<int8_t>(in ? dx : 0);
        w.sum[dy][lane] = static_cast<int8_t>(in ? 1 : 0);
      }
    }
    return w;
  }();
  return weights;
}

}  // namespace

namespace patch_kernels_internal {

PatchSums PatchSumsPortable(const int16_t* a, const cv::Mat& image, int x0, int y0, int side) {
  PatchSums sums;
#if CV_SIMD128
  // One 16-byte load per row, the bytes beyond `side` masked to zero. Per lane at most 16 rows * 4 * 255^2 < 2^31
  // (products) and 16 rows * 2 * 255 < 2^16 (sums).
  const cv::v_uint8x16 keep = cv::v_load(kKeep8.data() + kPatchRowPixels - side);
  cv::v_int32x4 ab4 = cv::v_setzero_s32(), bb4 = cv::v_setzero_s32();
  cv::v_uint16x8 sum8 = cv::v_setzero_u16();
  for (int r = 0; r < side; ++r, a += kPatchRowPixels) {
    const cv::v_uint8x16 b = cv::v_load(image.ptr<uint8_t>(y0 + r) + x0) & keep;
    cv::v_uint16x8 lo, hi;
    cv::v_expand(b, lo, hi);
    const cv::v_int16x8 slo = cv::v_reinterpret_as_s16(lo), shi = cv::v_reinterpret_as_s16(hi);
    ab4 += cv::v_dotprod(slo, cv::v_load(a)) + cv::v_dotprod(shi, cv::v_load(a + 8));
    bb4 += cv::v_dotprod(slo, slo) + cv::v_dotprod(shi, shi);
    sum8 += lo + hi;
  }
  sums.ab = cv::v_reduce_sum(ab4);
  sums.bb = cv::v_reduce_sum(bb4);
  sums.b = static_cast<int32_t>(cv::v_reduce_sum(sum8));
#else
  for (int r = 0; r < side; ++r, a += kPatchRowPixels) {
    const uint8_t* row = image.ptr<uint8_t>(y0 + r) + x0;
    for (int c = 0; c < side; ++c) {
      const int32_t b = row[c];
      sums.ab += a[c] * b;
      sums.b += b;
      sums.bb += b * b;
    }
  }
#endif
  return sums;
}

// A row of 16 pixels widened to 16 int16 lanes: one multiply-add each for a*b and b^2. Bounds as above.
ROVO_TARGET_AVX2 PatchSums PatchSumsAvx2(const int16_t* a, const cv::Mat& image, int x0, int y0, int side) {
  const __m256i keep = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kKeep16.data() + kPatchRowPixels - side));
  __m256i ab = _mm256_setzero_si256(), bb = _mm256_setzero_si256(), sum = _mm256_setzero_si256();
  for (int r = 0; r < side; ++r, a += kPatchRowPixels) {
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(image.ptr<uint8_t>(y0 + r) + x0));
    const __m256i b = _mm256_and_si256(_mm256_cvtepu8_epi16(bytes), keep);
    ab = _mm256_add_epi32(ab, _mm256_madd_epi16(b, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a))));
    bb = _mm256_add_epi32(bb, _mm256_madd_epi16(b, b));
    sum = _mm256_add_epi16(sum, b);
  }
  PatchSums sums;
  sums.ab = SumLanes(ab);
  sums.bb = SumLanes(bb);
  sums.b = SumLanes(_mm256_madd_epi16(sum, _mm256_set1_epi16(1)));
  return sums;
}

DiscMoments DiscMomentsPortable(const cv::Mat& image, int cx, int cy) {
  const bool inside =
      cx >= kDiscRadius && cy >= kDiscRadius && cx + kDiscRadius < image.cols && cy + kDiscRadius < image.rows;
  DiscMoments m;
  for (int dy = -kDiscRadius; dy <= kDiscRadius; ++dy) {
    const int y = cy + dy;
    if (y < 0 || y >= image.rows) continue;
    const uint8_t* row = image.ptr<uint8_t>(y);
    const int half = HalfWidths()[std::abs(dy)];
    int64_t row_sum = 0, row_moment = 0;
    if (inside) {
      for (int dx = -half; dx <= half; ++dx) {
        row_sum += row[cx + dx];
        row_moment += static_cast<int64_t>(dx) * row[cx + dx];
      }
    } else {
      for (int dx = -half; dx <= half; ++dx) {
        const int x = cx + dx;
        if (x < 0 || x >= image.cols) continue;
        row_sum += row[x];
        row_moment += static_cast<int64_t>(dx) * row[x];
      }
    }
    m.m10 += row_moment;
    m.m01 += dy * row_sum;
  }
  return m;
}

ROVO_TARGET_AVX2 DiscMoments DiscMomentsAvx2(const cv::Mat& image, int cx, int cy) {
  const DiscRowWeights& w = RowWeights();
  const __m256i ones = _mm256_set1_epi16(1);
  __m256i m10 = _mm256_setzero_si256(), m01 = _mm256_setzero_si256();
  for (int dy = -kDiscRadius; dy <= kDiscRadius; ++dy) {
    const int k = std::abs(dy);
    const __m256i pixels =
        _mm256_loadu_si256(reinterpret_cast<const __m256i*>(image.ptr<uint8_t>(cy + dy) + cx - kDiscRadius));
    const __m256i moment =
        _mm256_maddubs_epi16(pixels, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(w.moment[k].data())));
    const __m256i sum =
        _mm256_maddubs_epi16(pixels, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(w.sum[k].data())));
    m10 = _mm256_add_epi32(m10, _mm256_madd_epi16(moment, ones));
    m01 = _mm256_add_epi32(m01, _mm256_madd_epi16(sum, _mm256_set1_epi16(static_cast<int16_t>(dy))));
  }
  DiscMoments m;
  m.m10 = SumLanes(m10);
  m.m01 = SumLanes(m01);
  return m;
}

bool DiscMomentsAvx2Fits(const cv::Mat& image, int cx, int cy) {
  // The rows are read as 32 bytes from cx - 15.
  return cx >= kDiscRadius && cy >= kDiscRadius && cx + kDiscRadius + 1 < image.cols && cy + kDiscRadius < image.rows;
}

}  // namespace patch_kernels_internal

using namespace patch_kernels_internal;  // NOLINT(google-build-using-namespace): this file's own forms

PatchSums PatchSumsAgainst(const int16_t* reference_rows, const cv::Mat& image, int x0, int y0, int side) {
  if (CpuHasAvx2()) return PatchSumsAvx2(reference_rows, image, x0, y0, side);
  return PatchSumsPortable(reference_rows, image, x0, y0, side);
}

int DiscHalfWidth(int dy) { return HalfWidths()[std::abs(dy)]; }

DiscMoments DiscMomentsAt(const cv::Mat& image, int cx, int cy) {
  // The AVX2 rows read 32 bytes from cx - 15: inside the image when cx + 16 < cols.
  const bool avx2_inside =
      cx >= kDiscRadius && cy >= kDiscRadius && cx + kDiscRadius + 1 < image.cols && cy + kDiscRadius < image.rows;
  if (avx2_inside && CpuHasAvx2()) return DiscMomentsAvx2(image, cx, cy);
  return DiscMomentsPortable(image, cx, cy);
}

}  // namespace rovo
