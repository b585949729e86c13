#include "scenes/texture_gen.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "scenes/rng.h"

namespace rovo {
namespace {

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
          lattice[static_cast<size_t>(y) * period_x + x] = Hash01(x, y, seed + 7919u * o);
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

Color Gray(float v) { return Color(v, v, v); }

// Multiplies every pixel by (1 + amount * (fbm - 0.5)) plus per-pixel grain: the wear layer.
void AddGrime(Canvas& c, uint64_t seed, float large, float grain, int cells = 8) {
  const NoiseField noise(c.w(), c.h(), cells, 5, seed);
  for (int y = 0; y < c.h(); ++y)
    for (int x = 0; x < c.w(); ++x) {
      const float n = noise(x, y);
      const float g = Hash01(x, y, seed ^ 0xABCDEFull) - 0.5f;
      c.At(x, y) *= 1.0f + large * (n - 0.5f) * 2.0f + grain * g;
    }
}

// Random-walk crack starting at (x, y).
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

// Glass pane with a vertical sky-reflection gradient, blotchy reflections and optional blinds.
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

}  // namespace

namespace {

// The first draws of a facade's stream: the layout (shared with the geometry through
// GetFacadeLayout), the wall brightness and the noise seed. MakeFacadeTexture continues the stream.
struct FacadeDraws {
  FacadeLayout layout;
  float base = 0;
  uint64_t nseed = 0;
};
FacadeDraws DrawFacade(int index, SceneRng& rng) {
  FacadeDraws d;
  d.layout.style = index % 4;
  d.layout.bays = rng.UniformInt(3, 6);
  d.base = static_cast<float>(rng.Uniform(0.72, 0.95));
  d.nseed = rng.Next();
  const bool curtain = d.layout.style == 3;
  d.layout.window_width_fraction = curtain ? rng.Uniform(0.8, 0.92) : rng.Uniform(0.42, 0.68);
  d.layout.window_height_fraction = curtain ? rng.Uniform(0.62, 0.72) : rng.Uniform(0.42, 0.6);
  return d;
}

}  // namespace

FacadeLayout GetFacadeLayout(uint64_t seed, int index) {
  SceneRng rng(SubSeed(seed, "facade", static_cast<uint64_t>(index)));
  return DrawFacade(index, rng).layout;
}

int FacadeBays(uint64_t seed, int index) { return GetFacadeLayout(seed, index).bays; }

Texture MakeFacadeTexture(uint64_t seed, int index) {
  SceneRng rng(SubSeed(seed, "facade", static_cast<uint64_t>(index)));
  const int W = 1024, H = 1024, floor_px = H / 4;
  const FacadeDraws draws = DrawFacade(index, rng);
  const int style = draws.layout.style;  // 0 brick, 1 plaster, 2 panels, 3 glass curtain wall
  const int bays = draws.layout.bays;
  const float base = draws.base;
  Canvas c(W, H, Gray(base));
  const uint64_t nseed = draws.nseed;

  if (style == 0) {  // bricks: 52 per row, 32 courses per floor (tileable)
    const float brick_w = W / 52.0f;
    const int course = floor_px / 32;
    const Color mortar = Gray(std::min(1.0f, base + 0.05f));
    for (int y = 0; y < H; ++y) {
      const int row = y / course;
      const float shift = (row % 2) * brick_w * 0.5f;
      for (int x = 0; x < W; ++x) {
        const float bx = (x + shift) / brick_w;
        const int64_t bi = static_cast<int64_t>(std::floor(bx)) % 52;
        const bool joint = (y % course) < 2 || (bx - std::floor(bx)) * brick_w < 2.0f;
        if (joint) {
          c.At(x, y) = mortar;
        } else {
          const float v = 0.75f + 0.25f * Hash01(bi, row, nseed);
          const float warm = 0.05f * Hash01(bi, row, nseed + 1);
          c.At(x, y) = Color(base * v + warm, base * v * 0.93f, base * v * 0.88f);
        }
      }
    }
  } else if (style == 2) {  // precast panels: joints at bays and half floors
    const int panel_w = W / bays, panel_h = floor_px / 2;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const float v = 0.9f + 0.1f * Hash01(x / panel_w, y / panel_h, nseed);
        c.At(x, y) = Gray(base * v);
        if (x % panel_w < 3 || y % panel_h < 3) c.At(x, y) = Gray(base * 0.45f);
      }
  }
  AddGrime(c, nseed + 2, style == 3 ? 0.05f : 0.12f, style == 1 ? 0.10f : 0.06f);

