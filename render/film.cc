// The film: the image buffers, and the resolve of a tile (box filter, exposure, vignetting,
// sRGB encoding, or the linear radiance for the sensor model).
#include <emmintrin.h>

#include <algorithm>

#include "render/tracer_internal.h"

namespace rovo {
namespace tracer_internal {

namespace {

// 65536-entry table linear [0, 1] -> 8-bit sRGB (rounded).
const std::array<uint8_t, 65536>& SrgbTable() {
  static const std::array<uint8_t, 65536> table = [] {
    std::array<uint8_t, 65536> t{};
    for (int i = 0; i < 65536; ++i) {
      t[i] = static_cast<uint8_t>(std::lround(LinearToSrgb(i / 65535.0f) * 255.0f));
    }
    return t;
  }();
  return table;
}

// Optional vignetting: 1 - vignetting * (theta / theta_max)^2 at pixel pi, at least 0.
float VignettingGain(const RenderJob& job, size_t pi) {
  const Eigen::Vector3f& b = job.rays.bearing[pi];
  const float theta = std::atan2(std::hypot(b.x(), b.y()), b.z());
  const float rel = theta / job.theta_max;
  return std::max(0.0f, 1.0f - job.settings.vignetting * rel * rel);
}

// The linear resolve (ShadeSettings::linear_output): box filter times the vignetting gain, no
// exposure, no clamp; pixels without samples are 0.
void ResolveTileLinear(const RenderJob& job, const TileRect& t, const TileBuffers& tb) {
  for (int ly = 0; ly < t.th; ++ly) {
    const size_t row = static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0;
    for (int lx = 0; lx < t.tw; ++lx) {
      const int local = ly * kTile + lx;
      float* out = job.image->linear.data() + (row + lx) * 3;
      if (tb.count[local] == 0) {
        out[0] = out[1] = out[2] = 0.0f;
        continue;
      }
      float gain = 1.0f / static_cast<float>(tb.count[local]);
      if (job.settings.vignetting > 0.0f) gain *= VignettingGain(job, row + lx);
      alignas(16) float c[4];
      _mm_store_ps(c, _mm_mul_ps(tb.sum[local], _mm_set1_ps(gain)));
      out[0] = c[0];
      out[1] = c[1];
      out[2] = c[2];
    }
  }
}

}  // namespace

void PrepareImage(const ShadeSettings& settings, int width, int height, CameraImage* image) {
  const size_t num_pixels = static_cast<size_t>(width) * height;
  image->width = width;
  image->height = height;
  // The resolve writes every pixel (black outside the image circle): no clearing needed.
  if (settings.linear_output) {
    if (image->linear.size() != num_pixels * 3) image->linear.assign(num_pixels * 3, 0.0f);
    image->rgb.clear();
  } else {
    if (image->rgb.size() != num_pixels * 3) image->rgb.assign(num_pixels * 3, 0);
    image->linear.clear();
  }
  image->gray.clear();
  if (settings.want_depth)
    image->depth.assign(num_pixels, 0.0f);
  else
    image->depth.clear();
  if (settings.want_mask)
    image->mask.assign(num_pixels, 0);
  else
    image->mask.clear();
}

// Resolve: box filter, exposure, optional vignetting, sRGB. The encoding clamps to [0, 1]
// (NaN -> 0) and reads the 64k table at round(65535 x).
void ResolveTile(const RenderJob& job, const TileRect& t, const TileBuffers& tb) {
  const ShadeSettings& settings = job.settings;
  if (settings.linear_output) {
    ResolveTileLinear(job, t, tb);
    return;
  }
  const auto& srgb = SrgbTable();
  const __m128 one = _mm_set1_ps(1.0f), scale = _mm_set1_ps(65535.0f), half = _mm_set1_ps(0.5f);
  for (int ly = 0; ly < t.th; ++ly) {
    uint8_t* out = job.image->rgb.data() + (static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0) * 3;
    for (int lx = 0; lx < t.tw; ++lx, out += 3) {
      const int local = ly * kTile + lx;
      if (tb.count[local] == 0) {
        out[0] = out[1] = out[2] = 0;
        continue;
      }
      const size_t pi = static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0 + lx;
      float gain = job.exposure_over_count[tb.count[local]];
      if (settings.vignetting > 0.0f) gain *= VignettingGain(job, pi);
      const __m128 c = _mm_min_ps(_mm_max_ps(_mm_mul_ps(tb.sum[local], _mm_set1_ps(gain)), _mm_setzero_ps()), one);
      const __m128i i4 = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(c, scale), half));
      const int index[3] = {_mm_cvtsi128_si32(i4), _mm_cvtsi128_si32(_mm_shuffle_epi32(i4, 1)),
                            _mm_cvtsi128_si32(_mm_shuffle_epi32(i4, 2))};
      for (int k = 0; k < 3; ++k) out[k] = srgb[index[k]];
    }
  }
}

}  // namespace tracer_internal

}  // namespace rovo
