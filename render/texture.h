#pragma once
// Mip-mapped base-colour textures for the tracer.
//
// The 8-bit sRGB texels of a scenes/ Texture are decoded once to linear float RGB and reduced into
// a box-filtered pyramid (level k+1 texel = mean of the 2x2 level-k texels; odd sizes clamp the
// last row/column). Lookups are bilinear within a level and linear between the two levels around
// a fractional level of detail (trilinear filtering):
//   lod = log2(footprint_in_texels),  footprint_in_texels = footprint_m * texels_per_m,
// where the caller estimates footprint_m from the ray cone (distance * pixel angle / cos) and
// texels_per_m from the triangle's UV-to-world area ratio. Texture coordinates wrap (repeat);
// v = 0 is the top row of the image file.

#include "scenes/scene.h"

#include <Eigen/Core>

#include <vector>

#include <xmmintrin.h>

namespace rovo {

class MipTexture {
 public:
  MipTexture() = default;
  // Throws std::invalid_argument naming the texture when its size and pixel buffer disagree.
  explicit MipTexture(const Texture& texture);

  int NumLevels() const { return static_cast<int>(levels_.size()); }
  int Width(int level = 0) const { return levels_[level].width; }
  int Height(int level = 0) const { return levels_[level].height; }
  // sqrt(width * height) of level 0: texels per unit of UV along one axis (geometric mean).
  float TexelsPerUv() const { return texels_per_uv_; }

  // Linear RGB at (u, v) with trilinear filtering at level of detail `lod` (clamped to the pyramid).
  Eigen::Vector3f Sample(float u, float v, float lod) const;
  // Bilinear lookup in one level.
  Eigen::Vector3f SampleLevel(float u, float v, int level) const;
  // Texel of one level (wrapped coordinates), linear RGB.
  Eigen::Vector3f Texel(int level, int x, int y) const;
  // Bilinear lookup as an SSE register (r, g, b, 1).
  __m128 SampleLevel4(float u, float v, int level) const;

 private:
  struct Level {
    int width = 0;
    int height = 0;
    float fwidth = 0.0f, fheight = 0.0f;
    std::vector<float> rgba;  // linear, 4 floats per texel (alpha unused, for SSE loads), row-major
  };
  std::vector<Level> levels_;
  float texels_per_uv_ = 1.0f;
};

// sRGB transfer functions (IEC 61966-2-1), on [0, 1].
float SrgbToLinear(float srgb);
float LinearToSrgb(float linear);

}  // namespace rovo