  // Windows: one per bay and floor. Layout shared by the texture, details vary per window.
  const int bay_w = W / bays;
  const float win_wf = static_cast<float>(draws.layout.window_width_fraction);
  const float win_hf = static_cast<float>(draws.layout.window_height_fraction);
  const int win_w = static_cast<int>(bay_w * win_wf), win_h = static_cast<int>(floor_px * win_hf);
  const int frame_t = rng.UniformInt(4, 8);
  const Color frame_color = rng.Bernoulli(0.5) ? Gray(static_cast<float>(rng.Uniform(0.85, 0.97)))
                                               : Color(static_cast<float>(rng.Uniform(0.12, 0.35)), 0.2f, 0.17f);
  const int mullions = rng.UniformInt(0, 3);  // 0 none, 1 vertical, 2 cross, 3 two horizontal
  const bool sills = style != 3 && rng.Bernoulli(0.8);
  const bool lintels = style == 0 && rng.Bernoulli(0.7);
  const bool string_course = style != 3 && rng.Bernoulli(0.5);
  const Color trim = Gray(static_cast<float>(rng.Uniform(0.55, 0.98)));
  for (int f = 0; f < 4; ++f) {
    const int fy = f * floor_px;
    if (string_course) c.Rect(0, fy + floor_px - 10, W, fy + floor_px - 2, trim);
    if (style == 3) c.Rect(0, fy + floor_px - 40, W, fy + floor_px, Gray(base * 0.55f));  // spandrel
    for (int b = 0; b < bays; ++b) {
      const int x0 = b * bay_w + (bay_w - win_w) / 2, y0 = fy + (floor_px - win_h) / 2 - 8;
      const int x1 = x0 + win_w, y1 = y0 + win_h;
      if (lintels) c.Rect(x0 - 6, y0 - 14, x1 + 6, y0, Gray(base * 0.6f));
      Glass(c, rng, x0, y0, x1, y1, nseed + 100 + static_cast<uint64_t>(f * 16 + b));
      c.Frame(x0, y0, x1, y1, frame_t, frame_color);
      const int mx = (x0 + x1) / 2, my = y0 + (y1 - y0) * 2 / 5;
      if (mullions == 1 || mullions == 2) c.Rect(mx - frame_t / 2, y0, mx + frame_t / 2 + 1, y1, frame_color);
      if (mullions == 2) c.Rect(x0, my - frame_t / 2, x1, my + frame_t / 2 + 1, frame_color);
      if (mullions == 3) {
        c.Rect(x0, y0 + (y1 - y0) / 3, x1, y0 + (y1 - y0) / 3 + frame_t / 2 + 1, frame_color);
        c.Rect(x0, y0 + 2 * (y1 - y0) / 3, x1, y0 + 2 * (y1 - y0) / 3 + frame_t / 2 + 1, frame_color);
      }
      if (sills) c.Rect(x0 - 8, y1, x1 + 8, y1 + 9, trim);
      // Weathering streaks under the sill.
      if (style != 3) {
        for (int x = x0; x < x1; ++x) {
          const float s = 0.12f * Hash01(x / 3, f * 16 + b, nseed + 5);
          for (int y = y1 + 9; y < std::min(fy + floor_px + 60, y1 + 9 + 70); ++y) {
            const float fade = 1.0f - static_cast<float>(y - y1 - 9) / 70.0f;
            c.At(x, y) *= 1.0f - s * fade;
          }
        }
      }
      // Occasional sign, air conditioner or flower box.
      const double extra = rng.Uniform();
      if (extra < 0.06) {
        c.Rect(x1 + 6, y0 + 10, x1 + 40, y0 + 40, Gray(0.8f));
        c.Frame(x1 + 6, y0 + 10, x1 + 40, y0 + 40, 2, Gray(0.3f));
        for (int k = 0; k < 4; ++k) c.Rect(x1 + 10, y0 + 15 + k * 6, x1 + 36, y0 + 17 + k * 6, Gray(0.45f));
      } else if (extra < 0.12 && sills) {
        const Color flowers(static_cast<float>(rng.Uniform(0.5, 0.9)), static_cast<float>(rng.Uniform(0.1, 0.5)), 0.2f);
        for (int k = 0; k < win_w / 6; ++k)
          c.Disc(static_cast<float>(x0 + 3 + k * 6), static_cast<float>(y1 - 3), 3.0f,
                 k % 2 ? flowers : Color(0.15f, 0.4f, 0.12f), 1.0f);
      }
    }
  }
  return c.ToTexture("facade_" + std::to_string(index));
}

