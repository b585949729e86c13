#include "render/texture.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace rovo {

float SrgbToLinear(float srgb) { return srgb <= 0.04045f ? srgb / 12.92f : std::pow((srgb + 0.055f) / 1.055f, 2.4f); }

float LinearToSrgb(float linear) {
  linear = std::clamp(linear, 0.0f, 1.0f);
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

namespace {

// 16-bit linear r, g, b (x 1/65535) in one texel word: lround(y) for the float y = clamp(x) * 65535 in
// [0, 65535], without the library call. y + 1/2 in double is exact wherever it could reach an integer (a
// float below 1/2 is at most 1/2 - 2^-25), so truncating it rounds half away from zero as lround does.
uint64_t Pack(float r, float g, float b) {
  auto q = [](float x) {
    const float y = std::clamp(x, 0.0f, 1.0f) * 65535.0f;
    return static_cast<uint64_t>(static_cast<double>(y) + 0.5);  // NOLINT(bugprone-incorrect-roundings): above
  };
  return q(r) | (q(g) << 16) | (q(b) << 32);
}

// The box-filtered reduction of a sw x sh level whose linear colour channel c at (x, y) is
// source(x, y, c): the dst_w x dst_h level (odd sizes clamp the last row or column) as floats in `next`
// (3 per texel) and packed by `put(x, y, texel)`.
template <typename Source, typename Put>
void Reduce(const Source& source, int sw, int sh, int dst_w, int dst_h, float* next, const Put& put) {
  for (int y = 0; y < dst_h; ++y) {
    const int y0 = std::min(2 * y, sh - 1), y1 = std::min(2 * y + 1, sh - 1);
    for (int x = 0; x < dst_w; ++x) {
      const int x0 = std::min(2 * x, sw - 1), x1 = std::min(2 * x + 1, sw - 1);
      float* out = next + (static_cast<size_t>(y) * dst_w + x) * 3;
      for (int c = 0; c < 3; ++c)
        out[c] = 0.25f * (source(x0, y0, c) + source(x1, y0, c) + source(x0, y1, c) + source(x1, y1, c));
      put(x, y, Pack(out[0], out[1], out[2]));
    }
  }
}

}  // namespace

MipTexture::MipTexture(const Texture& texture) {
  if (texture.width <= 0 || texture.height <= 0 ||
      texture.rgb.size() != static_cast<size_t>(texture.width) * texture.height * 3) {
    throw std::invalid_argument("texture '" + texture.name + "': size " + std::to_string(texture.width) + "x" +
                                std::to_string(texture.height) + " does not match its " +
                                std::to_string(texture.rgb.size()) + " bytes of RGB data");
  }
  if (static_cast<double>(texture.width) * texture.height >= 2147483648.0)
    throw std::invalid_argument("texture '" + texture.name + "': more than 2^31 texels (lookups use 32-bit indices)");
  float to_linear[256];
  for (int i = 0; i < 256; ++i) to_linear[i] = SrgbToLinear(i / 255.0f);

  // Level 0 straight from the 8-bit texels; the reduced levels average linear floats, level 1 read
  // through the table (no float copy of level 0).
  Level base;
  base.Allocate(texture.width, texture.height);
  const uint8_t* rgb = texture.rgb.data();
  for (int y = 0; y < texture.height; ++y) {
    const uint8_t* row = rgb + static_cast<size_t>(y) * texture.width * 3;
    const size_t row_offset = base.RowOffset(y);
    for (int x = 0; x < texture.width; ++x) {
      base.texels[row_offset + Level::ColumnOffset(x)] =
          Pack(to_linear[row[3 * x]], to_linear[row[3 * x + 1]], to_linear[row[3 * x + 2]]);
    }
  }
  levels_.push_back(std::move(base));
  texels_per_uv_ = std::sqrt(static_cast<float>(texture.width) * static_cast<float>(texture.height));

  // Box-filtered reduction until 1x1; `linear` holds the last reduced level (3 floats per texel).
  std::unique_ptr<float[]> linear, next;
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const int sw = levels_.back().width, sh = levels_.back().height;
    Level dst;
    dst.Allocate(std::max(1, sw / 2), std::max(1, sh / 2));
    next.reset(new float[static_cast<size_t>(dst.width) * dst.height * 3]);  // every value is written
    auto put = [&dst](int x, int y, uint64_t texel) { dst.texels[dst.Index(x, y)] = texel; };
    if (levels_.size() == 1) {
      const int w = texture.width;
      Reduce([&](int x, int y, int c) { return to_linear[rgb[(static_cast<size_t>(y) * w + x) * 3 + c]]; }, sw, sh,
             dst.width, dst.height, next.get(), put);
    } else {
      const float* src = linear.get();
      Reduce([&](int x, int y, int c) { return src[(static_cast<size_t>(y) * sw + x) * 3 + c]; }, sw, sh, dst.width,
             dst.height, next.get(), put);
    }
    linear.swap(next);
    levels_.push_back(std::move(dst));
  }
  for (Level& l : levels_) {
    l.fwidth = static_cast<float>(l.width);
    l.fheight = static_cast<float>(l.height);
  }
  last_level_ = static_cast<int>(levels_.size()) - 1;
}

