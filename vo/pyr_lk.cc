#include "vo/pyr_lk.h"

#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>

#include "vo/cpu_dispatch.h"

// vo/CMakeLists.txt compiles this file with -ffp-contract=off: a product and a sum must round twice, as
// in OpenCV's SSE2 build, on any target.

namespace rovo {
namespace {

constexpr int kWindowWidth = 15;
constexpr int kMaxRows = 32;
constexpr int kLanes = 16;     // one AVX2 register of int16: a window row and one spare column
constexpr int kLaneBlock = 8;  // OpenCV's float lanes cover the first 8 columns of a row
constexpr int kWBits = 14;     // bilinear weights: 1 << kWBits in all
constexpr float kFltScale = 1.0f / (1 << 20);
constexpr float kMinEigThreshold = 1e-4f;  // cv::calcOpticalFlowPyrLK's default, as float
constexpr int64_t kExactFloatLimit = int64_t{1} << 24;

// cvFloor and cvRound of OpenCV 4.6 on x86-64.
inline int FloorInt(float v) {
  const int i = static_cast<int>(v);
  return i - (i > v);
}
inline int RoundInt(float v) { return _mm_cvtss_si32(_mm_set_ss(v)); }

struct Weights {
  int w00, w01, w10, w11;
};

// OpenCV's bilinear weights for the fractions (a, b) of a position.
inline Weights BilinearWeights(float a, float b) {
  Weights w;
  w.w00 = RoundInt((1.f - a) * (1.f - b) * static_cast<float>(1 << kWBits));
  w.w01 = RoundInt(a * (1.f - b) * static_cast<float>(1 << kWBits));
  w.w10 = RoundInt((1.f - a) * b * static_cast<float>(1 << kWBits));
  w.w11 = (1 << kWBits) - w.w00 - w.w01 - w.w10;
  return w;
}

// The window of the previous image at a point: intensity (x 32) and Scharr derivatives, interpolated.
// Column 15 lies outside the window: its derivatives are zero, and its intensity, which Mismatch
// multiplies only by them, is whatever the extraction left there.
// The derivatives are stored for Mismatch's pairwise products (_mm256_madd_epi16 against the
// mismatch shuffled by PairColumns): per row, x and y, (D0 D4 D1 D5 D2 D6 D3 D7 | D8 0 D9 0 D10 0 D11 0),
// and (Dx12 0 Dx13 0 Dx14 0 0 0 | Dy12 0 Dy13 0 Dy14 0 0 0).
struct Patch {
  alignas(32) int16_t i[kMaxRows][kLanes];
  alignas(32) int16_t x_pairs[kMaxRows][kLanes];
  alignas(32) int16_t y_pairs[kMaxRows][kLanes];
  alignas(32) int16_t xy_last[kMaxRows][kLanes];
};

// The gradient matrix in OpenCV's float order (lanes: columns k and k + 4 of the first 8, in turn;
// the rest one by one; then the lanes' sum ((l0 + l2) + (l1 + l3)) added).
struct Gradient {
  float a11, a12, a22;
};

// The (column k, column k + 1) pairs of 16 8-bit pixels of a row (the 16th pixel's partner is zero) as
// int16: columns 0-3 | 8-11 in *lo, 4-7 | 12-15 in *hi (the order of _mm256_madd_epi16's sums).
ROVO_TARGET_AVX2 inline void RowPairs(const uint8_t* row, __m256i* lo, __m256i* hi) {
  const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row));
  const __m256i a0 = _mm256_cvtepu8_epi16(bytes), a1 = _mm256_cvtepu8_epi16(_mm_srli_si128(bytes, 1));
  *lo = _mm256_unpacklo_epi16(a0, a1);
  *hi = _mm256_unpackhi_epi16(a0, a1);
}

// Bilinear interpolation of a window row from the column pairs (RowPairs) of its upper and lower image
// rows: (p00 w00 + p01 w01 + p10 w10 + p11 w11 + 2^(shift - 1)) >> shift per column, as int16 in column order.
ROVO_TARGET_AVX2 inline __m256i InterpolateRow(__m256i upper_lo, __m256i upper_hi, __m256i lower_lo, __m256i lower_hi,
                                               __m256i w0, __m256i w1, int shift) {
  const __m256i rounding = _mm256_set1_epi32(1 << (shift - 1));
  const __m128i count = _mm_cvtsi32_si128(shift);
  const __m256i lo =
      _mm256_add_epi32(_mm256_add_epi32(_mm256_madd_epi16(upper_lo, w0), _mm256_madd_epi16(lower_lo, w1)), rounding);
  const __m256i hi =
      _mm256_add_epi32(_mm256_add_epi32(_mm256_madd_epi16(upper_hi, w0), _mm256_madd_epi16(lower_hi, w1)), rounding);
  return _mm256_packs_epi32(_mm256_sra_epi32(lo, count), _mm256_sra_epi32(hi, count));  // back in column order
}

