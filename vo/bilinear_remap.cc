#include "vo/bilinear_remap.h"

#include <immintrin.h>

#include <cstdint>
#include <opencv2/imgproc.hpp>

#include "vo/cpu_dispatch.h"

namespace rovo {
namespace {

constexpr int kTabSize = 32;  // fractions of a pixel per axis (INTER_TAB_SIZE)
constexpr int kTabEntries = kTabSize * kTabSize;
constexpr int kCoefBits = 15;  // INTER_REMAP_COEF_BITS
constexpr int kCoefScale = 1 << kCoefBits;
constexpr int kBlock = 16;  // pixels per AVX2 step: two steps of eight

// OpenCV's weights (BilinearTab_i of initInterTab2D) of fraction entry fy * 32 + fx for the taps (sx, sy),
// (sx + 1, sy), (sx, sy + 1), (sx + 1, sy + 1): each product of multiples of 1/32 is exact in float, so
// its 15-bit rounding is 32 (32 - fx)(32 - fy), 32 fx (32 - fy), 32 (32 - fx) fy, 32 fx fy; only entry
// 0's 2^15 saturates to 32767, and the table's sum correction makes its last weight 1.
struct TapWeights {
  int w[4];
};

TapWeights WeightsOf(int entry) {
  if (entry == 0) return {{kCoefScale - 1, 0, 0, 1}};
  const int fx = entry % kTabSize, fy = entry / kTabSize, gx = kTabSize - fx, gy = kTabSize - fy;
  return {{kTabSize * gx * gy, kTabSize * fx * gy, kTabSize * gx * fy, kTabSize * fx * fy}};
}

// One pixel as cv::remap's border loop computes it with BORDER_CONSTANT and the value 0: taps outside
// the image count as 0.
uint8_t PixelAt(const cv::Mat& src, int sx, int sy, const TapWeights& weights) {
  const int* w = weights.w;
  int sum = 0;
  const auto tap = [&](int x, int y, int weight) {
    if (static_cast<unsigned>(x) < static_cast<unsigned>(src.cols) &&
        static_cast<unsigned>(y) < static_cast<unsigned>(src.rows)) {
      sum += src.ptr<uint8_t>(y)[x] * weight;
    }
  };
  tap(sx, sy, w[0]);
  tap(sx + 1, sy, w[1]);
  tap(sx, sy + 1, w[2]);
  tap(sx + 1, sy + 1, w[3]);
  return cv::saturate_cast<uint8_t>((sum + (1 << (kCoefBits - 1))) >> kCoefBits);
}

void RemapPixels(const cv::Mat& src, const int16_t* xy, const uint16_t* frac, int count, uint8_t* out) {
  for (int x = 0; x < count; ++x) {
    out[x] = PixelAt(src, xy[2 * x], xy[2 * x + 1], WeightsOf(frac[x] & (kTabEntries - 1)));
  }
}

// Constants of a row's AVX2 steps.
struct Avx2Row {
  const uint8_t* top_row;     // the image's first row
  const uint8_t* bottom_row;  // its second row
  __m256i offset_of_pair;     // (1, step) as int16 pairs: madd of (sx, sy) gives sy * step + sx
  __m256i x_limit, y_limit;   // sx <= cols - 2, sy <= rows - 3: all four taps and the gathers' bytes inside
  __m256i spread;             // bytes 0 and 1 of each int32 lane to int16 lanes 0 and 1
};

ROVO_TARGET_AVX2 inline Avx2Row MakeAvx2Row(const cv::Mat& src) {
  const int step = static_cast<int>(src.step);
  const __m256i spread = _mm256_setr_epi8(0, -1, 1, -1, 4, -1, 5, -1, 8, -1, 9, -1, 12, -1, 13, -1,  //
                                          0, -1, 1, -1, 4, -1, 5, -1, 8, -1, 9, -1, 12, -1, 13, -1);
  return {src.data,
          src.data + step,
          _mm256_set1_epi32((step << 16) | 1),
          _mm256_set1_epi32(src.cols - 1),
          _mm256_set1_epi32(src.rows - 2),
          spread};
}

// Whether the eight (sx, sy) pairs of `xy` lie where the gathers may read: sx in [0, cols - 2], sy in
// [0, rows - 3] (each gather reads four bytes from sx of rows sy and sy + 1).
ROVO_TARGET_AVX2 inline bool EightInside(const Avx2Row& row, __m256i xy) {
  const __m256i sx = _mm256_srai_epi32(_mm256_slli_epi32(xy, 16), 16);
  const __m256i sy = _mm256_srai_epi32(xy, 16);
  const __m256i minus_one = _mm256_set1_epi32(-1);
  const __m256i inside =
      _mm256_and_si256(_mm256_and_si256(_mm256_cmpgt_epi32(sx, minus_one), _mm256_cmpgt_epi32(row.x_limit, sx)),
                       _mm256_and_si256(_mm256_cmpgt_epi32(sy, minus_one), _mm256_cmpgt_epi32(row.y_limit, sy)));
  return _mm256_movemask_epi8(inside) == -1;
}

// 32 v in both int16 halves of each int32 lane (v <= 32).
ROVO_TARGET_AVX2 inline __m256i BothHalvesTimes32(__m256i v) {
  return _mm256_or_si256(_mm256_slli_epi32(v, 5), _mm256_slli_epi32(v, 21));
}

// WeightsOf for eight fraction indices, as int16 pairs (w0, w1) and (w2, w3): computed, as a table's
// loads would compete with the pixels' gathers.
ROVO_TARGET_AVX2 inline void EightWeights(__m128i frac, __m256i* top, __m256i* bottom) {
  const __m256i entry = _mm256_and_si256(_mm256_cvtepu16_epi32(frac), _mm256_set1_epi32(kTabEntries - 1));
  const __m256i fx = _mm256_and_si256(entry, _mm256_set1_epi32(kTabSize - 1));
  const __m256i fy = _mm256_srli_epi32(entry, 5);
  const __m256i gx = _mm256_sub_epi32(_mm256_set1_epi32(kTabSize), fx);
  const __m256i gy = _mm256_sub_epi32(_mm256_set1_epi32(kTabSize), fy);
  const __m256i x_pair = _mm256_or_si256(gx, _mm256_slli_epi32(fx, 16));  // (32 - fx, fx)
  const __m256i is_zero = _mm256_cmpeq_epi32(entry, _mm256_setzero_si256());
  *top =
      _mm256_blendv_epi8(_mm256_mullo_epi16(x_pair, BothHalvesTimes32(gy)), _mm256_set1_epi32(kCoefScale - 1), is_zero);
  *bottom = _mm256_blendv_epi8(_mm256_mullo_epi16(x_pair, BothHalvesTimes32(fy)), _mm256_set1_epi32(1 << 16), is_zero);
}

// Eight pixels, as int32: (sum of tap * weight + 2^14) >> 15.
ROVO_TARGET_AVX2 inline __m256i EightPixels(const Avx2Row& row, __m256i xy, const uint16_t* frac) {
  const __m256i offset = _mm256_madd_epi16(xy, row.offset_of_pair);
  const __m256i top = _mm256_i32gather_epi32(reinterpret_cast<const int*>(row.top_row), offset, 1);
  const __m256i bottom = _mm256_i32gather_epi32(reinterpret_cast<const int*>(row.bottom_row), offset, 1);
  __m256i top_weights, bottom_weights;
  EightWeights(_mm_loadu_si128(reinterpret_cast<const __m128i*>(frac)), &top_weights, &bottom_weights);
  const __m256i sum = _mm256_add_epi32(_mm256_madd_epi16(_mm256_shuffle_epi8(top, row.spread), top_weights),
                                       _mm256_madd_epi16(_mm256_shuffle_epi8(bottom, row.spread), bottom_weights));
  return _mm256_srai_epi32(_mm256_add_epi32(sum, _mm256_set1_epi32(1 << (kCoefBits - 1))), kCoefBits);
}

// Sixteen int32 pixels in [0, 255] stored as bytes, in order.
ROVO_TARGET_AVX2 inline void StoreSixteen(__m256i first, __m256i second, uint8_t* out) {
  const __m256i words = _mm256_permute4x64_epi64(_mm256_packs_epi32(first, second), 0xD8);
  const __m256i bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(words, words), 0x08);
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm256_castsi256_si128(bytes));
}