Eigen::Vector3f MipTexture::Texel(int level, int x, int y) const {
  const Level& l = levels_[level];
  x %= l.width;
  if (x < 0) x += l.width;
  y %= l.height;
  if (y < 0) y += l.height;
  const uint64_t t = l.texels[l.Index(x, y)];
  constexpr float kScale = 1.0f / 65535.0f;
  return Eigen::Vector3f((t & 0xffffu) * kScale, ((t >> 16) & 0xffffu) * kScale, ((t >> 32) & 0xffffu) * kScale);
}

namespace {

// floor(x) as an int for |x| < 2^31, without a libm call or a rounding-mode switch.
inline int FloorInt(float x) {
  const int i = static_cast<int>(x);
  return i - (x < static_cast<float>(i));
}

// x - floor(x) in [0, 1) (one repeat of a wrapping texture coordinate); non-finite -> 0.
inline float WrapFinite01(float x) {
  if (!(std::abs(x) < 1e9f)) return 0.0f;
  const float w = x - static_cast<float>(FloorInt(x));
  return w < 1.0f ? w : 0.0f;
}

}  // namespace

__m128 MipTexture::SampleWrapped(float u01, float v01, int level) const {
  const Level& l = levels_[level];
  // Texel centres sit at (i + 0.5) / width in UV; u01 in [0, 1) gives fu in [-0.5, width - 0.5).
  const float fu = u01 * l.fwidth - 0.5f;
  const float fv = v01 * l.fheight - 0.5f;
  int xa = FloorInt(fu), ya = FloorInt(fv);
  const float ax = fu - static_cast<float>(xa), ay = fv - static_cast<float>(ya);
  if (xa < 0) xa = l.width - 1;  // left of the first centre: between the last and the first texel
  if (ya < 0) ya = l.height - 1;
  if (xa >= l.width) xa = l.width - 1;  // rounding guard
  if (ya >= l.height) ya = l.height - 1;
  const int xb = xa + 1 == l.width ? 0 : xa + 1;
  const int yb = ya + 1 == l.height ? 0 : ya + 1;
  // Index(x, y) = RowOffset(y) + ColumnOffset(x): the two parts never share a bit below 16 and add.
  const size_t col_a = l.ColumnOffset(xa), col_b = l.ColumnOffset(xb);
  const uint64_t* row_a = l.texels.data() + l.RowOffset(ya);
  const uint64_t* row_b = l.texels.data() + l.RowOffset(yb);
  const __m128i zero = _mm_setzero_si128();
  auto load = [&](const uint64_t* p) {
    return _mm_cvtepi32_ps(_mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)), zero));
  };
  const __m128 t00 = load(row_a + col_a), t10 = load(row_a + col_b);
  const __m128 t01 = load(row_b + col_a), t11 = load(row_b + col_b);
  const __m128 vax = _mm_set1_ps(ax), vay = _mm_set1_ps(ay);
  const __m128 top = _mm_add_ps(t00, _mm_mul_ps(vax, _mm_sub_ps(t10, t00)));
  const __m128 bottom = _mm_add_ps(t01, _mm_mul_ps(vax, _mm_sub_ps(t11, t01)));
  return _mm_mul_ps(_mm_add_ps(top, _mm_mul_ps(vay, _mm_sub_ps(bottom, top))), _mm_set1_ps(1.0f / 65535.0f));
}

__m128 MipTexture::SampleLevel4(float u, float v, int level) const {
  return SampleWrapped(WrapFinite01(u), WrapFinite01(v), level);
}

Eigen::Vector3f MipTexture::SampleLevel(float u, float v, int level) const {
  alignas(16) float out[4];
  _mm_store_ps(out, SampleLevel4(u, v, level));
  return Eigen::Vector3f(out[0], out[1], out[2]);
}

