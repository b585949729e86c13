#pragma once
// SSE helpers of the lights' loop (render/lights.cc): log2, exp2 and 1/sqrt per lane.
#include <emmintrin.h>

namespace rovo {
namespace tracer_internal {

// log2(x) per lane for normal x > 0: x = 2^e m, m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(t) with
// t = (m - 1) / (m + 1), |t| < 0.172, to t^7 (error below 4e-7).
inline __m128 Log2x4(__m128 x) {
  const __m128i bits = _mm_castps_si128(x);
  __m128 e = _mm_cvtepi32_ps(
      _mm_sub_epi32(_mm_and_si128(_mm_srli_epi32(bits, 23), _mm_set1_epi32(0xff)), _mm_set1_epi32(127)));
  __m128 m =
      _mm_castsi128_ps(_mm_or_si128(_mm_and_si128(bits, _mm_set1_epi32(0x007fffff)), _mm_set1_epi32(0x3f800000)));
  const __m128 big = _mm_cmpgt_ps(m, _mm_set1_ps(1.41421356f));
  m = _mm_or_ps(_mm_and_ps(big, _mm_mul_ps(m, _mm_set1_ps(0.5f))), _mm_andnot_ps(big, m));
  e = _mm_add_ps(e, _mm_and_ps(big, _mm_set1_ps(1.0f)));
  const __m128 t = _mm_div_ps(_mm_sub_ps(m, _mm_set1_ps(1.0f)), _mm_add_ps(m, _mm_set1_ps(1.0f)));
  const __m128 t2 = _mm_mul_ps(t, t);
  __m128 p = _mm_add_ps(_mm_set1_ps(1.0f / 5.0f), _mm_mul_ps(t2, _mm_set1_ps(1.0f / 7.0f)));
  p = _mm_add_ps(_mm_set1_ps(1.0f / 3.0f), _mm_mul_ps(t2, p));
  p = _mm_add_ps(_mm_set1_ps(1.0f), _mm_mul_ps(t2, p));
  return _mm_add_ps(e, _mm_mul_ps(_mm_mul_ps(t, p), _mm_set1_ps(2.0f * 1.44269504f)));
}

// 2^x per lane for x >= -126 (smaller x is clamped there): 2^round(x) times the Taylor series of
// 2^f, |f| <= 1/2, to f^5 (relative error below 4e-6).
inline __m128 Exp2x4(__m128 x) {
  x = _mm_min_ps(_mm_max_ps(x, _mm_set1_ps(-126.0f)), _mm_set1_ps(127.0f));
  const __m128i i = _mm_cvtps_epi32(x);  // round to nearest
  const __m128 f = _mm_sub_ps(x, _mm_cvtepi32_ps(i));
  __m128 p = _mm_set1_ps(1.3333558e-3f);
  p = _mm_add_ps(_mm_set1_ps(9.6181291e-3f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(5.5504109e-2f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(2.4022651e-1f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(6.9314718e-1f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(1.0f), _mm_mul_ps(f, p));
  return _mm_mul_ps(p, _mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(i, _mm_set1_epi32(127)), 23)));
}

// 1 / sqrt(x) per lane: the hardware estimate and one Newton step (relative error about 1e-7 more
// than float's own for normal x > 0).
inline __m128 RsqrtNewton(__m128 x) {
  const __m128 y = _mm_rsqrt_ps(x);
  return _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(0.5f), y), _mm_sub_ps(_mm_set1_ps(3.0f), _mm_mul_ps(_mm_mul_ps(x, y), y)));
}

}  // namespace tracer_internal
}  // namespace rovo