Texture MakeStorefrontTexture(uint64_t seed, int index) {
  SceneRng rng(SubSeed(seed, "storefront", static_cast<uint64_t>(index)));
  const int W = 1024, H = 320;
  const float base = static_cast<float>(rng.Uniform(0.6, 0.9));
  Canvas c(W, H, Gray(base));
  const uint64_t nseed = rng.Next();
  AddGrime(c, nseed, 0.12f, 0.08f);
  c.Rect(0, H - 26, W, H, Gray(base * 0.55f));  // plinth
  for (int x = 0; x < W; x += 64) c.Rect(x, H - 26, x + 2, H, Gray(base * 0.35f));
  const int shops = rng.UniformInt(2, 3);
  int x = 0;
  for (int s = 0; s < shops; ++s) {
    const int sw = s == shops - 1 ? W - x : W / shops + rng.UniformInt(-60, 60);
    const int pil = rng.UniformInt(18, 40);
    c.Rect(x, 0, x + pil, H, Gray(base * 0.8f));
    c.Frame(x, 0, x + pil, H - 26, 3, Gray(base * 0.6f));
    // Sign board with letter blocks.
    const Color board(static_cast<float>(rng.Uniform(0.05, 0.95)), static_cast<float>(rng.Uniform(0.05, 0.9)),
                      static_cast<float>(rng.Uniform(0.05, 0.9)));
    const Color ink = board.mean() > 0.5f ? Gray(0.08f) : Gray(0.95f);
    const int bx0 = x + pil + 10, bx1 = x + sw - 10, by0 = 18, by1 = by0 + rng.UniformInt(40, 56);
    c.Rect(bx0, by0, bx1, by1, board);
    c.Frame(bx0, by0, bx1, by1, 3, board * 0.5f);
    int lx = bx0 + rng.UniformInt(12, 40);
    const int letters = rng.UniformInt(4, 10);
    for (int k = 0; k < letters && lx < bx1 - 30; ++k) {
      const int lw = rng.UniformInt(10, 18), lh = by1 - by0 - 16;
      const int shape = rng.UniformInt(0, 3);
      if (shape == 0) {
        c.Rect(lx, by0 + 8, lx + lw, by0 + 8 + lh, ink);
        c.Rect(lx + 3, by0 + 12, lx + lw - 3, by0 + 4 + lh, board);
      } else if (shape == 1) {
        c.Rect(lx, by0 + 8, lx + 4, by0 + 8 + lh, ink);
        c.Rect(lx, by0 + 8, lx + lw, by0 + 12, ink);
        c.Rect(lx, by0 + 6 + lh / 2, lx + lw - 3, by0 + 10 + lh / 2, ink);
      } else if (shape == 2) {
        c.Rect(lx, by0 + 8, lx + lw, by0 + 12, ink);
        c.Rect(lx + lw / 2 - 2, by0 + 8, lx + lw / 2 + 2, by0 + 8 + lh, ink);
      } else {
        c.Line(static_cast<float>(lx), static_cast<float>(by0 + 8 + lh), static_cast<float>(lx + lw / 2),
               static_cast<float>(by0 + 8), 2.0f, ink, 1.0f);
        c.Line(static_cast<float>(lx + lw / 2), static_cast<float>(by0 + 8), static_cast<float>(lx + lw),
               static_cast<float>(by0 + 8 + lh), 2.0f, ink, 1.0f);
      }
      lx += lw + rng.UniformInt(4, 9);
    }
    // Door and shop window.
    const int wy0 = by1 + 16, wy1 = H - 30;
    const int door_w = 84;
    const bool door_left = rng.Bernoulli(0.5);
    const int dx0 = door_left ? x + pil + 8 : x + sw - door_w - 8;
    const Color frame = rng.Bernoulli(0.5) ? Gray(0.15f) : Gray(0.85f);
    Glass(c, rng, dx0, wy0 + 8, dx0 + door_w, H - 26, nseed + 10 + static_cast<uint64_t>(s));
    c.Frame(dx0, wy0 + 8, dx0 + door_w, H - 26, 8, frame);
    c.Rect(dx0 + (door_left ? door_w - 18 : 10), (wy0 + H) / 2, dx0 + (door_left ? door_w - 14 : 14),
           (wy0 + H) / 2 + 30, Gray(0.7f));
    const int wx0 = door_left ? dx0 + door_w + 12 : x + pil + 8, wx1 = door_left ? x + sw - 8 : dx0 - 12;
    if (wx1 - wx0 > 40) {
      Glass(c, rng, wx0, wy0, wx1, wy1, nseed + 20 + static_cast<uint64_t>(s));
      // Window display: goods on shelves.
      for (int k = 0; k < (wx1 - wx0) / 25; ++k) {
        const int gx = wx0 + 8 + k * 25, gh = rng.UniformInt(12, 40);
        const Color goods(static_cast<float>(rng.Uniform(0.2, 0.9)), static_cast<float>(rng.Uniform(0.2, 0.9)),
                          static_cast<float>(rng.Uniform(0.2, 0.9)));
        c.Rect(gx, wy1 - 10 - gh, gx + rng.UniformInt(10, 20), wy1 - 10, goods, 0.8f);
      }
      c.Frame(wx0, wy0, wx1, wy1, 7, frame);
      const int panes = rng.UniformInt(1, 3);
      for (int p = 1; p < panes; ++p)
        c.Rect(wx0 + (wx1 - wx0) * p / panes - 3, wy0, wx0 + (wx1 - wx0) * p / panes + 3, wy1, frame);
    }
    x += sw;
  }
  return c.ToTexture("storefront_" + std::to_string(index));
}

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