__m128 MipTexture::Sample4(float u, float v, float lod) const {
  const int last = NumLevels() - 1;
  const float u01 = WrapFinite01(u), v01 = WrapFinite01(v);
  if (!(lod > 0.0f)) return SampleWrapped(u01, v01, 0);  // also catches NaN
  if (lod >= static_cast<float>(last)) return SampleWrapped(u01, v01, last);
  const int l0 = static_cast<int>(lod);
  const float a = lod - static_cast<float>(l0);
  const __m128 c = SampleWrapped(u01, v01, l0);
  if (!(a > 0.0f)) return c;
  return _mm_add_ps(c, _mm_mul_ps(_mm_set1_ps(a), _mm_sub_ps(SampleWrapped(u01, v01, l0 + 1), c)));
}

namespace {

// FloorInt and WrapFinite01 on four lanes, with the scalar versions' exact arithmetic.
inline __m128i FloorInt4(__m128 x) {
  const __m128i i = _mm_cvttps_epi32(x);
  return _mm_add_epi32(i, _mm_castps_si128(_mm_cmplt_ps(x, _mm_cvtepi32_ps(i))));
}

inline __m128 Wrap01x4(__m128 x) {
  const __m128 finite = _mm_cmplt_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), x), _mm_set1_ps(1e9f));
  const __m128 w = _mm_sub_ps(x, _mm_cvtepi32_ps(FloorInt4(x)));
  return _mm_and_ps(_mm_and_ps(w, _mm_cmplt_ps(w, _mm_set1_ps(1.0f))), finite);
}

// Low 32 bits of the lane-wise product (SSE2 has no pmulld).
inline __m128i MulLo32(__m128i a, __m128i b) {
  const __m128i even = _mm_mul_epu32(a, b);
  const __m128i odd = _mm_mul_epu32(_mm_srli_epi64(a, 32), _mm_srli_epi64(b, 32));
  return _mm_unpacklo_epi32(_mm_shuffle_epi32(even, _MM_SHUFFLE(0, 0, 2, 0)),
                            _mm_shuffle_epi32(odd, _MM_SHUFFLE(0, 0, 2, 0)));
}

// a ? b : c per lane (a all-ones or all-zeros).
inline __m128i Select(__m128i a, __m128i b, __m128i c) {
  return _mm_or_si128(_mm_and_si128(a, b), _mm_andnot_si128(a, c));
}

}  // namespace

// Where the bilinear lookups of four lanes read: per lane the level's texels, the four texel
// indices (00, 10, 01, 11) and the weights ax, ay.
struct MipTexture::Footprint4 {
  const uint64_t* texels[4];
  alignas(16) uint32_t index[4][4];  // [corner][lane]
  alignas(16) float ax[4], ay[4];
};

__attribute__((always_inline)) inline void MipTexture::Address4(const Level* const level[4], __m128 u01, __m128 v01,
                                                                Footprint4* fp) {
  // Transpose the lanes' (fwidth, fheight, width, height) into one register per field.
  __m128 fw = _mm_loadu_ps(&level[0]->fwidth), fh = _mm_loadu_ps(&level[1]->fwidth);
  __m128 wf = _mm_loadu_ps(&level[2]->fwidth), hf = _mm_loadu_ps(&level[3]->fwidth);
  _MM_TRANSPOSE4_PS(fw, fh, wf, hf);
  const __m128i w = _mm_castps_si128(wf), h = _mm_castps_si128(hf);
  const __m128i bx = _mm_setr_epi32(level[0]->blocks_x, level[1]->blocks_x, level[2]->blocks_x, level[3]->blocks_x);
  for (int k = 0; k < 4; ++k) fp->texels[k] = level[k]->texels.data();
  const __m128i one = _mm_set1_epi32(1), three = _mm_set1_epi32(3), zero = _mm_setzero_si128();
  const __m128 half = _mm_set1_ps(0.5f);
  // As SampleWrapped: texel centres at (i + 0.5) / width; wrap the lower neighbour to the last texel.
  const __m128 fu = _mm_sub_ps(_mm_mul_ps(u01, fw), half);
  const __m128 fv = _mm_sub_ps(_mm_mul_ps(v01, fh), half);
  __m128i xa = FloorInt4(fu), ya = FloorInt4(fv);
  _mm_store_ps(fp->ax, _mm_sub_ps(fu, _mm_cvtepi32_ps(xa)));
  _mm_store_ps(fp->ay, _mm_sub_ps(fv, _mm_cvtepi32_ps(ya)));
  const __m128i w1 = _mm_sub_epi32(w, one), h1 = _mm_sub_epi32(h, one);
  xa = Select(_mm_cmplt_epi32(xa, zero), w1, xa);
  ya = Select(_mm_cmplt_epi32(ya, zero), h1, ya);
  xa = Select(_mm_cmpgt_epi32(xa, w1), w1, xa);  // rounding guard
  ya = Select(_mm_cmpgt_epi32(ya, h1), h1, ya);
  const __m128i xb = _mm_andnot_si128(_mm_cmpeq_epi32(xa, w1), _mm_add_epi32(xa, one));
  const __m128i yb = _mm_andnot_si128(_mm_cmpeq_epi32(ya, h1), _mm_add_epi32(ya, one));
  // Level::Index: ColumnOffset(x) = (x >> 2) << 4 | (x & 3), RowOffset(y) = (y >> 2) * blocks_x << 4 | (y & 3) << 2.
  auto column = [&](__m128i x) {
    return _mm_or_si128(_mm_slli_epi32(_mm_srli_epi32(x, 2), 4), _mm_and_si128(x, three));
  };
  auto row = [&](__m128i y) {
    return _mm_or_si128(_mm_slli_epi32(MulLo32(_mm_srli_epi32(y, 2), bx), 4),
                        _mm_slli_epi32(_mm_and_si128(y, three), 2));
  };
  const __m128i col_a = column(xa), col_b = column(xb), row_a = row(ya), row_b = row(yb);
  _mm_store_si128(reinterpret_cast<__m128i*>(fp->index[0]), _mm_add_epi32(row_a, col_a));
  _mm_store_si128(reinterpret_cast<__m128i*>(fp->index[1]), _mm_add_epi32(row_a, col_b));
  _mm_store_si128(reinterpret_cast<__m128i*>(fp->index[2]), _mm_add_epi32(row_b, col_a));
  _mm_store_si128(reinterpret_cast<__m128i*>(fp->index[3]), _mm_add_epi32(row_b, col_b));
}