// The interpolated derivatives of 8 pixels: d00/d01 the (Ix, Iy) pairs of pixels k and k + 1 of the
// upper row, d10/d11 of the lower one. Returns Ix of the 8 pixels in the low half, Iy in the high one.
ROVO_TARGET_AVX2 inline __m256i InterpolatePairs(__m256i d00, __m256i d01, __m256i d10, __m256i d11, __m256i w0,
                                                 __m256i w1) {
  const __m256i rounding = _mm256_set1_epi32(1 << (kWBits - 1));
  // unpacklo: (Ix, Iy) of pixels 0-1 | 4-5, unpackhi: 2-3 | 6-7.
  const __m256i lo = _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(d00, d01), w0),
                                      _mm256_madd_epi16(_mm256_unpacklo_epi16(d10, d11), w1));
  const __m256i hi = _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(d00, d01), w0),
                                      _mm256_madd_epi16(_mm256_unpackhi_epi16(d10, d11), w1));
  const __m256i pairs = _mm256_packs_epi32(_mm256_srai_epi32(_mm256_add_epi32(lo, rounding), kWBits),
                                           _mm256_srai_epi32(_mm256_add_epi32(hi, rounding), kWBits));
  // (Ix0 Iy0 .. Ix3 Iy3 | Ix4 Iy4 .. Ix7 Iy7) -> (Ix0..Ix3 Iy0..Iy3 | Ix4..Ix7 Iy4..Iy7) -> Ix0..7 | Iy0..7.
  const __m256i split =
      _mm256_shuffle_epi8(pairs, _mm256_setr_epi8(0, 1, 4, 5, 8, 9, 12, 13, 2, 3, 6, 7, 10, 11, 14, 15, 0, 1, 4, 5, 8,
                                                  9, 12, 13, 2, 3, 6, 7, 10, 11, 14, 15));
  return _mm256_permute4x64_epi64(split, _MM_SHUFFLE(3, 1, 2, 0));
}

ROVO_TARGET_AVX2 inline __m256i PairWeights(int a, int b) {
  return _mm256_set1_epi32(static_cast<int>((static_cast<uint32_t>(a) & 0xffffu) | (static_cast<uint32_t>(b) << 16)));
}

// In-lane shuffles of 16 int16 columns: PairColumns gives (c0 c4 c1 c5 c2 c6 c3 c7 | c8 0 c9 0 c10 0 c11 0),
// LastColumns (c12 0 c13 0 c14 0 c15 0) from the upper half of each 128-bit lane.
ROVO_TARGET_AVX2 inline __m256i PairColumns(__m256i v) {
  return _mm256_shuffle_epi8(v, _mm256_setr_epi8(0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15, 0, 1, -1, -1, 2,
                                                 3, -1, -1, 4, 5, -1, -1, 6, 7, -1, -1));
}
ROVO_TARGET_AVX2 inline __m256i LastColumns(__m256i v) {
  return _mm256_shuffle_epi8(v, _mm256_setr_epi8(8, 9, -1, -1, 10, 11, -1, -1, 12, 13, -1, -1, 14, 15, -1, -1, 8, 9, -1,
                                                 -1, 10, 11, -1, -1, 12, 13, -1, -1, 14, 15, -1, -1));
}

// 8 (Ix, Iy) pairs; Load7 leaves the 8th unread (zero).
ROVO_TARGET_AVX2 inline __m256i Load(const int16_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}
ROVO_TARGET_AVX2 inline __m256i Load7(const int16_t* p) {
  return _mm256_maskload_epi32(reinterpret_cast<const int*>(p), _mm256_setr_epi32(-1, -1, -1, -1, -1, -1, -1, 0));
}

// The gradient matrix's sums over a patch's rows, in OpenCV's order (Gradient), and the patch's rows.
struct GradientSums {
  __m128 lane11 = _mm_setzero_ps(), lane12 = _mm_setzero_ps(), lane22 = _mm_setzero_ps();
  alignas(32) int32_t tail_xx[kMaxRows][kLaneBlock], tail_xy[kMaxRows][kLaneBlock], tail_yy[kMaxRows][kLaneBlock];

