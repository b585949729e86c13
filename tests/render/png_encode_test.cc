#include "render/png_encode.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace rovo {
namespace {

namespace fs = std::filesystem;

// Writes `png` to a temporary file and reads it back with OpenImageIO (libpng): spec and pixels.
template <typename T>
std::vector<T> DecodeWithLibpng(const std::string& png, OIIO::TypeDesc type, OIIO::ImageSpec* spec) {
  const fs::path path = fs::temp_directory_path() / ("rovo_png_encode_" + std::to_string(::getpid()) + ".png");
  std::ofstream(path, std::ios::binary).write(png.data(), static_cast<std::streamsize>(png.size()));
  auto in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << OIIO::geterror();
  std::vector<T> pixels;
  if (in) {
    *spec = in->spec();
    pixels.resize(static_cast<size_t>(spec->width) * spec->height * spec->nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec->nchannels, type, pixels.data())) << in->geterror();
    in->close();
  }
  fs::remove(path);
  return pixels;
}

template <typename T>
std::vector<T> Noise(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<T> v(n);
  for (T& x : v) x = static_cast<T>(rng());
  return v;
}

TEST(PngEncode, LibpngReadsBackEveryLayoutExactly) {
  const int width = 37, height = 23;  // odd sizes: no row padding assumed
  const auto rgb = Noise<uint8_t>(width * height * 3, 1);
  OIIO::ImageSpec spec;
  EXPECT_EQ(
      DecodeWithLibpng<uint8_t>(EncodePng(width, height, 3, 8, rgb.data(), "rovo test"), OIIO::TypeDesc::UINT8, &spec),
      rgb);
  EXPECT_EQ(spec.width, width);
  EXPECT_EQ(spec.height, height);
  EXPECT_EQ(spec.nchannels, 3);
  EXPECT_EQ(spec.get_string_attribute("Software"), "rovo test");

  const auto gray = Noise<uint8_t>(width * height, 2);
  EXPECT_EQ(DecodeWithLibpng<uint8_t>(EncodePng(width, height, 1, 8, gray.data(), "x"), OIIO::TypeDesc::UINT8, &spec),
            gray);
  EXPECT_EQ(spec.nchannels, 1);

  const auto ids = Noise<uint16_t>(width * height, 3);
  EXPECT_EQ(DecodeWithLibpng<uint16_t>(EncodePng(width, height, 1, 16, ids.data(), "x"), OIIO::TypeDesc::UINT16, &spec),
            ids);
  EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT16);
}

TEST(PngEncode, ASmoothImageCompresses) {
  const int width = 256, height = 64;
  std::vector<uint8_t> ramp(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) ramp[y * width + x] = static_cast<uint8_t>(x);
  EXPECT_LT(EncodePng(width, height, 1, 8, ramp.data(), "x").size(), ramp.size() / 20);
}

TEST(PngEncode, RejectsUnsupportedLayouts) {
  const std::vector<uint16_t> pixels(64, 0);
  EXPECT_THROW(EncodePng(0, 4, 1, 8, pixels.data(), "x"), std::invalid_argument);
  EXPECT_THROW(EncodePng(4, 4, 2, 8, pixels.data(), "x"), std::invalid_argument);
  EXPECT_THROW(EncodePng(4, 4, 3, 16, pixels.data(), "x"), std::invalid_argument);
  EXPECT_THROW(EncodePng(4, 4, 1, 12, pixels.data(), "x"), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
