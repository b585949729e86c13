#pragma once
// Mip-mapped base-colour textures for the tracer.
//
// The 8-bit sRGB texels of a scenes/ Texture are decoded to linear float RGB and reduced into a
// box-filtered pyramid in float (level k+1 texel = mean of the 2x2 level-k texels; odd sizes clamp
// the last row/column). Every level is stored as 16-bit linear RGBA (8 bytes per texel, 1/65535
// steps: finer than 8-bit sRGB everywhere) in 4x4-texel blocks, so a bilinear 2x2 usually falls
// inside one block; lookups are four 8-byte loads widened and blended in SSE registers (half the
// memory of float texels, no per-lookup table decode). Lookups are bilinear within a level and
// linear between the two levels around a fractional level of detail (trilinear filtering):
//   lod = log2(footprint_in_texels),  footprint_in_texels = footprint_m * texels_per_m,
// where the caller estimates footprint_m from the ray cone (distance * pixel angle / cos) and
// texels_per_m from the triangle's UV-to-world area ratio. Texture coordinates wrap (repeat);
// v = 0 is the top row of the image file.

#include <emmintrin.h>
#include <xmmintrin.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scenes/scene.h"

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
  // Batch of Sample4 lookups, out[k] = textures[k]->Sample4(u[k], v[k], lod[k]) for k < n, bit for
  // bit; with trilinear = false instead SampleLevel4(u[k], v[k], clamp(int(lod[k] + 1/2), 0, last))
  // (bilinear on the nearest level). Four lookups at a time share SSE registers for the level
  // choice and the texel addresses (each may use its own texture and level); all addresses of up
  // to 64 lookups are computed, and their texels prefetched, before the first texel is read.
  static void SampleBatch(const MipTexture* const* textures, const float* u, const float* v, const float* lod, int n,
                          __m128* out, bool trilinear = true);
  // Bilinear lookup in one level.
  Eigen::Vector3f SampleLevel(float u, float v, int level) const;
  // Texel of one level (wrapped coordinates), linear RGB.
  Eigen::Vector3f Texel(int level, int x, int y) const;
  // Sample() as an SSE register (r, g, b, 0).
  __m128 Sample4(float u, float v, float lod) const;
  // Bilinear lookup as an SSE register (r, g, b, 0).
  __m128 SampleLevel4(float u, float v, int level) const;

 private:
  // The first 16 bytes (fwidth, fheight, width, height) load as one SSE register (Address4).
  struct alignas(16) Level {
    float fwidth = 0.0f, fheight = 0.0f;
    int32_t width = 0;
    int32_t height = 0;
    int32_t blocks_x = 0;          // ceil(width / 4)
    std::vector<uint64_t> texels;  // linear r, g, b, 0 as uint16 (x 1/65535), in 4x4-texel blocks
    // Texel (x, y) lives at Index(x, y): blocks row-major, texels row-major inside a block.
    size_t Index(int x, int y) const { return RowOffset(y) + ColumnOffset(x); }
    size_t RowOffset(int y) const {
      return ((static_cast<size_t>(y >> 2) * blocks_x) << 4) | static_cast<size_t>((y & 3) << 2);
    }
    static size_t ColumnOffset(int x) { return (static_cast<size_t>(x >> 2) << 4) | static_cast<size_t>(x & 3); }
    void Allocate(int w, int h) {
      width = w;
      height = h;
      blocks_x = (w + 3) / 4;
      texels.assign(static_cast<size_t>(blocks_x) * ((h + 3) / 4) * 16, 0ull);
    }
  };
  // Bilinear lookups in four levels (one per lane) at coordinates already wrapped into [0, 1):
  // Address4 finds the texels and weights, Filter reads and blends one lane's.
  struct Footprint4;
  static void Address4(const Level* const level[4], __m128 u01, __m128 v01, Footprint4* fp);
  static __m128 Filter(const Footprint4& fp, int lane);
  // Bilinear lookup in one level at coordinates already wrapped into [0, 1).
  __m128 SampleWrapped(float u01, float v01, int level) const;

  std::vector<Level> levels_;
  int last_level_ = 0;  // NumLevels() - 1
  float texels_per_uv_ = 1.0f;
};

// sRGB transfer functions (IEC 61966-2-1), on [0, 1].
float SrgbToLinear(float srgb);
float LinearToSrgb(float linear);

}  // namespace rovo