  // Window row y: its interpolated intensity and derivatives (Ix, Iy of columns 0..15; column 15 is
  // outside the window and cleared here).
  ROVO_TARGET_AVX2 void AddRow(int y, __m256i intensity, __m256i ix, __m256i iy, Patch* patch) {
    const __m256i window_columns = _mm256_setr_epi16(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0);
    ix = _mm256_and_si256(ix, window_columns);
    iy = _mm256_and_si256(iy, window_columns);
    _mm256_store_si256(reinterpret_cast<__m256i*>(patch->i[y]), intensity);
    _mm256_store_si256(reinterpret_cast<__m256i*>(patch->x_pairs[y]), PairColumns(ix));
    _mm256_store_si256(reinterpret_cast<__m256i*>(patch->y_pairs[y]), PairColumns(iy));
    _mm256_store_si256(reinterpret_cast<__m256i*>(patch->xy_last[y]),
                       LastColumns(_mm256_permute2x128_si256(ix, iy, 0x31)));

    // OpenCV's lanes: columns 0-3, then 4-7 (product, then sum: two roundings, no FMA).
    const __m128i ix07 = _mm256_castsi256_si128(ix), iy07 = _mm256_castsi256_si128(iy);
    for (const int half : {0, 1}) {
      const __m128i sx = half == 0 ? ix07 : _mm_srli_si128(ix07, 8), sy = half == 0 ? iy07 : _mm_srli_si128(iy07, 8);
      const __m128 fx = _mm_cvtepi32_ps(_mm_cvtepi16_epi32(sx)), fy = _mm_cvtepi32_ps(_mm_cvtepi16_epi32(sy));
      lane22 = _mm_add_ps(_mm_mul_ps(fy, fy), lane22);
      lane12 = _mm_add_ps(_mm_mul_ps(fx, fy), lane12);
      lane11 = _mm_add_ps(_mm_mul_ps(fx, fx), lane11);
    }
    // Columns 8..15 (15 is zero) as exact int32 products, added one by one in Total.
    const __m256i tx = _mm256_cvtepi16_epi32(_mm256_extracti128_si256(ix, 1));
    const __m256i ty = _mm256_cvtepi16_epi32(_mm256_extracti128_si256(iy, 1));
    _mm256_store_si256(reinterpret_cast<__m256i*>(tail_xx[y]), _mm256_mullo_epi32(tx, tx));
    _mm256_store_si256(reinterpret_cast<__m256i*>(tail_xy[y]), _mm256_mullo_epi32(tx, ty));
    _mm256_store_si256(reinterpret_cast<__m256i*>(tail_yy[y]), _mm256_mullo_epi32(ty, ty));
  }

  Gradient Total(int rows) const {
    float a11 = 0, a12 = 0, a22 = 0;
    for (int y = 0; y < rows; ++y) {
      for (int k = 0; k < kWindowWidth - kLaneBlock; ++k) {
        a11 += static_cast<float>(tail_xx[y][k]);
        a12 += static_cast<float>(tail_xy[y][k]);
        a22 += static_cast<float>(tail_yy[y][k]);
      }
    }
    alignas(16) float l11[4], l12[4], l22[4];
    _mm_store_ps(l11, lane11);
    _mm_store_ps(l12, lane12);
    _mm_store_ps(l22, lane22);
    a11 += (l11[0] + l11[2]) + (l11[1] + l11[3]);
    a12 += (l12[0] + l12[2]) + (l12[1] + l12[3]);
    a22 += (l22[0] + l22[2]) + (l22[1] + l22[3]);
    return {a11 * kFltScale, a12 * kFltScale, a22 * kFltScale};
  }
};