Texture MakeCarSideTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "car_side"));
  const int W = 512, H = 128;  // 4.4 m x 1.1 m
  Canvas c(W, H, Gray(0.9f));
  AddGrime(c, rng.Next(), 0.04f, 0.03f);
  const Color line = Gray(0.35f);
  for (int x : {int(W * 0.28), int(W * 0.52), int(W * 0.74)}) c.Rect(x, 6, x + 2, H - 22, line);  // door seams
  c.Rect(0, 4, W, 6, line);
  c.Rect(0, H - 22, W, H, Gray(0.25f));                                                // sill / bumper strip
  for (int x : {int(W * 0.44), int(W * 0.66)}) c.Rect(x, 24, x + 16, 29, Gray(0.2f));  // handles
  for (float wx : {W * 0.17f, W * 0.83f}) {                                            // wheel arches
    c.Disc(wx, H + 6.0f, 44.0f, Gray(0.1f), 1.0f);
  }
  c.Rect(W - 10, 30, W, 46, Color(0.9f, 0.6f, 0.1f));  // side marker
  return c.ToTexture("car_side");
}

Texture MakeCarEndTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "car_end"));
  const int W = 256, H = 128;
  Canvas c(W, H, Gray(0.9f));
  c.Rect(0, H - 30, W, H, Gray(0.25f));                         // bumper
  c.Rect(W / 2 - 36, H - 56, W / 2 + 36, H - 36, Gray(0.95f));  // plate
  c.Frame(W / 2 - 36, H - 56, W / 2 + 36, H - 36, 2, Gray(0.1f));
  for (int k = 0; k < 6; ++k) c.Rect(W / 2 - 30 + k * 10, H - 52, W / 2 - 25 + k * 10, H - 40, Gray(0.15f));
  const Color lamp = rng.Bernoulli(0.5) ? Color(0.95f, 0.95f, 0.85f) : Color(0.8f, 0.1f, 0.08f);
  c.Rect(10, 30, 64, 56, lamp);
  c.Frame(10, 30, 64, 56, 3, Gray(0.2f));
  c.Rect(W - 64, 30, W - 10, 56, lamp);
  c.Frame(W - 64, 30, W - 10, 56, 3, Gray(0.2f));
  for (int y = 36; y < 56; y += 6) c.Rect(80, y, W - 80, y + 3, Gray(0.2f));  // grille
  return c.ToTexture("car_end");
}

