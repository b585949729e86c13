#include "render/texture.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace rovo {
namespace {

Texture Gradient(int width, int height) {
  Texture tex;
  tex.name = "gradient";
  tex.width = width;
  tex.height = height;
  tex.rgb.resize(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      tex.rgb[(y * width + x) * 3 + 0] = static_cast<uint8_t>((x * 37 + y * 11) % 256);
      tex.rgb[(y * width + x) * 3 + 1] = static_cast<uint8_t>((x * 5 + y * 71) % 256);
      tex.rgb[(y * width + x) * 3 + 2] = static_cast<uint8_t>(x == y ? 255 : 0);
    }
  return tex;
}

TEST(SrgbTest, RoundTripsAndKnownValues) {
  EXPECT_NEAR(SrgbToLinear(1.0f), 1.0f, 1e-6f);
  EXPECT_NEAR(SrgbToLinear(0.5f), 0.21404f, 1e-4f);
  for (int i = 0; i <= 255; ++i) {
    const float s = i / 255.0f;
    EXPECT_NEAR(LinearToSrgb(SrgbToLinear(s)), s, 1e-5f) << i;
  }
  EXPECT_EQ(LinearToSrgb(-1.0f), 0.0f);
  EXPECT_NEAR(LinearToSrgb(2.0f), 1.0f, 1e-6f);
}

TEST(MipTextureTest, PyramidSizesAndBoxFilterPreservesMean) {
  const Texture tex = Gradient(16, 8);
  const MipTexture mip(tex);
  ASSERT_EQ(mip.NumLevels(), 5);  // 16x8, 8x4, 4x2, 2x1, 1x1
  EXPECT_EQ(mip.Width(1), 8);
  EXPECT_EQ(mip.Height(1), 4);
  EXPECT_EQ(mip.Width(4), 1);
  EXPECT_EQ(mip.Height(4), 1);
  EXPECT_FLOAT_EQ(mip.TexelsPerUv(), std::sqrt(128.0f));
  // Power-of-two sizes: every level has the same mean as level 0.
  Eigen::Vector3f mean0 = Eigen::Vector3f::Zero();
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) mean0 += mip.Texel(0, x, y);
  mean0 /= 128.0f;
  // Reduced levels are stored as 16-bit linear: the exact mean, well within half an 8-bit code.
  auto srgb_step = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    float worst = 0.0f;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(LinearToSrgb(a[c]) - LinearToSrgb(b[c])) * 255.0f);
    return worst;
  };
  EXPECT_LE(srgb_step(mip.Texel(4, 0, 0), mean0), 0.5f + 1e-3f);
  // One level-1 texel is the mean of its 2x2 parents.
  const Eigen::Vector3f expected =
      0.25f * (mip.Texel(0, 2, 4) + mip.Texel(0, 3, 4) + mip.Texel(0, 2, 5) + mip.Texel(0, 3, 5));
  EXPECT_LE(srgb_step(mip.Texel(1, 1, 2), expected), 0.5f + 1e-3f);
  // Level 2 is the mean of the 4x4 level-0 block (computed from the unrounded level 1).
  Eigen::Vector3f block = Eigen::Vector3f::Zero();
  for (int y = 4; y < 8; ++y)
    for (int x = 8; x < 12; ++x) block += mip.Texel(0, x, y);
  EXPECT_LE(srgb_step(mip.Texel(2, 2, 1), block / 16.0f), 0.5f + 1e-3f);
  // Level 0 holds the decoded sRGB values.
  EXPECT_NEAR(mip.Texel(0, 3, 3).z(), 1.0f, 1e-6f);
  EXPECT_NEAR(mip.Texel(0, 3, 2).z(), 0.0f, 1e-6f);
}

// The stored 16-bit code of a texel channel (Texel returns code / 65535).
long Code(float value) { return std::lround(value * 65535.0f); }

TEST(MipTextureTest, TexelsAreLinearValuesRoundedTo16BitCodes) {
  // Level 0: every 8-bit code, decoded and rounded to 16 bits as lround does; level 1: each texel the float
  // mean of its 2x2 parents, rounded the same way.
  Texture tex;
  tex.name = "codes";
  tex.width = 256;
  tex.height = 2;
  tex.rgb.resize(256 * 2 * 3);
  for (int x = 0; x < 256; ++x)
    for (int c = 0; c < 3; ++c) {
      tex.rgb[x * 3 + c] = static_cast<uint8_t>(x);
      tex.rgb[(256 + x) * 3 + c] = static_cast<uint8_t>(255 - (x * 7 + c * 31) % 256);
    }
  const MipTexture mip(tex);
  auto linear = [&](int x, int y, int c) { return SrgbToLinear(tex.rgb[(y * 256 + x) * 3 + c] / 255.0f); };
  for (int x = 0; x < 256; ++x) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(Code(mip.Texel(0, x, 0)[c]), Code(linear(x, 0, c))) << "code " << x;
      ASSERT_EQ(Code(mip.Texel(0, x, 1)[c]), Code(linear(x, 1, c))) << "column " << x;
    }
  }
  for (int x = 0; x < 128; ++x) {
    for (int c = 0; c < 3; ++c) {
      const float mean =
          0.25f * (linear(2 * x, 0, c) + linear(2 * x + 1, 0, c) + linear(2 * x, 1, c) + linear(2 * x + 1, 1, c));
      ASSERT_EQ(Code(mip.Texel(1, x, 0)[c]), Code(mean)) << "level-1 column " << x;
    }
  }
}