// Extracts the patch whose top-left pixel is `corner` and sums its gradient matrix, the derivatives
// read from memory: `deriv` holds the (Ix, Iy) pair of the window's top-left pixel, `step_d` int16 per
// row. Reads what OpenCV reads: columns 0..15 and rows 0..rows of the window (the last pixel pair
// through a masked load).
ROVO_TARGET_AVX2 Gradient ExtractPatch(const cv::Mat& image, const int16_t* deriv, size_t step_d, cv::Point corner,
                                       const Weights& w, int rows, Patch* patch) {
  const size_t step_i = image.step[0];
  const __m256i w0 = PairWeights(w.w00, w.w01), w1 = PairWeights(w.w10, w.w11);
  GradientSums sums;
  for (int y = 0; y < rows; ++y) {
    const uint8_t* src = image.ptr<uint8_t>(corner.y + y) + corner.x;
    __m256i upper_lo, upper_hi, lower_lo, lower_hi;
    RowPairs(src, &upper_lo, &upper_hi);
    RowPairs(src + step_i, &lower_lo, &lower_hi);
    const __m256i intensity = InterpolateRow(upper_lo, upper_hi, lower_lo, lower_hi, w0, w1, kWBits - 5);
    const int16_t* d = deriv + y * step_d;
    const int16_t* e = d + step_d;
    const __m256i g0 = InterpolatePairs(Load(d), Load(d + 2), Load(e), Load(e + 2), w0, w1);
    const __m256i g1 = InterpolatePairs(Load(d + 16), Load7(d + 18), Load(e + 16), Load7(e + 18), w0, w1);
    sums.AddRow(y, intensity, _mm256_permute2x128_si256(g0, g1, 0x20), _mm256_permute2x128_si256(g0, g1, 0x31), patch);
  }
  return sums.Total(rows);
}

// An image row's 16 pixels from column x + offset, as int16.
ROVO_TARGET_AVX2 inline __m256i Widen(const uint8_t* row, int offset) {
  return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + offset)));
}

// An image row's pixels at columns x - 1, x, x + 1 and x + 2 (16 each, int16).
struct ShiftedRow {
  __m256i m1, p0, p1, p2;
};
ROVO_TARGET_AVX2 inline ShiftedRow LoadShifted(const uint8_t* row) {
  return {Widen(row, -1), Widen(row, 0), Widen(row, 1), Widen(row, 2)};
}

// Scharr derivatives of a row of 16 pixels (columns x..x+15) and of the same row one pixel to the right,
// from the image rows above, at and below it: as calcScharrDeriv (modules/video/src/lkpyramid.cpp),
// vertical pass t0 = 3 (above + below) + 10 at, t1 = below - above, then Ix = t0(x + 1) - t0(x - 1),
// Iy = 3 (t1(x - 1) + t1(x + 1)) + 10 t1(x), in int16 (|value| <= 16 * 255, no wrap).
struct ScharrRow {
  __m256i ix, iy, ix_right, iy_right;
};
// 3 (a + c) + 10 b, the Scharr smoothing, in int16.
ROVO_TARGET_AVX2 inline __m256i Smooth(__m256i a, __m256i b, __m256i c) {
  return _mm256_add_epi16(_mm256_mullo_epi16(_mm256_add_epi16(a, c), _mm256_set1_epi16(3)),
                          _mm256_mullo_epi16(b, _mm256_set1_epi16(10)));
}
ROVO_TARGET_AVX2 inline ScharrRow Scharr(const ShiftedRow& above, const ShiftedRow& at, const ShiftedRow& below) {
  const __m256i t0_m1 = Smooth(above.m1, at.m1, below.m1), t0_p0 = Smooth(above.p0, at.p0, below.p0);
  const __m256i t0_p1 = Smooth(above.p1, at.p1, below.p1), t0_p2 = Smooth(above.p2, at.p2, below.p2);
  const __m256i t1_m1 = _mm256_sub_epi16(below.m1, above.m1), t1_p0 = _mm256_sub_epi16(below.p0, above.p0);
  const __m256i t1_p1 = _mm256_sub_epi16(below.p1, above.p1), t1_p2 = _mm256_sub_epi16(below.p2, above.p2);
  ScharrRow r;
  r.ix = _mm256_sub_epi16(t0_p1, t0_m1);
  r.ix_right = _mm256_sub_epi16(t0_p2, t0_p0);
  r.iy = Smooth(t1_m1, t1_p0, t1_p1);
  r.iy_right = Smooth(t1_p0, t1_p1, t1_p2);
  return r;
}

// Bilinear interpolation of one derivative over a window row from its values at the upper and lower
// image rows (columns k and, right, k + 1).
ROVO_TARGET_AVX2 inline __m256i InterpolateDerivative(__m256i upper, __m256i upper_right, __m256i lower,
                                                      __m256i lower_right, __m256i w0, __m256i w1) {
  return InterpolateRow(_mm256_unpacklo_epi16(upper, upper_right), _mm256_unpackhi_epi16(upper, upper_right),
                        _mm256_unpacklo_epi16(lower, lower_right), _mm256_unpackhi_epi16(lower, lower_right), w0, w1,
                        kWBits);
}