namespace {

// Requests the cache lines of a footprint's texels 00 and 11 (a 4x4 block is two lines, texel rows
// 0-1 and 2-3: the two cover the 2x2 neighbourhood unless it straddles blocks both ways).
inline void Prefetch(const uint64_t* texels, const uint32_t* const index[4], int lane) {
  _mm_prefetch(reinterpret_cast<const char*>(texels + index[0][lane]), _MM_HINT_T0);
  _mm_prefetch(reinterpret_cast<const char*>(texels + index[3][lane]), _MM_HINT_T0);
}

}  // namespace

__attribute__((always_inline)) inline __m128 MipTexture::Filter(const Footprint4& fp, int lane) {
  const uint64_t* texels = fp.texels[lane];
  const __m128i zero = _mm_setzero_si128();
  auto load = [&](int corner) {
    return _mm_cvtepi32_ps(
        _mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(texels + fp.index[corner][lane])), zero));
  };
  const __m128 t00 = load(0), t10 = load(1), t01 = load(2), t11 = load(3);
  const __m128 vax = _mm_set1_ps(fp.ax[lane]), vay = _mm_set1_ps(fp.ay[lane]);
  const __m128 top = _mm_add_ps(t00, _mm_mul_ps(vax, _mm_sub_ps(t10, t00)));
  const __m128 bottom = _mm_add_ps(t01, _mm_mul_ps(vax, _mm_sub_ps(t11, t01)));
  return _mm_mul_ps(_mm_add_ps(top, _mm_mul_ps(vay, _mm_sub_ps(bottom, top))), _mm_set1_ps(1.0f / 65535.0f));
}

namespace {

// As Sample4: level 0 for lod <= 0 or NaN, the last level from lod >= last on, else the two
// levels around lod with weight lod - floor(lod) on the coarser one: the finer level l0, the weight a.
inline void SelectLevels4(__m128 l, __m128i last, bool trilinear, __m128i* l0, __m128* a) {
  if (trilinear) {
    const __m128 positive = _mm_cmpgt_ps(l, _mm_setzero_ps());
    const __m128 inside = _mm_and_ps(positive, _mm_cmplt_ps(l, _mm_cvtepi32_ps(last)));
    const __m128i floor_l = _mm_cvttps_epi32(l);
    *l0 = Select(_mm_castps_si128(inside), floor_l, _mm_and_si128(_mm_castps_si128(positive), last));
    *a = _mm_and_ps(inside, _mm_sub_ps(l, _mm_cvtepi32_ps(floor_l)));
  } else {
    // The nearest level, clamp(int(lod + 1/2), 0, last) (a NaN converts to INT_MIN: level 0).
    *l0 = _mm_cvttps_epi32(_mm_add_ps(l, _mm_set1_ps(0.5f)));
    *l0 = _mm_andnot_si128(_mm_cmplt_epi32(*l0, _mm_setzero_si128()), *l0);
    *l0 = Select(_mm_cmpgt_epi32(*l0, last), last, *l0);
    *a = _mm_setzero_ps();
  }
}

}  // namespace

