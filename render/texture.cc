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
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = SrgbToLinear(i / 255.0f);

  Level base;
  base.width = texture.width;
  base.height = texture.height;
  const size_t n = static_cast<size_t>(texture.width) * texture.height;
  base.rgba.resize(n * 4);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) base.rgba[4 * i + c] = lut[texture.rgb[3 * i + c]];
    base.rgba[4 * i + 3] = 1.0f;
  }
  levels_.push_back(std::move(base));
  texels_per_uv_ = std::sqrt(static_cast<float>(texture.width) * static_cast<float>(texture.height));

  // Box-filtered reduction until 1x1.
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const Level& src = levels_.back();
    Level dst;
    dst.width = std::max(1, src.width / 2);
    dst.height = std::max(1, src.height / 2);
    dst.rgba.resize(static_cast<size_t>(dst.width) * dst.height * 4);
    for (int y = 0; y < dst.height; ++y) {
      const int y0 = std::min(2 * y, src.height - 1), y1 = std::min(2 * y + 1, src.height - 1);
      for (int x = 0; x < dst.width; ++x) {
        const int x0 = std::min(2 * x, src.width - 1), x1 = std::min(2 * x + 1, src.width - 1);
        for (int c = 0; c < 4; ++c) {
          const float sum = src.rgba[(static_cast<size_t>(y0) * src.width + x0) * 4 + c] +
                            src.rgba[(static_cast<size_t>(y0) * src.width + x1) * 4 + c] +
                            src.rgba[(static_cast<size_t>(y1) * src.width + x0) * 4 + c] +
                            src.rgba[(static_cast<size_t>(y1) * src.width + x1) * 4 + c];
          dst.rgba[(static_cast<size_t>(y) * dst.width + x) * 4 + c] = 0.25f * sum;
        }
      }
    }
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
  const float* p = &l.rgba[(static_cast<size_t>(y) * l.width + x) * 4];
  return Eigen::Vector3f(p[0], p[1], p[2]);
}

namespace {

// Wraps a texel index into [0, size).
inline int WrapIndex(float index, int size, float fsize) {
  if (std::abs(index) < 1e9f) {
    if ((size & (size - 1)) == 0) return static_cast<int>(index) & (size - 1);  // power of two
    int i = static_cast<int>(index) % size;
    return i < 0 ? i + size : i;
  }
  return std::min(size - 1, std::max(0, static_cast<int>(index - fsize * std::floor(index / fsize))));
}

}  // namespace

__m128 MipTexture::SampleLevel4(float u, float v, int level) const {
  const Level& l = levels_[level];
  // Texel centres sit at (i + 0.5) / width in UV.
  const float fu = u * l.fwidth - 0.5f;
  const float fv = v * l.fheight - 0.5f;
  const float x0f = std::floor(fu), y0f = std::floor(fv);
  const int xa = WrapIndex(x0f, l.width, l.fwidth);
  const int ya = WrapIndex(y0f, l.height, l.fheight);
  const int xb = xa + 1 == l.width ? 0 : xa + 1;
  const int yb = ya + 1 == l.height ? 0 : ya + 1;
  const float* r0 = &l.rgba[static_cast<size_t>(ya) * l.width * 4];
  const float* r1 = &l.rgba[static_cast<size_t>(yb) * l.width * 4];
  const __m128 ax = _mm_set1_ps(fu - x0f), ay = _mm_set1_ps(fv - y0f);
  const __m128 t00 = _mm_loadu_ps(r0 + 4 * xa), t10 = _mm_loadu_ps(r0 + 4 * xb);
  const __m128 t01 = _mm_loadu_ps(r1 + 4 * xa), t11 = _mm_loadu_ps(r1 + 4 * xb);
  const __m128 top = _mm_add_ps(t00, _mm_mul_ps(ax, _mm_sub_ps(t10, t00)));
  const __m128 bottom = _mm_add_ps(t01, _mm_mul_ps(ax, _mm_sub_ps(t11, t01)));
  return _mm_add_ps(top, _mm_mul_ps(ay, _mm_sub_ps(bottom, top)));
}

Eigen::Vector3f MipTexture::SampleLevel(float u, float v, int level) const {
  alignas(16) float out[4];
  _mm_store_ps(out, SampleLevel4(u, v, level));
  return Eigen::Vector3f(out[0], out[1], out[2]);
}

Eigen::Vector3f MipTexture::Sample(float u, float v, float lod) const {
  const int last = NumLevels() - 1;
  __m128 c;
  if (!(lod > 0.0f)) {  // also catches NaN
    c = SampleLevel4(u, v, 0);
  } else if (lod >= static_cast<float>(last)) {
    c = SampleLevel4(u, v, last);
  } else {
    const int l0 = static_cast<int>(lod);
    const float a = lod - static_cast<float>(l0);
    c = SampleLevel4(u, v, l0);
    if (a > 0.0f) c = _mm_add_ps(c, _mm_mul_ps(_mm_set1_ps(a), _mm_sub_ps(SampleLevel4(u, v, l0 + 1), c)));
  }
  alignas(16) float out[4];
  _mm_store_ps(out, c);
  return Eigen::Vector3f(out[0], out[1], out[2]);
}

}  // namespace rovo
