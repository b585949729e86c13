#include "scenes/texture_draw.h"

#include <algorithm>
#include <cmath>

namespace rovo::texture_internal {

float ValueNoise(float x, float y, int period, uint64_t seed) {
  const float fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  float tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const int64_t x0 = Mod(ix, period), x1 = Mod(ix + 1, period), y0 = Mod(iy, period), y1 = Mod(iy + 1, period);
  const float a = Hash01(x0, y0, seed), b = Hash01(x1, y0, seed), c = Hash01(x0, y1, seed), d = Hash01(x1, y1, seed);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

void AddGrime(Canvas& c, uint64_t seed, float large, float grain, int cells) {
  const NoiseField noise(c.w(), c.h(), cells, 5, seed);
  for (int y = 0; y < c.h(); ++y)
    for (int x = 0; x < c.w(); ++x) {
      const float n = noise(x, y);
      const float g = Hash01(x, y, seed ^ 0xABCDEFull) - 0.5f;
      c.At(x, y) *= 1.0f + large * (n - 0.5f) * 2.0f + grain * g;
    }
}

void Crack(Canvas& c, SceneRng& rng, float x, float y, int steps, float step_px, const Color& color) {
  float heading = static_cast<float>(rng.Uniform(0, 2 * M_PI));
  for (int i = 0; i < steps; ++i) {
    heading += static_cast<float>(rng.Normal(0, 0.45));
    const float nx = x + step_px * std::cos(heading), ny = y + step_px * std::sin(heading);
    c.Line(x, y, nx, ny, rng.Bernoulli(0.3) ? 1.0f : 0.6f, color, 0.75f);
    x = nx;
    y = ny;
    if (rng.Bernoulli(0.06)) Crack(c, rng, x, y, steps / 3, step_px, color);
  }
}

void Glass(Canvas& c, SceneRng& rng, int x0, int y0, int x1, int y1, uint64_t seed) {
  const Color dark(0.10f + 0.05f * static_cast<float>(rng.Uniform()), 0.13f,
                   0.17f + 0.06f * static_cast<float>(rng.Uniform()));
  const Color sky(0.55f, 0.62f, 0.70f);
  const float refl = static_cast<float>(rng.Uniform(0.1, 0.5));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const float g = 1.0f - static_cast<float>(y - y0) / std::max(1, y1 - y0);
      const float blot = ValueNoise(x * 0.03f, y * 0.03f, 1 << 20, seed);
      c.At(x, y) = dark + (refl * g * g + 0.25f * blot * refl) * (sky - dark);
    }
  // Curtains or blinds in some windows (corners inside the pane).
  const double kind = rng.Uniform();
  if (kind < 0.25) {
    const int yb = y0 + static_cast<int>((y1 - y0) * rng.Uniform(0.2, 0.8));
    const Color blind = Gray(static_cast<float>(rng.Uniform(0.6, 0.9)));
    for (int y = y0; y < yb; ++y)
      if ((y - y0) % 5 != 4) c.Rect(x0, y, x1, y + 1, blind, 0.9f);
  } else if (kind < 0.45) {
    const Color curtain(static_cast<float>(rng.Uniform(0.4, 0.9)), static_cast<float>(rng.Uniform(0.3, 0.8)),
                        static_cast<float>(rng.Uniform(0.3, 0.7)));
    const int w = static_cast<int>((x1 - x0) * rng.Uniform(0.15, 0.35));
    c.Rect(x0, y0, x0 + w, y1, curtain, 0.85f);
    c.Rect(x1 - w, y0, x1, y1, curtain, 0.85f);
  } else if (kind < 0.55) {
    // Lit room / interior objects: a few soft rectangles.
    for (int k = 0; k < 3; ++k) {
      const int ax = rng.UniformInt(x0, x1 - 4), ay = rng.UniformInt(y0 + (y1 - y0) / 2, y1 - 4);
      c.Rect(ax, ay, std::min(x1, ax + rng.UniformInt(6, 30)), y1, Gray(static_cast<float>(rng.Uniform(0.2, 0.6))),
             0.6f);
    }
  }
}

}  // namespace rovo::texture_internal
