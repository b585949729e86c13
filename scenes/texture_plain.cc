// The harder worlds' plain, low-contrast surfaces: house walls, lawns, painted walls, polished
// floors, ceiling tiles and posters.

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "scenes/texture_draw.h"
#include "scenes/texture_gen.h"

namespace rovo {

using namespace texture_internal;  // the drawing primitives

// Smooth surface: base colour times (1 + large * (fbm - 0.5) * 2 + grain * (hash - 0.5)).
namespace {

Texture PlainTexture(const std::string& name, int n, const Color& base, float large, float grain, int cells,
                     uint64_t seed) {
  Canvas c(n, n, base);
  AddGrime(c, seed, large, grain, cells);
  return c.ToTexture(name);
}

}  // namespace

Texture MakeHouseWallTexture(uint64_t seed, int index) {
  SceneRng rng(SubSeed(seed, "house_wall", static_cast<uint64_t>(index)));
  const float v = static_cast<float>(rng.Uniform(0.82, 0.92));
  return PlainTexture("house_wall_" + std::to_string(index), 512, Gray(v), 0.035f, 0.03f, 4, rng.Next());
}

Texture MakeLawnTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "lawn"));
  return PlainTexture("lawn", 512, Color(0.3f, 0.46f, 0.2f), 0.06f, 0.05f, 3, rng.Next());
}

Texture MakeWallPaintTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "wall_paint"));
  return PlainTexture("wall_paint", 512, Gray(0.9f), 0.02f, 0.02f, 3, rng.Next());
}

Texture MakePolishedFloorTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "polished_floor"));
  const int N = 1024, slab = N / 4;  // 1.2 m slabs, about 4.7 mm per texel
  Canvas c(N, N, Gray(0.72f));
  const uint64_t nseed = rng.Next();
  const NoiseField veins(N, N, 6, 5, nseed);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      // Soft veins where the noise crosses 0.5, per-slab shade.
      const float v = veins(x, y);
      const float vein = std::exp(-std::pow((v - 0.5f) * 30.0f, 2.0f));
      const float shade = 0.95f + 0.1f * Hash01(x / slab, y / slab, nseed + 3);
      c.At(x, y) = Color(0.74f, 0.72f, 0.68f) * shade * (1.0f - 0.07f * vein);
    }
  for (int k = 0; k < 4; ++k) {  // thin light joints
    c.Rect(k * slab, 0, k * slab + 2, N, Gray(0.8f), 0.6f);
    c.Rect(0, k * slab, N, k * slab + 2, Gray(0.8f), 0.6f);
  }
  return c.ToTexture("polished_floor");
}

Texture MakeCeilingTileTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "ceiling"));
  const int N = 512, panel = N / 4;
  Canvas c(N, N, Gray(0.92f));
  AddGrime(c, rng.Next(), 0.02f, 0.06f, 4);
  for (int k = 0; k < 4; ++k) {
    c.Rect(k * panel, 0, k * panel + 3, N, Gray(0.78f));
    c.Rect(0, k * panel, N, k * panel + 3, Gray(0.78f));
  }
  return c.ToTexture("ceiling");
}

Texture MakePosterTexture(uint64_t seed, int index) {
  SceneRng rng(SubSeed(seed, "poster", static_cast<uint64_t>(index)));
  const int W = 256, H = 360;
  const Color paper(0.93f, 0.92f, 0.88f);
  Canvas c(W, H, paper);
  // A coloured header band, a picture block and lines of "text".
  const Color accent(static_cast<float>(rng.Uniform(0.1, 0.9)), static_cast<float>(rng.Uniform(0.1, 0.6)),
                     static_cast<float>(rng.Uniform(0.2, 0.9)));
  c.Rect(0, 0, W, 50, accent);
  const int py = 70, ph = static_cast<int>(rng.Uniform(80, 140));
  const uint64_t picture_seed = rng.Next();
  for (int y = py; y < py + ph; ++y)
    for (int x = 20; x < W - 20; ++x) c.At(x, y) = accent * (0.4f + 0.6f * Hash01(x / 12, y / 12, picture_seed));
  for (int y = py + ph + 20; y < H - 20; y += 14) {
    const int len = static_cast<int>(rng.Uniform(80, W - 40));
    c.Rect(20, y, 20 + len, y + 6, Gray(0.25f));
  }
  c.Frame(0, 0, W, H, 4, Gray(0.3f));
  return c.ToTexture("poster_" + std::to_string(index));
}

}  // namespace rovo
