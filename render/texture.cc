#include "render/texture.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rovo {

float SrgbToLinear(float srgb) {
  return srgb <= 0.04045f ? srgb / 12.92f : std::pow((srgb + 0.055f) / 1.055f, 2.4f);
}

float LinearToSrgb(float linear) {
  linear = std::clamp(linear, 0.0f, 1.0f);
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

MipTexture::MipTexture(const Texture& texture) {
  if (texture.width <= 0 || texture.height <= 0 ||
      texture.rgb.size() != static_cast<size_t>(texture.width) * texture.height * 3) {
    throw std::invalid_argument("texture '" + texture.name + "': size " + std::to_string(texture.width) + "x" +
                                std::to_string(texture.height) + " does not match its " +
                                std::to_string(texture.rgb.size()) + " bytes of RGB data");
  }
  float to_linear[256];
  for (int i = 0; i < 256; ++i) to_linear[i] = SrgbToLinear(i / 255.0f);
  auto pack = [](float r, float g, float b) -> uint64_t {
    auto q = [](float x) { return static_cast<uint64_t>(std::lround(std::clamp(x, 0.0f, 1.0f) * 65535.0f)); };
    return q(r) | (q(g) << 16) | (q(b) << 32);
  };

  Level base;
  base.Allocate(texture.width, texture.height);
  const size_t n = static_cast<size_t>(texture.width) * texture.height;
  // Working copy of the current level in linear float (reduced levels are averaged from it).
  std::vector<float> linear(n * 3);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) linear[3 * i + c] = to_linear[texture.rgb[3 * i + c]];
    base.texels[base.Index(static_cast<int>(i % texture.width), static_cast<int>(i / texture.width))] =
        pack(linear[3 * i], linear[3 * i + 1], linear[3 * i + 2]);
  }
  levels_.push_back(std::move(base));
  texels_per_uv_ = std::sqrt(static_cast<float>(texture.width) * static_cast<float>(texture.height));

  // Box-filtered reduction until 1x1.
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const int sw = levels_.back().width, sh = levels_.back().height;
    Level dst;
    dst.Allocate(std::max(1, sw / 2), std::max(1, sh / 2));
    std::vector<float> next(static_cast<size_t>(dst.width) * dst.height * 3);
    for (int y = 0; y < dst.height; ++y) {
      const int y0 = std::min(2 * y, sh - 1), y1 = std::min(2 * y + 1, sh - 1);
      for (int x = 0; x < dst.width; ++x) {
        const int x0 = std::min(2 * x, sw - 1), x1 = std::min(2 * x + 1, sw - 1);
        const size_t o = static_cast<size_t>(y) * dst.width + x;
        for (int c = 0; c < 3; ++c) {
          const float sum = linear[(static_cast<size_t>(y0) * sw + x0) * 3 + c] +
                            linear[(static_cast<size_t>(y0) * sw + x1) * 3 + c] +
                            linear[(static_cast<size_t>(y1) * sw + x0) * 3 + c] +
                            linear[(static_cast<size_t>(y1) * sw + x1) * 3 + c];
          next[o * 3 + c] = 0.25f * sum;
        }
        dst.texels[dst.Index(x, y)] = pack(next[o * 3], next[o * 3 + 1], next[o * 3 + 2]);
      }
    }
    linear.swap(next);
    levels_.push_back(std::move(dst));
  }
  for (Level& l : levels_) {
    l.fwidth = static_cast<float>(l.width);
    l.fheight = static_cast<float>(l.height);
  }
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
inline float Wrap01(float x) {
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
  const uint64_t* texels = l.texels.data();
  const __m128i zero = _mm_setzero_si128();
  auto load = [&](size_t i) {
    return _mm_cvtepi32_ps(_mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(texels + i)), zero));
  };
  const __m128 t00 = load(l.Index(xa, ya)), t10 = load(l.Index(xb, ya));
  const __m128 t01 = load(l.Index(xa, yb)), t11 = load(l.Index(xb, yb));
  const __m128 vax = _mm_set1_ps(ax), vay = _mm_set1_ps(ay);
  const __m128 top = _mm_add_ps(t00, _mm_mul_ps(vax, _mm_sub_ps(t10, t00)));
  const __m128 bottom = _mm_add_ps(t01, _mm_mul_ps(vax, _mm_sub_ps(t11, t01)));
  return _mm_mul_ps(_mm_add_ps(top, _mm_mul_ps(vay, _mm_sub_ps(bottom, top))), _mm_set1_ps(1.0f / 65535.0f));
}

__m128 MipTexture::SampleLevel4(float u, float v, int level) const {
  return SampleWrapped(Wrap01(u), Wrap01(v), level);
}

Eigen::Vector3f MipTexture::SampleLevel(float u, float v, int level) const {
  alignas(16) float out[4];
  _mm_store_ps(out, SampleLevel4(u, v, level));
  return Eigen::Vector3f(out[0], out[1], out[2]);
}

Eigen::Vector3f MipTexture::Sample(float u, float v, float lod) const {
  const int last = NumLevels() - 1;
  const float u01 = Wrap01(u), v01 = Wrap01(v);
  __m128 c;
  if (!(lod > 0.0f)) {  // also catches NaN
    c = SampleWrapped(u01, v01, 0);
  } else if (lod >= static_cast<float>(last)) {
    c = SampleWrapped(u01, v01, last);
  } else {
    const int l0 = static_cast<int>(lod);
    const float a = lod - static_cast<float>(l0);
    c = SampleWrapped(u01, v01, l0);
    if (a > 0.0f) c = _mm_add_ps(c, _mm_mul_ps(_mm_set1_ps(a), _mm_sub_ps(SampleWrapped(u01, v01, l0 + 1), c)));
  }
  alignas(16) float out[4];
  _mm_store_ps(out, c);
  return Eigen::Vector3f(out[0], out[1], out[2]);
}

}  // namespace rovo