void MipTexture::SampleBatch(const MipTexture* const* textures, const float* u, const float* v, const float* lod, int n,
                             __m128* out, bool trilinear) {
  // Chunks of up to kChunk lookups: first every address (four lanes at a time) with a prefetch of
  // its texels, then the loads and filters, so that many cache misses overlap.
  constexpr int kChunk = 64;
  Footprint4 fp0[kChunk / 4], fp1[kChunk / 4];
  alignas(16) float blend[kChunk];
  bool any_blend[kChunk / 4];
  for (int c0 = 0; c0 < n; c0 += kChunk) {
    const int chunk = std::min(kChunk, n - c0);
    for (int g = 0; g * 4 < chunk; ++g) {
      // Four lookups (the tail repeats the last one).
      const MipTexture* tex[4];
      __m128 lu, lv, l;
      if (g * 4 + 4 <= chunk) {
        const int k = c0 + g * 4;
        for (int j = 0; j < 4; ++j) tex[j] = textures[k + j];
        lu = _mm_loadu_ps(u + k);
        lv = _mm_loadu_ps(v + k);
        l = _mm_loadu_ps(lod + k);
      } else {
        alignas(16) float tu[4], tv[4], tl[4];
        for (int j = 0; j < 4; ++j) {
          const int k = c0 + std::min(g * 4 + j, chunk - 1);
          tex[j] = textures[k];
          tu[j] = u[k];
          tv[j] = v[k];
          tl[j] = lod[k];
        }
        lu = _mm_load_ps(tu);
        lv = _mm_load_ps(tv);
        l = _mm_load_ps(tl);
      }
      const __m128i last =
          _mm_setr_epi32(tex[0]->last_level_, tex[1]->last_level_, tex[2]->last_level_, tex[3]->last_level_);
      __m128i l0;
      __m128 a;
      SelectLevels4(l, last, trilinear, &l0, &a);
      __m128i l1 = _mm_add_epi32(l0, _mm_set1_epi32(1));
      l1 = Select(_mm_cmpgt_epi32(l1, last), last, l1);
      _mm_store_ps(blend + g * 4, a);
      any_blend[g] = _mm_movemask_ps(_mm_cmpgt_ps(a, _mm_setzero_ps())) != 0;
      alignas(16) int32_t level_index0[4], level_index1[4];
      _mm_store_si128(reinterpret_cast<__m128i*>(level_index0), l0);
      _mm_store_si128(reinterpret_cast<__m128i*>(level_index1), l1);
      const Level* level0[4];
      const Level* level1[4];
      for (int j = 0; j < 4; ++j) {
        level0[j] = tex[j]->levels_.data() + level_index0[j];
        level1[j] = tex[j]->levels_.data() + level_index1[j];
      }
      const __m128 u01 = Wrap01x4(lu), v01 = Wrap01x4(lv);
      const uint32_t* const index0[4] = {fp0[g].index[0], fp0[g].index[1], fp0[g].index[2], fp0[g].index[3]};
      Address4(level0, u01, v01, &fp0[g]);
      for (int j = 0; j < 4; ++j) Prefetch(fp0[g].texels[j], index0, j);
      if (any_blend[g]) {
        const uint32_t* const index1[4] = {fp1[g].index[0], fp1[g].index[1], fp1[g].index[2], fp1[g].index[3]};
        Address4(level1, u01, v01, &fp1[g]);
        for (int j = 0; j < 4; ++j) Prefetch(fp1[g].texels[j], index1, j);
      }
    }
    for (int i = 0; i < chunk; ++i) {
      const int g = i / 4, j = i % 4;
      const __m128 c = Filter(fp0[g], j);
      // As Sample4: c + a (c1 - c) where the level of detail lies strictly between two levels.
      const float a = blend[i];
      out[c0 + i] = a > 0.0f ? _mm_add_ps(c, _mm_mul_ps(_mm_set1_ps(a), _mm_sub_ps(Filter(fp1[g], j), c))) : c;
    }
  }
}

Eigen::Vector3f MipTexture::Sample(float u, float v, float lod) const {
  alignas(16) float out[4];
  _mm_store_ps(out, Sample4(u, v, lod));
  return Eigen::Vector3f(out[0], out[1], out[2]);
}

}  // namespace rovo