Texture MakeCarGlassTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "car_glass"));
  const int W = 256, H = 64;
  Canvas c(W, H, Gray(0.1f));
  Glass(c, rng, 0, 0, W, H, rng.Next());
  for (int x : {0, W / 2 - 4, W - 8}) c.Rect(x, 0, x + 8, H, Gray(0.12f));  // pillars
  c.Rect(0, 0, W, 4, Gray(0.12f));
  return c.ToTexture("car_glass");
}

Texture MakeAwningTexture(uint64_t seed, int index) {
  SceneRng rng(SubSeed(seed, "awning", static_cast<uint64_t>(index)));
  const int W = 256, H = 64;
  const int stripes = 2 * rng.UniformInt(4, 8);  // even: the tile repeats seamlessly
  const Color cloth(static_cast<float>(rng.Uniform(0.1, 0.8)), static_cast<float>(rng.Uniform(0.1, 0.6)),
                    static_cast<float>(rng.Uniform(0.1, 0.6)));
  const bool plain = rng.Bernoulli(0.3);
  Canvas c(W, H, cloth);
  const uint64_t nseed = rng.Next();
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool light = !plain && (x * stripes / W) % 2 == 1;
      const float v = 0.9f + 0.1f * Hash01(x / 2, y / 2, nseed);
      c.At(x, y) = (light ? Gray(0.92f) : cloth) * v;
    }
  AddGrime(c, nseed + 1, 0.08f, 0.04f, 4);
  return c.ToTexture("awning_" + std::to_string(index));
}

Texture MakeBarkTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "bark"));
  const int N = 128;
  Canvas c(N, N, Gray(0.3f));
  const uint64_t nseed = rng.Next();
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const float v = 0.25f + 0.25f * ValueNoise(x * 0.5f, y * 0.06f, 64, nseed) + 0.1f * Hash01(x, y, nseed);
      c.At(x, y) = Color(v * 1.1f, v * 0.95f, v * 0.75f);
    }
  return c.ToTexture("bark");
}

