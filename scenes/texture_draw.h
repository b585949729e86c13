#pragma once
// Drawing primitives of the procedural textures (internal to scenes/): hash and value noise, a
// wrapping canvas (textures tile), and the wear, crack and glass painters the generators share.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "scenes/rng.h"
#include "scenes/scene.h"

namespace rovo::texture_internal {

using Color = Eigen::Vector3f;  // sRGB in [0, 1] while drawing

// Integer hash to [0, 1) (per-element variation without RNG streams): 32-bit avalanche mix.
inline float Hash01(int64_t x, int64_t y, uint64_t seed) {
  uint32_t h = static_cast<uint32_t>(x) * 0x27D4EB2Du ^ static_cast<uint32_t>(y) * 0x165667B1u ^
               static_cast<uint32_t>(seed) ^ static_cast<uint32_t>(seed >> 32) * 0x9E3779B9u;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

inline int64_t Mod(int64_t a, int64_t m) { return ((a % m) + m) % m; }

// Tileable value noise in [0, 1): x, y in lattice cells, lattice period `period` cells.
float ValueNoise(float x, float y, int period, uint64_t seed);

// Tileable fractal value noise over a w x h texture, precomputed into a full-resolution field:
// octave o has a lattice of (cells * 2^o) x (cells * 2^o * h / w) cells spanning the texture,
// smoothstep-interpolated, amplitudes halving. Values roughly in [0, 1].
class NoiseField {
 public:
  NoiseField(int w, int h, int cells, int octaves, uint64_t seed) : w_(w), values_(static_cast<size_t>(w) * h, 0.0f) {
    float amp = 0.5f, norm = 0;
    int period_x = cells;
    std::vector<float> lattice;
    for (int o = 0; o < octaves; ++o) {
      const int period_y = std::max(1, period_x * h / w);
      lattice.resize(static_cast<size_t>(period_x) * period_y);
      for (int y = 0; y < period_y; ++y)
        for (int x = 0; x < period_x; ++x)
          lattice[static_cast<size_t>(y) * period_x + x] = Hash01(x, y, seed + static_cast<uint64_t>(7919u * o));
      for (int py = 0; py < h; ++py) {
        const float fy = (py + 0.5f) * period_y / h;
        const int y0 = static_cast<int>(fy);
        float ty = fy - y0;
        ty = ty * ty * (3 - 2 * ty);
        const float* r0 = &lattice[static_cast<size_t>(y0 % period_y) * period_x];
        const float* r1 = &lattice[static_cast<size_t>((y0 + 1) % period_y) * period_x];
        float* out = &values_[static_cast<size_t>(py) * w];
        for (int px = 0; px < w; ++px) {
          const float fx = (px + 0.5f) * period_x / w;
          const int x0 = static_cast<int>(fx), x1 = (x0 + 1) % period_x;
          float tx = fx - x0;
          tx = tx * tx * (3 - 2 * tx);
          const int xa = x0 % period_x;
          const float top = r0[xa] + (r0[x1] - r0[xa]) * tx, bottom = r1[xa] + (r1[x1] - r1[xa]) * tx;
          out[px] += amp * (top + (bottom - top) * ty);
        }
      }
      norm += amp;
      amp *= 0.5f;
      period_x *= 2;
    }
    for (float& v : values_) v /= norm;
  }
  float operator()(int x, int y) const { return values_[static_cast<size_t>(y) * w_ + x]; }

 private:
  int w_;
  std::vector<float> values_;
};

class Canvas {
 public:
  Canvas(int w, int h, const Color& fill) : w_(w), h_(h), px_(static_cast<size_t>(w) * h, fill) {}
  int w() const { return w_; }
  int h() const { return h_; }
  Color& At(int x, int y) { return px_[static_cast<size_t>(Mod(y, h_)) * w_ + Mod(x, w_)]; }
  // Filled rectangle [x0, x1) x [y0, y1), wrapping around the edges (textures tile).
  void Rect(int x0, int y0, int x1, int y1, const Color& c, float alpha = 1.0f) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        Color& p = At(x, y);
        p = p + alpha * (c - p);
      }
  }
  // Rectangle outline of thickness t.
  void Frame(int x0, int y0, int x1, int y1, int t, const Color& c) {
    Rect(x0, y0, x1, y0 + t, c);
    Rect(x0, y1 - t, x1, y1, c);
    Rect(x0, y0, x0 + t, y1, c);
    Rect(x1 - t, y0, x1, y1, c);
  }
  void Scale(int x0, int y0, int x1, int y1, float s) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) At(x, y) *= s;
  }
  // Thick line segment (cracks, markings) by stamping discs.
  void Line(float xa, float ya, float xb, float yb, float radius, const Color& c, float alpha) {
    const float len = std::hypot(xb - xa, yb - ya);
    const int steps = std::max(1, static_cast<int>(len * 2));
    const int r = static_cast<int>(std::ceil(radius));
    for (int s = 0; s <= steps; ++s) {
      const float x = xa + (xb - xa) * s / steps, y = ya + (yb - ya) * s / steps;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx)
          if (dx * dx + dy * dy <= radius * radius + 0.25f) {
            Color& p = At(static_cast<int>(std::lround(x)) + dx, static_cast<int>(std::lround(y)) + dy);
            p = p + alpha * (c - p);
          }
    }
  }
  void Disc(float cx, float cy, float radius, const Color& c, float alpha) { Line(cx, cy, cx, cy, radius, c, alpha); }

  Texture ToTexture(const std::string& name) const {
    Texture t;
    t.name = name;
    t.width = w_;
    t.height = h_;
    t.rgb.resize(px_.size() * 3);
    for (size_t i = 0; i < px_.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        t.rgb[i * 3 + c] = static_cast<uint8_t>(std::clamp(std::lround(px_[i][c] * 255.0f), 0L, 255L));
      }
    return t;
  }

 private:
  int w_, h_;
  std::vector<Color> px_;
};

inline Color Gray(float v) { return Color(v, v, v); }

// Multiplies every pixel by (1 + amount * (fbm - 0.5)) plus per-pixel grain: the wear layer.
void AddGrime(Canvas& c, uint64_t seed, float large, float grain, int cells = 8);
// Random-walk crack starting at (x, y).
void Crack(Canvas& c, SceneRng& rng, float x, float y, int steps, float step_px, const Color& color);
// Glass pane with a vertical sky-reflection gradient, blotchy reflections and optional blinds.
void Glass(Canvas& c, SceneRng& rng, int x0, int y0, int x1, int y1, uint64_t seed);

}  // namespace rovo::texture_internal