// ExtractPatch with the derivatives computed from the image, for a window whose Scharr stencils lie
// inside it (ScharrInside): the values cv::buildOpticalFlowPyramid would have stored. Reads image
// columns corner.x - 1 .. corner.x + 17 (the last only for column 15, which is cleared) and rows
// corner.y - 1 .. corner.y + rows + 1.
ROVO_TARGET_AVX2 Gradient ExtractPatchScharr(const cv::Mat& image, cv::Point corner, const Weights& w, int rows,
                                             Patch* patch) {
  const size_t step_i = image.step[0];
  const __m256i w0 = PairWeights(w.w00, w.w01), w1 = PairWeights(w.w10, w.w11);
  const uint8_t* row = image.ptr<uint8_t>(corner.y) + corner.x;
  ShiftedRow above = LoadShifted(row - step_i), at = LoadShifted(row), below = LoadShifted(row + step_i);
  ScharrRow upper = Scharr(above, at, below);
  GradientSums sums;
  for (int y = 0; y < rows; ++y) {
    above = at;
    at = below;
    below = LoadShifted(row + (y + 2) * step_i);
    const ScharrRow lower = Scharr(above, at, below);
    // The intensity's (k, k + 1) pairs are the widened pixels at columns 0 and 1 of rows y and y + 1.
    const __m256i intensity =
        InterpolateRow(_mm256_unpacklo_epi16(above.p0, above.p1), _mm256_unpackhi_epi16(above.p0, above.p1),
                       _mm256_unpacklo_epi16(at.p0, at.p1), _mm256_unpackhi_epi16(at.p0, at.p1), w0, w1, kWBits - 5);
    const __m256i ix = InterpolateDerivative(upper.ix, upper.ix_right, lower.ix, lower.ix_right, w0, w1);
    const __m256i iy = InterpolateDerivative(upper.iy, upper.iy_right, lower.iy, lower.iy_right, w0, w1);
    sums.AddRow(y, intensity, ix, iy, patch);
    upper = lower;
  }
  return sums.Total(rows);
}

// Whether ExtractPatchScharr serves the window at `corner`: every stencil of the window's columns 0..15
// and rows 0..rows lies inside the image, where calcScharrDeriv's border rule does not act.
bool ScharrInside(const cv::Mat& image, cv::Point corner, int rows) {
  return corner.x >= 1 && corner.x + kWindowWidth + 1 <= image.cols - 1 && corner.y >= 1 &&
         corner.y + rows + 1 <= image.rows - 1;
}

// The stored derivatives of window rows 0..rows, columns 0..15 at `corner` (some outside the image), as
// cv::buildOpticalFlowPyramid stores them: calcScharrDeriv's rule inside the image (the row and the
// vertical pass's column beyond an edge reflected, 101), zero outside (BORDER_CONSTANT).
constexpr int kBlockStep = 2 * kLanes;  // int16 per row: (Ix, Iy) of 16 pixels
void ScharrBlock(const cv::Mat& image, cv::Point corner, int rows, int16_t (*block)[kBlockStep]) {
  const int w = image.cols, h = image.rows;
  const auto reflect = [](int i, int n) { return i < 0 ? (n > 1 ? 1 : 0) : i >= n ? (n > 1 ? n - 2 : 0) : i; };
  for (int y = 0; y <= rows; ++y) {
    const int iy = corner.y + y;
    for (int x = 0; x < kLanes; ++x) {
      const int ix = corner.x + x;
      int16_t dx = 0, dy = 0;
      if (ix >= 0 && ix < w && iy >= 0 && iy < h) {
        const uint8_t* above = image.ptr<uint8_t>(reflect(iy - 1, h));
        const uint8_t* at = image.ptr<uint8_t>(iy);
        const uint8_t* below = image.ptr<uint8_t>(reflect(iy + 1, h));
        const auto t0 = [&](int c) { return (above[c] + below[c]) * 3 + at[c] * 10; };
        const auto t1 = [&](int c) { return below[c] - above[c]; };
        const int left = reflect(ix - 1, w), right = reflect(ix + 1, w);
        dx = static_cast<int16_t>(t0(right) - t0(left));
        dy = static_cast<int16_t>((t1(left) + t1(right)) * 3 + t1(ix) * 10);
      }
      block[y][2 * x] = dx;
      block[y][2 * x + 1] = dy;
    }
  }
}

