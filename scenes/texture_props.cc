// Textures of the things along the streets: cars, tree bark and foliage, road signs.

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "scenes/texture_draw.h"
#include "scenes/texture_gen.h"

namespace rovo {

using namespace texture_internal;  // the drawing primitives

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

}  // namespace rovo