ROVO_TARGET_AVX2 void RemapRowAvx2(const cv::Mat& src, const Avx2Row& row, const int16_t* xy, const uint16_t* frac,
                                   int width, uint8_t* out) {
  int x = 0;
  for (; x + kBlock <= width; x += kBlock) {
    const __m256i xy_first = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(xy + 2 * x));
    const __m256i xy_second = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(xy + 2 * x + 16));
    if (EightInside(row, xy_first) && EightInside(row, xy_second)) {
      StoreSixteen(EightPixels(row, xy_first, frac + x), EightPixels(row, xy_second, frac + x + 8), out + x);
    } else {
      RemapPixels(src, xy + 2 * x, frac + x, kBlock, out + x);
    }
  }
  RemapPixels(src, xy + 2 * x, frac + x, width - x, out + x);
}

ROVO_TARGET_AVX2 void RemapAvx2(const cv::Mat& src, const cv::Mat& map_fixed, const cv::Mat& map_frac, cv::Mat* dst) {
  const Avx2Row row = MakeAvx2Row(src);
  for (int y = 0; y < map_fixed.rows; ++y) {
    RemapRowAvx2(src, row, map_fixed.ptr<int16_t>(y), map_frac.ptr<uint16_t>(y), map_fixed.cols, dst->ptr<uint8_t>(y));
  }
}

}  // namespace

bool RemapBilinearGrayApplies(const cv::Mat& src, const cv::Mat& map_fixed, const cv::Mat& map_frac,
                              const cv::Mat& dst) {
  return CpuHasAvx2() && src.type() == CV_8UC1 && !src.empty() && src.step < 0x8000 && !map_fixed.empty() &&
         map_fixed.type() == CV_16SC2 && map_frac.type() == CV_16UC1 && map_fixed.size() == map_frac.size() &&
         dst.data != src.data;
}

void RemapBilinearGray(const cv::Mat& src, const cv::Mat& map_fixed, const cv::Mat& map_frac, cv::Mat* dst) {
  if (!RemapBilinearGrayApplies(src, map_fixed, map_frac, *dst)) {
    cv::remap(src, *dst, map_fixed, map_frac, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
    return;
  }
  dst->create(map_fixed.size(), CV_8UC1);
  RemapAvx2(src, map_fixed, map_frac, dst);
}

}  // namespace rovo
