// Street surface textures: road segments, intersections, sidewalk slabs, concrete and the ground
// beyond the city.

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "scenes/texture_draw.h"
#include "scenes/texture_gen.h"

namespace rovo {

using namespace texture_internal;  // the drawing primitives

Texture MakeRoadTexture(uint64_t seed, int index, double road_width_m, double parking_lane_m) {
  SceneRng rng(SubSeed(seed, "road", static_cast<uint64_t>(index)));
  const int N = 1024;  // x along the road (u), y across (v); square tile of road_width_m
  const float ppm = static_cast<float>(N / road_width_m);
  const float tone = static_cast<float>(rng.Uniform(0.28, 0.36));
  Canvas c(N, N, Gray(tone));
  const uint64_t nseed = rng.Next();
  const NoiseField large_noise(N, N, 4, 3, nseed), mid_noise(N, N, 64, 3, nseed + 1);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const float large = large_noise(x, y);
      const float mid = mid_noise(x, y);
      const float speck = Hash01(x, y, nseed + 2);
      float v = tone * (0.8f + 0.3f * large + 0.25f * (mid - 0.5f)) * (0.82f + 0.36f * speck);
      if (Hash01(x / 2, y / 2, nseed + 3) > 0.985f) v = std::min(0.8f, v * 1.9f);  // aggregate stones
      c.At(x, y) = Color(v, v * 1.0f, v * 1.03f);
    }
  // Repair patches with sharp edges.
  for (int k = 0; k < rng.UniformInt(1, 4); ++k) {
    const int px = rng.UniformInt(0, N), py = rng.UniformInt(N / 8, N * 7 / 8);
    const int pw = rng.UniformInt(60, 300), ph = rng.UniformInt(40, 200);
    c.Scale(px, py, px + pw, py + ph, static_cast<float>(rng.Uniform(0.7, 0.85)));
    c.Frame(px, py, px + pw, py + ph, 2, Gray(tone * 0.5f));
  }
  for (int k = 0; k < rng.UniformInt(6, 14); ++k) {
    Crack(c, rng, static_cast<float>(rng.Uniform(0, N)), static_cast<float>(rng.Uniform(0, N)), rng.UniformInt(20, 80),
          4.0f, Gray(tone * 0.35f));
  }
  for (int k = 0; k < rng.UniformInt(2, 6); ++k) {  // oil stains
    const float cx = static_cast<float>(rng.Uniform(0, N)), cy = static_cast<float>(rng.Uniform(0, N));
    for (int d = 0; d < 5; ++d)
      c.Disc(cx + static_cast<float>(rng.Normal(0, 10)), cy + static_cast<float>(rng.Normal(0, 10)),
             static_cast<float>(rng.Uniform(4, 16)), Gray(tone * 0.45f), 0.35f);
  }
  // Gutters (concrete bands at the curbs).
  const int gutter = static_cast<int>(0.3f * ppm);
  for (int band = 0; band < 2; ++band) {
    const int y0 = band == 0 ? 0 : N - gutter;
    for (int y = y0; y < y0 + gutter; ++y)
      for (int x = 0; x < N; ++x) c.At(x, y) = Gray(0.55f * (0.85f + 0.3f * Hash01(x, y, nseed + 9)));
    for (int x = 0; x < N; x += static_cast<int>(N / 4)) c.Rect(x, y0, x + 2, y0 + gutter, Gray(0.3f));
  }
  // Paint with wear: a noise mask removes some of it.
  const NoiseField wear_noise(N, N, 128, 2, nseed + 4);
  auto paint = [&](int x0, int y0, int x1, int y1, const Color& color) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const float wear = wear_noise(static_cast<int>(Mod(x, N)), static_cast<int>(Mod(y, N)));
        if (wear > 0.3f) {
          Color& p = c.At(x, y);
          p = p + 0.9f * (color - p);
        }
      }
  };
  const Color white = Gray(0.92f);
  const int line_w = static_cast<int>(0.12f * ppm);
  const int centre = N / 2;
  const int dash = static_cast<int>(N * 0.3), period = N / 2;  // two dashes per tile, 60% painted
  for (int d = 0; d < 2; ++d) paint(d * period, centre - line_w / 2, d * period + dash, centre + line_w / 2 + 1, white);
  if (parking_lane_m > 0) {
    const int off = static_cast<int>(parking_lane_m * ppm);
    paint(0, off - line_w / 2, N, off + line_w / 2 + 1, white);
    paint(0, N - off - line_w / 2, N, N - off + line_w / 2 + 1, white);
  }
  // Manhole cover in some tiles.
  if (rng.Bernoulli(0.5)) {
    const float mx = static_cast<float>(rng.Uniform(0, N)), my = static_cast<float>(N * rng.Uniform(0.2, 0.4));
    c.Disc(mx, my, 0.32f * ppm, Gray(0.2f), 1.0f);
    c.Disc(mx, my, 0.28f * ppm, Gray(0.32f), 1.0f);
    for (int k = -3; k <= 3; ++k)
      c.Rect(static_cast<int>(mx - 0.25f * ppm), static_cast<int>(my + k * 0.07f * ppm),
             static_cast<int>(mx + 0.25f * ppm), static_cast<int>(my + k * 0.07f * ppm) + 3, Gray(0.18f));
  }
  return c.ToTexture("road_" + std::to_string(index));
}