// The sum of the one-by-one columns (8..14) of `rows` rows, added in OpenCV's order (row by row, column
// by column) from `terms`, or, where their magnitudes (per-lane int32 sums in abs_sum) sum below 2^24, as
// the exact integer sum of the per-lane sums in `sum`: then every partial sum is exact in float.
ROVO_TARGET_AVX2 float OneByOneSum(__m256i abs_sum, __m256i sum, const float (*terms)[kLaneBlock], int rows) {
  alignas(32) int32_t a[8], s[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(a), abs_sum);
  _mm256_store_si256(reinterpret_cast<__m256i*>(s), sum);
  int64_t total_abs = 0, total = 0;
  for (int k = 0; k < 8; ++k) {
    total_abs += a[k];
    total += s[k];
  }
  if (total_abs < kExactFloatLimit) return static_cast<float>(total);
  float acc = 0.0f;
  for (int y = 0; y < rows; ++y)
    for (int k = 0; k < kWindowWidth - kLaneBlock; ++k) acc += terms[y][k];
  return acc;
}

// The mismatch vector (b1, b2) of the patch against the moving image whose window's top-left pixel is
// `j` (interpolated with w), in OpenCV's float order (see Gradient; in the lanes the integer sum of
// columns k and k + 4 is converted and added).
ROVO_TARGET_AVX2 void Mismatch(const Patch& patch, const uint8_t* j, size_t step_j, const Weights& w, int rows,
                               float* b1, float* b2) {
  const __m256i w0 = PairWeights(w.w00, w.w01), w1 = PairWeights(w.w10, w.w11);
  __m128 lanes_x = _mm_setzero_ps(), lanes_y = _mm_setzero_ps();
  __m256i abs_x = _mm256_setzero_si256(), abs_y = _mm256_setzero_si256();
  __m256i sum_x = _mm256_setzero_si256(), sum_y = _mm256_setzero_si256();
  alignas(32) float tail_x[kMaxRows][kLaneBlock], tail_y[kMaxRows][kLaneBlock];
  // Each image row's (column k, k + 1) pairs serve as the lower row of one window row and the upper of the next.
  __m256i upper_lo, upper_hi;
  RowPairs(j, &upper_lo, &upper_hi);
  for (int y = 0; y < rows; ++y) {
    j += step_j;
    __m256i lower_lo, lower_hi;
    RowPairs(j, &lower_lo, &lower_hi);
    const __m256i diff = _mm256_subs_epi16(InterpolateRow(upper_lo, upper_hi, lower_lo, lower_hi, w0, w1, kWBits - 5),
                                           _mm256_load_si256(reinterpret_cast<const __m256i*>(patch.i[y])));
    upper_lo = lower_lo;
    upper_hi = lower_hi;
    // Products with the derivatives: (k, k + 4) pairs of columns 0-7 | single columns 8-11, and 12-14 | 12-14.
    const __m256i pairs = PairColumns(diff), last = LastColumns(_mm256_permute2x128_si256(diff, diff, 0x11));
    const __m256i px = _mm256_madd_epi16(pairs, _mm256_load_si256(reinterpret_cast<const __m256i*>(patch.x_pairs[y])));
    const __m256i py = _mm256_madd_epi16(pairs, _mm256_load_si256(reinterpret_cast<const __m256i*>(patch.y_pairs[y])));
    const __m256i pl = _mm256_madd_epi16(last, _mm256_load_si256(reinterpret_cast<const __m256i*>(patch.xy_last[y])));
    lanes_x = _mm_add_ps(lanes_x, _mm_cvtepi32_ps(_mm256_castsi256_si128(px)));
    lanes_y = _mm_add_ps(lanes_y, _mm_cvtepi32_ps(_mm256_castsi256_si128(py)));
    // Columns 8..15 in order (15 is zero: the patch's derivatives are zero there).
    const __m256i tx = _mm256_permute2x128_si256(px, pl, 0x21);
    const __m256i ty = _mm256_permute2x128_si256(py, pl, 0x31);
    _mm256_store_ps(tail_x[y], _mm256_cvtepi32_ps(tx));
    _mm256_store_ps(tail_y[y], _mm256_cvtepi32_ps(ty));
    abs_x = _mm256_add_epi32(abs_x, _mm256_abs_epi32(tx));
    abs_y = _mm256_add_epi32(abs_y, _mm256_abs_epi32(ty));
    sum_x = _mm256_add_epi32(sum_x, tx);
    sum_y = _mm256_add_epi32(sum_y, ty);
  }
  alignas(16) float lx[4], ly[4];
  _mm_store_ps(lx, lanes_x);
  _mm_store_ps(ly, lanes_y);
  // OpenCV pairs lanes 0 and 2, 1 and 3 of each of b1 and b2 before adding the pairs.
  *b1 = OneByOneSum(abs_x, sum_x, tail_x, rows) + ((lx[0] + lx[2]) + (lx[1] + lx[3]));
  *b2 = OneByOneSum(abs_y, sum_y, tail_y, rows) + ((ly[0] + ly[2]) + (ly[1] + ly[3]));
}

