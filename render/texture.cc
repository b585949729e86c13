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
  base.rgb.resize(texture.rgb.size());
  for (size_t i = 0; i < texture.rgb.size(); ++i) base.rgb[i] = lut[texture.rgb[i]];
  levels_.push_back(std::move(base));
  texels_per_uv_ = std::sqrt(static_cast<float>(texture.width) * static_cast<float>(texture.height));

  // Box-filtered reduction until 1x1.
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const Level& src = levels_.back();
    Level dst;
    dst.width = std::max(1, src.width / 2);
    dst.height = std::max(1, src.height / 2);
    dst.rgb.resize(static_cast<size_t>(dst.width) * dst.height * 3);
    for (int y = 0; y < dst.height; ++y) {
      const int y0 = std::min(2 * y, src.height - 1), y1 = std::min(2 * y + 1, src.height - 1);
      for (int x = 0; x < dst.width; ++x) {
        const int x0 = std::min(2 * x, src.width - 1), x1 = std::min(2 * x + 1, src.width - 1);
        for (int c = 0; c < 3; ++c) {
          const float sum = src.rgb[(static_cast<size_t>(y0) * src.width + x0) * 3 + c] +
                            src.rgb[(static_cast<size_t>(y0) * src.width + x1) * 3 + c] +
                            src.rgb[(static_cast<size_t>(y1) * src.width + x0) * 3 + c] +
                            src.rgb[(static_cast<size_t>(y1) * src.width + x1) * 3 + c];
          dst.rgb[(static_cast<size_t>(y) * dst.width + x) * 3 + c] = 0.25f * sum;
        }
      }
    }
    levels_.push_back(std::move(dst));
  }
}

Eigen::Vector3f MipTexture::Texel(int level, int x, int y) const {
  const Level& l = levels_[level];
  x %= l.width;
  if (x < 0) x += l.width;
  y %= l.height;
  if (y < 0) y += l.height;
  const float* p = &l.rgb[(static_cast<size_t>(y) * l.width + x) * 3];
  return Eigen::Vector3f(p[0], p[1], p[2]);
}

Eigen::Vector3f MipTexture::SampleLevel(float u, float v, int level) const {
  const Level& l = levels_[level];
  // Texel centres sit at (i + 0.5) / width in UV.
  const float fu = u * l.width - 0.5f;
  const float fv = v * l.height - 0.5f;
  const float x0f = std::floor(fu), y0f = std::floor(fv);
  const float ax = fu - x0f, ay = fv - y0f;
  // Wrap once in floating point so that huge UVs do not overflow int.
  const int x0 = static_cast<int>(x0f - l.width * std::floor(x0f / l.width));
  const int y0 = static_cast<int>(y0f - l.height * std::floor(y0f / l.height));
  const int xa = std::min(x0, l.width - 1);
  const int ya = std::min(y0, l.height - 1);
  const int xb = xa + 1 == l.width ? 0 : xa + 1;
  const int yb = ya + 1 == l.height ? 0 : ya + 1;
  const float* r0 = &l.rgb[static_cast<size_t>(ya) * l.width * 3];
  const float* r1 = &l.rgb[static_cast<size_t>(yb) * l.width * 3];
  Eigen::Vector3f out;
  for (int c = 0; c < 3; ++c) {
    const float top = r0[xa * 3 + c] + ax * (r0[xb * 3 + c] - r0[xa * 3 + c]);
    const float bottom = r1[xa * 3 + c] + ax * (r1[xb * 3 + c] - r1[xa * 3 + c]);
    out[c] = top + ay * (bottom - top);
  }
  return out;
}

Eigen::Vector3f MipTexture::Sample(float u, float v, float lod) const {
  if (!(lod > 0.0f)) return SampleLevel(u, v, 0);  // also catches NaN
  const int last = NumLevels() - 1;
  if (lod >= static_cast<float>(last)) return SampleLevel(u, v, last);
  const int l0 = static_cast<int>(lod);
  const float a = lod - static_cast<float>(l0);
  const Eigen::Vector3f c0 = SampleLevel(u, v, l0);
  if (a <= 0.0f) return c0;
  return c0 + a * (SampleLevel(u, v, l0 + 1) - c0);
}

}  // namespace rovo
