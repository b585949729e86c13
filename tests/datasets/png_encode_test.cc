#include "datasets/png_encode.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace rovo {
namespace {

// Decodes `png` with OpenCV's PNG reader (libpng), an independent decoder, as stored.
cv::Mat DecodeWithOpenCv(const std::string& png) {
  return cv::imdecode(cv::Mat(1, static_cast<int>(png.size()), CV_8UC1, const_cast<char*>(png.data())),
                      cv::IMREAD_UNCHANGED);
}

template <typename T>
std::vector<T> Samples(const cv::Mat& image) {
  return image.isContinuous() ? std::vector<T>(image.ptr<T>(0), image.ptr<T>(0) + image.total() * image.channels())
                              : std::vector<T>();
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
  const std::string rgb_png = EncodePng(width, height, 3, 8, rgb.data(), "rovo test");
  cv::Mat decoded = DecodeWithOpenCv(rgb_png);
  ASSERT_EQ(decoded.type(), CV_8UC3);
  EXPECT_EQ(decoded.cols, width);
  EXPECT_EQ(decoded.rows, height);
  cv::cvtColor(decoded, decoded, cv::COLOR_BGR2RGB);
  EXPECT_EQ(Samples<uint8_t>(decoded), rgb);
  EXPECT_NE(rgb_png.find(std::string("tEXtSoftware\0rovo test", 21)), std::string::npos);

  const auto gray = Noise<uint8_t>(width * height, 2);
  decoded = DecodeWithOpenCv(EncodePng(width, height, 1, 8, gray.data(), "x"));
  ASSERT_EQ(decoded.type(), CV_8UC1);
  EXPECT_EQ(Samples<uint8_t>(decoded), gray);

  const auto ids = Noise<uint16_t>(width * height, 3);
  decoded = DecodeWithOpenCv(EncodePng(width, height, 1, 16, ids.data(), "x"));
  ASSERT_EQ(decoded.type(), CV_16UC1);
  EXPECT_EQ(Samples<uint16_t>(decoded), ids);
}

TEST(PngEncode, EveryLevelDecodesToTheSamePixels) {
  const int width = 64, height = 16;
  std::vector<uint8_t> rgb(width * height * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>((i / 7) % 251);
  const std::string fast = EncodePng(width, height, 3, 8, rgb.data(), "x", 1);
  const std::string small = EncodePng(width, height, 3, 8, rgb.data(), "x", 9);
  EXPECT_LE(small.size(), fast.size());
  cv::Mat decoded = DecodeWithOpenCv(small);
  cv::cvtColor(decoded, decoded, cv::COLOR_BGR2RGB);
  EXPECT_EQ(Samples<uint8_t>(decoded), rgb);
  EXPECT_THROW(EncodePng(width, height, 3, 8, rgb.data(), "x", 0), std::invalid_argument);
  EXPECT_THROW(EncodePng(width, height, 3, 8, rgb.data(), "x", 13), std::invalid_argument);
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