struct Level {
  const cv::Mat* image;  // previous image
  const cv::Mat* deriv;  // its derivatives; nullptr: computed here (ExtractPatchScharr, ScharrBlock)
  const cv::Mat* next;   // moving image
};

// The patch of the previous image at `corner` and its gradient matrix.
Gradient PatchAt(const Level& lv, cv::Point corner, const Weights& w, int rows, Patch* patch) {
  if (lv.deriv) {
    const size_t step_d = lv.deriv->step[0] / sizeof(int16_t);
    return ExtractPatch(*lv.image, lv.deriv->ptr<int16_t>(corner.y) + 2 * corner.x, step_d, corner, w, rows, patch);
  }
  if (ScharrInside(*lv.image, corner, rows)) return ExtractPatchScharr(*lv.image, corner, w, rows, patch);
  alignas(32) int16_t block[kMaxRows + 1][kBlockStep];
  ScharrBlock(*lv.image, corner, rows, block);
  return ExtractPatch(*lv.image, block[0], kBlockStep, corner, w, rows, patch);
}

struct Settings {
  cv::Size window;
  int max_count;
  double epsilon2;  // squared
  bool initial_flow;
};

// One point at one level (LKTrackerInvoker::operator() for one point); `next` is the point's state.
void TrackAtLevel(const Level& lv, const Settings& s, int level, int max_level, cv::Point2f from, cv::Point2f* next,
                  uint8_t* status, Patch* patch) {
  const cv::Point2f half_win((s.window.width - 1) * 0.5f, (s.window.height - 1) * 0.5f);
  cv::Point2f prev_pt = from * static_cast<float>(1. / (1 << level));
  cv::Point2f next_pt;
  if (level == max_level)
    next_pt = s.initial_flow ? *next * static_cast<float>(1. / (1 << level)) : prev_pt;
  else
    next_pt = *next * 2.f;
  *next = next_pt;

  prev_pt -= half_win;
  const cv::Point iprev(FloorInt(prev_pt.x), FloorInt(prev_pt.y));
  if (iprev.x < -s.window.width || iprev.x >= lv.image->cols || iprev.y < -s.window.height ||
      iprev.y >= lv.image->rows) {
    if (level == 0) *status = 0;
    return;
  }
  const Gradient g =
      PatchAt(lv, iprev, BilinearWeights(prev_pt.x - iprev.x, prev_pt.y - iprev.y), s.window.height, patch);
  float d = g.a11 * g.a22 - g.a12 * g.a12;
  const float min_eig = (g.a22 + g.a11 - std::sqrt((g.a11 - g.a22) * (g.a11 - g.a22) + 4.f * g.a12 * g.a12)) /
                        static_cast<float>(2 * s.window.width * s.window.height);
  if (min_eig < kMinEigThreshold || d < FLT_EPSILON) {
    if (level == 0) *status = 0;
    return;
  }
  d = 1.f / d;

  const cv::Mat& next_image = *lv.next;
  next_pt -= half_win;
  cv::Point2f prev_delta;
  for (int it = 0; it < s.max_count; ++it) {
    const cv::Point inext(FloorInt(next_pt.x), FloorInt(next_pt.y));
    if (inext.x < -s.window.width || inext.x >= next_image.cols || inext.y < -s.window.height ||
        inext.y >= next_image.rows) {
      if (level == 0) *status = 0;
      break;
    }
    float b1, b2;
    Mismatch(*patch, next_image.ptr<uint8_t>(inext.y) + inext.x, next_image.step[0],
             BilinearWeights(next_pt.x - inext.x, next_pt.y - inext.y), s.window.height, &b1, &b2);
    b1 *= kFltScale;
    b2 *= kFltScale;
    const cv::Point2f delta((g.a12 * b2 - g.a22 * b1) * d, (g.a12 * b1 - g.a11 * b2) * d);
    next_pt += delta;
    *next = next_pt + half_win;
    if (delta.ddot(delta) <= s.epsilon2) break;
    if (it > 0 && std::abs(delta.x + prev_delta.x) < 0.01 && std::abs(delta.y + prev_delta.y) < 0.01) {
      *next -= delta * 0.5f;
      break;
    }
    prev_delta = delta;
  }
}

// Levels of a pyramid as cv::calcOpticalFlowPyrLK reads it: the step between images (2 with
// derivatives) and the number of levels above the base.
struct PyramidShape {
  int step = 1, levels = -1;
};