Texture MakeIntersectionTexture(uint64_t seed, double road_width_m) {
  SceneRng rng(SubSeed(seed, "intersection"));
  const int N = 1024;
  const float ppm = static_cast<float>(N / road_width_m);
  const float tone = 0.3f;
  Canvas c(N, N, Gray(tone));
  const uint64_t nseed = rng.Next();
  const NoiseField large_noise(N, N, 4, 3, nseed), wear_noise(N, N, 128, 2, nseed + 5);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const float v = tone * (0.8f + 0.3f * large_noise(x, y)) * (0.82f + 0.36f * Hash01(x, y, nseed + 2));
      c.At(x, y) = Gray(v);
    }
  for (int k = 0; k < 10; ++k) {
    Crack(c, rng, static_cast<float>(rng.Uniform(0, N)), static_cast<float>(rng.Uniform(0, N)), rng.UniformInt(20, 60),
          4.0f, Gray(0.1f));
  }
  // Zebra crossings: 0.5 m stripes, 0.5 m gaps, 2.5 m long, inside a 3 m band on each edge.
  const int band = static_cast<int>(3.0f * ppm), stripe = static_cast<int>(0.5f * ppm),
            len = static_cast<int>(2.5f * ppm);
  const int inset = static_cast<int>(0.25f * ppm);
  for (int p = band; p + stripe <= N - band; p += 2 * stripe) {
    for (int y = inset; y < inset + len; ++y)
      for (int x = p; x < p + stripe; ++x) {
        if (wear_noise(x, y) < 0.28f) continue;
        c.At(x, y) = Gray(0.9f);
        c.At(x, N - 1 - y) = Gray(0.9f);
        c.At(y, x) = Gray(0.9f);
        c.At(N - 1 - y, x) = Gray(0.9f);
      }
  }
  return c.ToTexture("intersection");
}

Texture MakeSidewalkTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "sidewalk"));
  const int N = 1024, slab = N / 16;  // 0.5 m slabs
  Canvas c(N, N, Gray(0.6f));
  const uint64_t nseed = rng.Next();
  const NoiseField noise(N, N, 32, 3, nseed + 2);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const int sx = x / slab, sy = y / slab;
      const float tone = 0.5f + 0.2f * Hash01(sx, sy, nseed);
      const float grain = 0.85f + 0.3f * Hash01(x, y, nseed + 1);
      const float n = 0.9f + 0.2f * noise(x, y);
      Color col = Gray(tone * grain * n);
      col.x() *= 1.02f;
      if (x % slab < 2 || y % slab < 2) col = Gray(0.25f);
      c.At(x, y) = col;
    }
  for (int k = 0; k < 8; ++k) {
    const int sx = rng.UniformInt(0, 15) * slab, sy = rng.UniformInt(0, 15) * slab;
    c.Line(static_cast<float>(sx + rng.UniformInt(2, slab)), static_cast<float>(sy + 2),
           static_cast<float>(sx + rng.UniformInt(2, slab)), static_cast<float>(sy + slab - 1), 0.8f, Gray(0.2f), 0.8f);
  }
  for (int k = 0; k < 120; ++k) {  // chewing gum, stains
    c.Disc(static_cast<float>(rng.Uniform(0, N)), static_cast<float>(rng.Uniform(0, N)),
           static_cast<float>(rng.Uniform(1.5, 4)), Gray(static_cast<float>(rng.Uniform(0.15, 0.4))), 0.8f);
  }
  return c.ToTexture("sidewalk");
}

Texture MakeConcreteTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "concrete"));
  const int N = 512;
  Canvas c(N, N, Gray(0.6f));
  const uint64_t nseed = rng.Next();
  const NoiseField noise(N, N, 8, 5, nseed);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const float v = 0.55f * (0.8f + 0.3f * noise(x, y)) * (0.85f + 0.3f * Hash01(x, y, nseed + 1));
      c.At(x, y) = Gray(v);
    }
  for (int k = 0; k < 6; ++k)
    Crack(c, rng, static_cast<float>(rng.Uniform(0, N)), static_cast<float>(rng.Uniform(0, N)), 30, 3.0f, Gray(0.25f));
  return c.ToTexture("concrete");
}

Texture MakeGroundTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "ground"));
  const int N = 512;
  Canvas c(N, N, Gray(0.5f));
  const uint64_t nseed = rng.Next();
  const NoiseField noise(N, N, 4, 4, nseed);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const float dirt = noise(x, y);
      const float blade = Hash01(x, y, nseed + 1);
      const Color grass(0.25f, 0.42f, 0.16f), soil(0.42f, 0.34f, 0.24f);
      const float m = std::clamp((dirt - 0.45f) * 4.0f, 0.0f, 1.0f);
      c.At(x, y) = (grass + m * (soil - grass)) * (0.75f + 0.5f * blade);
    }
  return c.ToTexture("ground");
}

}  // namespace rovo
