// Building textures: upper-floor facades (brick, plaster, panels, glass curtain wall), ground-floor
// shops and awning cloth.

#include <algorithm>
#include <cmath>
#include <string>

#include "scenes/texture_draw.h"
#include "scenes/texture_gen.h"

namespace rovo {

using namespace texture_internal;  // the drawing primitives

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

// The facade's wall, before the windows are painted over it: bricks (52 per row, 32 courses per floor, tileable) or
// precast panels (joints at bays and half floors), then the wear layer.
void PaintFacadeWall(Canvas& c, const FacadeDraws& draws) {
  const int W = c.w(), H = c.h(), floor_px = H / 4;
  const int style = draws.layout.style;
  const int bays = draws.layout.bays;
  const float base = draws.base;
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
}

// The window details shared by every window of a facade (drawn after the wall, in this order).
struct WindowStyle {
  int frame_t = 0;
  Color frame_color;
  int mullions = 0;  // 0 none, 1 vertical, 2 cross, 3 two horizontal
  bool sills = false, lintels = false, string_course = false;
  Color trim;
};

WindowStyle DrawWindowStyle(int style, SceneRng& rng) {
  WindowStyle w;
  w.frame_t = rng.UniformInt(4, 8);
  w.frame_color = rng.Bernoulli(0.5) ? Gray(static_cast<float>(rng.Uniform(0.85, 0.97)))
                                     : Color(static_cast<float>(rng.Uniform(0.12, 0.35)), 0.2f, 0.17f);
  w.mullions = rng.UniformInt(0, 3);
  w.sills = style != 3 && rng.Bernoulli(0.8);
  w.lintels = style == 0 && rng.Bernoulli(0.7);
  w.string_course = style != 3 && rng.Bernoulli(0.5);
  w.trim = Gray(static_cast<float>(rng.Uniform(0.55, 0.98)));
  return w;
}

// One window [x0, x1) x [y0, y1) of bay b on floor f (top row fy): lintel, glass, frame, mullions,
// sill, weathering streaks, and now and then a sign, an air conditioner or a flower box.
void PaintWindow(Canvas& c, SceneRng& rng, const FacadeDraws& draws, const WindowStyle& w, int f, int b, int fy, int x0,
                 int y0, int win_w, int win_h) {
  const int floor_px = c.h() / 4;
  const int style = draws.layout.style;
  const float base = draws.base;
  const uint64_t nseed = draws.nseed;
  const int frame_t = w.frame_t;
  const Color& frame_color = w.frame_color;
  const int x1 = x0 + win_w, y1 = y0 + win_h;
  if (w.lintels) c.Rect(x0 - 6, y0 - 14, x1 + 6, y0, Gray(base * 0.6f));
  Glass(c, rng, x0, y0, x1, y1, nseed + 100 + static_cast<uint64_t>(f * 16 + b));
  c.Frame(x0, y0, x1, y1, frame_t, frame_color);
  const int mx = (x0 + x1) / 2, my = y0 + (y1 - y0) * 2 / 5;
  if (w.mullions == 1 || w.mullions == 2) c.Rect(mx - frame_t / 2, y0, mx + frame_t / 2 + 1, y1, frame_color);
  if (w.mullions == 2) c.Rect(x0, my - frame_t / 2, x1, my + frame_t / 2 + 1, frame_color);
  if (w.mullions == 3) {
    c.Rect(x0, y0 + (y1 - y0) / 3, x1, y0 + (y1 - y0) / 3 + frame_t / 2 + 1, frame_color);
    c.Rect(x0, y0 + 2 * (y1 - y0) / 3, x1, y0 + 2 * (y1 - y0) / 3 + frame_t / 2 + 1, frame_color);
  }
  if (w.sills) c.Rect(x0 - 8, y1, x1 + 8, y1 + 9, w.trim);
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
  } else if (extra < 0.12 && w.sills) {
    const Color flowers(static_cast<float>(rng.Uniform(0.5, 0.9)), static_cast<float>(rng.Uniform(0.1, 0.5)), 0.2f);
    for (int k = 0; k < win_w / 6; ++k)
      c.Disc(static_cast<float>(x0 + 3 + k * 6), static_cast<float>(y1 - 3), 3.0f,
             k % 2 ? flowers : Color(0.15f, 0.4f, 0.12f), 1.0f);
  }
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
  PaintFacadeWall(c, draws);

  // Windows: one per bay and floor. Layout shared by the texture, details vary per window.
  const int bay_w = W / bays;
  const float win_wf = static_cast<float>(draws.layout.window_width_fraction);
  const float win_hf = static_cast<float>(draws.layout.window_height_fraction);
  const int win_w = static_cast<int>(bay_w * win_wf), win_h = static_cast<int>(floor_px * win_hf);
  const WindowStyle w = DrawWindowStyle(style, rng);
  for (int f = 0; f < 4; ++f) {
    const int fy = f * floor_px;
    if (w.string_course) c.Rect(0, fy + floor_px - 10, W, fy + floor_px - 2, w.trim);
    if (style == 3) c.Rect(0, fy + floor_px - 40, W, fy + floor_px, Gray(base * 0.55f));  // spandrel
    for (int b = 0; b < bays; ++b) {
      const int x0 = b * bay_w + (bay_w - win_w) / 2, y0 = fy + (floor_px - win_h) / 2 - 8;
      PaintWindow(c, rng, draws, w, f, b, fy, x0, y0, win_w, win_h);
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
        const int mid_x = lx + lw / 2;  // whole pixels
        c.Line(static_cast<float>(lx), static_cast<float>(by0 + 8 + lh), static_cast<float>(mid_x),
               static_cast<float>(by0 + 8), 2.0f, ink, 1.0f);
        c.Line(static_cast<float>(mid_x), static_cast<float>(by0 + 8), static_cast<float>(lx + lw),
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

}  // namespace rovo