PyramidShape ShapeOf(const std::vector<cv::Mat>& pyramid) {
  PyramidShape shape;
  if (pyramid.empty()) return shape;
  shape.levels = static_cast<int>(pyramid.size()) - 1;
  if (shape.levels % 2 == 1 && pyramid[0].channels() * 2 == pyramid[1].channels() && pyramid[1].depth() == CV_16S) {
    shape.step = 2;
    shape.levels /= 2;
  }
  return shape;
}

// Whether `m` is an ROI with at least `window` pixels of its allocation on every side (the border
// cv::buildOpticalFlowPyramid leaves, which LK's reads near the image's edges rely on).
bool Padded(const cv::Mat& m, cv::Size window) {
  cv::Size whole;
  cv::Point offset;
  m.locateROI(whole, offset);
  return offset.x >= window.width && offset.y >= window.height && offset.x + m.cols + window.width <= whole.width &&
         offset.y + m.rows + window.height <= whole.height;
}

// The CPU and window PyrLk serves.
bool ServesWindow(cv::Size window) {
  return CpuHasAvx2() && window.width == kWindowWidth && window.height >= 3 && window.height <= kMaxRows;
}

}  // namespace

bool PyrLkApplies(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid, cv::Size window) {
  if (!ServesWindow(window)) return false;
  const PyramidShape from = ShapeOf(from_pyramid), to = ShapeOf(to_pyramid);
  if (from.levels < 0 || to.levels < 0) return false;
  for (int l = 0; l <= std::min(from.levels, to.levels); ++l) {
    const cv::Mat& i = from_pyramid[from.step * l];
    const cv::Mat& j = to_pyramid[to.step * l];
    if (i.type() != CV_8UC1 || j.type() != CV_8UC1 || i.size() != j.size() || !Padded(i, window) || !Padded(j, window))
      return false;
    if (from.step == 2) {
      const cv::Mat& d = from_pyramid[2 * l + 1];
      if (d.type() != CV_16SC2 || d.size() != i.size() || !Padded(d, window)) return false;
    }
  }
  return true;
}

void PyrLk(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid, const cv::Point2f* from,
           cv::Point2f* to, uint8_t* status, int n, cv::Size window, int max_level, const cv::TermCriteria& criteria,
           int flags) {
  if (max_level < 0) throw std::invalid_argument("PyrLk: max_level must be >= 0");
  if (n <= 0) return;
  if (!PyrLkApplies(from_pyramid, to_pyramid, window)) {  // OpenCV itself, on the caller's arrays
    const cv::Mat from_mat(n, 1, CV_32FC2, const_cast<cv::Point2f*>(from));
    cv::Mat to_mat(n, 1, CV_32FC2, to), status_mat(n, 1, CV_8U, status);
    cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, from_mat, to_mat, status_mat, cv::noArray(), window, max_level,
                             criteria, flags);
    return;
  }
  const PyramidShape from_shape = ShapeOf(from_pyramid), to_shape = ShapeOf(to_pyramid);
  max_level = std::min({max_level, from_shape.levels, to_shape.levels});
  Settings s;
  s.window = window;
  s.initial_flow = (flags & cv::OPTFLOW_USE_INITIAL_FLOW) != 0;
  s.max_count = (criteria.type & cv::TermCriteria::COUNT) == 0 ? 30 : std::min(std::max(criteria.maxCount, 0), 100);
  const double eps =
      (criteria.type & cv::TermCriteria::EPS) == 0 ? 0.01 : std::min(std::max(criteria.epsilon, 0.), 10.);
  s.epsilon2 = eps * eps;
  std::vector<Level> levels(max_level + 1);
  for (int l = 0; l <= max_level; ++l)
    levels[l] = {&from_pyramid[from_shape.step * l], from_shape.step == 2 ? &from_pyramid[2 * l + 1] : nullptr,
                 &to_pyramid[to_shape.step * l]};
  Patch patch;
  for (int k = 0; k < n; ++k) {
    status[k] = 1;
    for (int l = max_level; l >= 0; --l) TrackAtLevel(levels[l], s, l, max_level, from[k], &to[k], &status[k], &patch);
  }
}

int BuildPyrLkPyramid(const cv::Mat& image, std::vector<cv::Mat>* pyramid, cv::Size window, int max_level) {
  return cv::buildOpticalFlowPyramid(image, *pyramid, window, max_level, !ServesWindow(window));
}

}  // namespace rovo