Texture MakeSignTexture(uint64_t seed, int kind) {
  SceneRng rng(SubSeed(seed, "sign", static_cast<uint64_t>(kind)));
  const int N = 256;
  const float c = N / 2.0f;
  Canvas img(N, N, Gray(0.62f));
  const Color red(0.8f, 0.08f, 0.06f), white = Gray(0.95f), blue(0.05f, 0.25f, 0.65f), black = Gray(0.05f);
  auto fill = [&](const std::function<bool(float, float)>& inside, const Color& color) {
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x)
        if (inside(x + 0.5f - c, y + 0.5f - c)) img.At(x, y) = color;
  };
  auto octagon = [](float r) {
    return
        [r](float x, float y) { return std::abs(x) < r && std::abs(y) < r && std::abs(x) + std::abs(y) < r * 1.414f; };
  };
  auto disc = [](float r) { return [r](float x, float y) { return x * x + y * y < r * r; }; };
  switch (kind) {
    case 0:  // stop
      fill(octagon(120), white);
      fill(octagon(110), red);
      for (int k = 0; k < 4; ++k) img.Rect(50 + k * 42, 105, 50 + k * 42 + 30, 150, white);
      for (int k = 0; k < 4; ++k) img.Rect(58 + k * 42, 113, 50 + k * 42 + 22, 142, red);
      break;
    case 1:  // give way: inverted triangle
      fill([](float x, float y) { return y > -110 && y < 110 && std::abs(x) < (110 - y) * 0.577f; }, red);
      fill([](float x, float y) { return y > -85 && y < 75 && std::abs(x) < (75 - y) * 0.577f; }, white);
      break;
    case 2:  // no entry
      fill(disc(120), white);
      fill(disc(112), red);
      img.Rect(40, 112, 216, 144, white);
      break;
    case 3: {  // speed limit: digits as blocks
      fill(disc(120), white);
      fill(disc(120), red);
      fill(disc(96), white);
      const int tens = rng.UniformInt(2, 6);
      for (int d = 0; d < 2; ++d) {
        const int x0 = 78 + d * 56;
        img.Frame(x0, 82, x0 + 44, 174, 12, black);
        if (d == 0 && tens % 2) img.Rect(x0 + 12, 122, x0 + 44, 134, black);
      }
      break;
    }
    default:  // pedestrian crossing: blue square, white triangle, walking figure
      img.Rect(16, 16, 240, 240, white);
      img.Rect(24, 24, 232, 232, blue);
      fill([](float x, float y) { return y > -80 && y < 80 && std::abs(x) < (y + 80) * 0.6f; }, white);
      img.Disc(c, c - 20, 12, black, 1.0f);
      img.Line(c, c - 5, c - 6, c + 35, 5, black, 1.0f);
      img.Line(c - 6, c + 35, c - 25, c + 65, 5, black, 1.0f);
      img.Line(c - 6, c + 35, c + 18, c + 65, 5, black, 1.0f);
      for (int k = 0; k < 4; ++k) img.Rect(70 + k * 30, 196, 88 + k * 30, 206, black);
      break;
  }
  AddGrime(img, rng.Next(), 0.05f, 0.04f);
  return img.ToTexture("sign_" + std::to_string(kind));
}

Texture MakeFoliageTexture(uint64_t seed) {
  SceneRng rng(SubSeed(seed, "foliage"));
  const int N = 256;
  Canvas c(N, N, Color(0.12f, 0.25f, 0.08f));
  for (int k = 0; k < 1500; ++k) {
    const float g = static_cast<float>(rng.Uniform(0.5, 1.4));
    c.Disc(static_cast<float>(rng.Uniform(0, N)), static_cast<float>(rng.Uniform(0, N)),
           static_cast<float>(rng.Uniform(1.5, 4.5)), Color(0.18f * g, 0.38f * g, 0.12f * g), 1.0f);
  }
  return c.ToTexture("foliage");
}

// ---- harder worlds -------------------------------------------------------------------------------

// Smooth surface: base colour times (1 + large * (fbm - 0.5) * 2 + grain * (hash - 0.5)).
Texture PlainTexture(const std::string& name, int n, const Color& base, float large, float grain, int cells,
                     uint64_t seed) {
  Canvas c(n, n, base);
  AddGrime(c, seed, large, grain, cells);
  return c.ToTexture(name);
}

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