TEST(MipTextureTest, BilinearHitsTexelCentresInterpolatesAndWraps) {
  const MipTexture mip(Gradient(8, 8));
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const float u = (x + 0.5f) / 8.0f, v = (y + 0.5f) / 8.0f;
      EXPECT_LT((mip.SampleLevel(u, v, 0) - mip.Texel(0, x, y)).norm(), 1e-5f);
      // Repeat wrapping: shifted by whole periods (also negative).
      EXPECT_LT((mip.SampleLevel(u + 3.0f, v - 2.0f, 0) - mip.Texel(0, x, y)).norm(), 1e-4f);
    }
  // Half-way between two texel centres: their mean.
  const Eigen::Vector3f mid = mip.SampleLevel(2.0f / 8.0f, 0.5f / 8.0f, 0);
  EXPECT_LT((mid - 0.5f * (mip.Texel(0, 1, 0) + mip.Texel(0, 2, 0))).norm(), 1e-5f);
  // Across the wrap seam: between the last and the first column.
  const Eigen::Vector3f seam = mip.SampleLevel(0.0f, 0.5f / 8.0f, 0);
  EXPECT_LT((seam - 0.5f * (mip.Texel(0, 7, 0) + mip.Texel(0, 0, 0))).norm(), 1e-5f);
}

TEST(MipTextureTest, TrilinearBlendsLevelsAndClamps) {
  const MipTexture mip(Gradient(8, 8));
  const float u = 0.3f, v = 0.6f;
  const Eigen::Vector3f l1 = mip.SampleLevel(u, v, 1), l2 = mip.SampleLevel(u, v, 2);
  EXPECT_LT((mip.Sample(u, v, 1.25f) - (0.75f * l1 + 0.25f * l2)).norm(), 1e-5f);
  EXPECT_LT((mip.Sample(u, v, -3.0f) - mip.SampleLevel(u, v, 0)).norm(), 1e-6f);
  EXPECT_LT((mip.Sample(u, v, 100.0f) - mip.Texel(3, 0, 0)).norm(), 1e-6f);
  EXPECT_LT((mip.Sample(u, v, std::nanf("")) - mip.SampleLevel(u, v, 0)).norm(), 1e-6f);
}

TEST(MipTextureTest, BatchLookupsEqualSingleLookupsBitForBit) {
  // Mixed textures (odd, non-power-of-two, 1x1) and levels in one batch, coordinates outside
  // [0, 1), non-finite values, integer and out-of-range levels of detail; 203 lookups cover
  // several 64-lookup chunks and a partial group of four.
  std::vector<MipTexture> textures;
  textures.emplace_back(Gradient(16, 8));
  textures.emplace_back(Gradient(13, 7));
  textures.emplace_back(Gradient(1, 1));
  textures.emplace_back(Gradient(40, 3));
  const float specials[] = {0.0f, 1.0f, -1.0f, 0.999999f, -0.0f, 2e9f, -3e9f, std::nanf(""), INFINITY, 5.5f};
  const float lods[] = {-1.0f, 0.0f, 1.0f, 2.0f, 0.5f, 1.75f, 3.999f, 7.0f, 100.0f, std::nanf("")};
  constexpr int kN = 203;
  std::vector<const MipTexture*> tex(kN);
  std::vector<float> u(kN), v(kN), lod(kN);
  uint32_t state = 12345;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / 16777216.0f;
  };
  for (int k = 0; k < kN; ++k) {
    tex[k] = &textures[k % 7 % textures.size()];
    u[k] = k % 11 == 0 ? specials[k % 10] : 6.0f * next() - 3.0f;
    v[k] = k % 13 == 0 ? specials[(k / 13) % 10] : 6.0f * next() - 3.0f;
    lod[k] = k % 3 == 0 ? lods[(k / 3) % 10] : 6.0f * next() - 1.0f;
  }
  for (const bool trilinear : {true, false}) {
    __m128 out[kN];
    MipTexture::SampleBatch(tex.data(), u.data(), v.data(), lod.data(), kN, out, trilinear);
    for (int k = 0; k < kN; ++k) {
      alignas(16) float batch[4], single[4];
      _mm_store_ps(batch, out[k]);
      const int nearest = std::isnan(lod[k]) || lod[k] + 0.5f < 0.0f
                              ? 0
                              : std::min(static_cast<int>(std::min(lod[k] + 0.5f, 1e6f)), tex[k]->NumLevels() - 1);
      _mm_store_ps(single, trilinear ? tex[k]->Sample4(u[k], v[k], lod[k]) : tex[k]->SampleLevel4(u[k], v[k], nearest));
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(std::memcmp(&batch[c], &single[c], sizeof(float)), 0)
            << (trilinear ? "trilinear" : "nearest level") << " lookup " << k << " channel " << c << ": " << batch[c]
            << " vs " << single[c] << " (u " << u[k] << ", v " << v[k] << ", lod " << lod[k] << ")";
    }
  }
}

TEST(MipTextureTest, RejectsInconsistentSize) {
  Texture tex = Gradient(4, 4);
  tex.rgb.pop_back();
  try {
    MipTexture mip(tex);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gradient"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rovo
