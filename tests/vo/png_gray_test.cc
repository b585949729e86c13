// The fast PNG path of replays (vo/png_gray.h) against cv::imread(IMREAD_GRAYSCALE): byte for byte
// on the kinds it takes, and the fallback to OpenCV on the others and on damaged files.
#include "vo/png_gray.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace rovo {
namespace {

namespace fs = std::filesystem;

// Half smooth gradient, half noise, with flat patches: libpng's adaptive filtering then picks
// several of the five row filters.
cv::Mat TestImage(int channels, uint64_t seed) {
  cv::Mat image(97, 131, CV_8UC(channels));
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  for (int y = 0; y < image.rows / 2; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      for (int c = 0; c < channels; ++c)
        image.ptr<uint8_t>(y)[x * channels + c] = static_cast<uint8_t>(x + 2 * y + 40 * c);
    }
  }
  cv::rectangle(image, cv::Rect(10, 60, 30, 20), cv::Scalar::all(77), cv::FILLED);
  return image;
}

std::vector<uint8_t> ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class PngGray : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rovo_png_gray_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const cv::Mat& image, const std::vector<int>& params = {}) {
    std::string path = (dir_ / name).string();
    EXPECT_TRUE(cv::imwrite(path, image, params)) << path;
    return path;
  }
  fs::path dir_;
};

TEST_F(PngGray, GrayAndRgbEqualOpenCvByteForByte) {
  for (const int channels : {1, 3}) {
    for (const int level : {0, 1, 6, 9}) {
      for (const int strategy :
           {cv::IMWRITE_PNG_STRATEGY_DEFAULT, cv::IMWRITE_PNG_STRATEGY_FILTERED, cv::IMWRITE_PNG_STRATEGY_RLE}) {
        const std::string path = Write("image.png", TestImage(channels, 10 + level),
                                       {cv::IMWRITE_PNG_COMPRESSION, level, cv::IMWRITE_PNG_STRATEGY, strategy});
        const std::vector<uint8_t> bytes = ReadBytes(path);
        const auto fast = DecodePngGrayFast(bytes.data(), bytes.size());
        ASSERT_TRUE(fast.has_value()) << "channels " << channels << " level " << level;
        const cv::Mat expected = cv::imread(path, cv::IMREAD_GRAYSCALE);
        ASSERT_EQ(fast->size(), expected.size());
        ASSERT_EQ(fast->type(), CV_8UC1);
        EXPECT_EQ(cv::countNonZero(*fast != expected), 0) << "channels " << channels << " level " << level;
        EXPECT_EQ(cv::countNonZero(ReadGrayImage(path) != expected), 0);
      }
    }
  }
}

// Other PNGs go to libpng, set up as OpenCV sets it up: the same image as OpenCV's; other formats
// (dataset images are PNG) are not read.
TEST_F(PngGray, OtherKindsGoToLibpngAsOpenCvReadsThem) {
  cv::Mat wide, gray_wide;
  TestImage(3, 3).convertTo(wide, CV_16UC3, 257.0);
  TestImage(1, 4).convertTo(gray_wide, CV_16UC1, 251.0);
  const std::vector<std::string> paths = {Write("rgba.png", TestImage(4, 1)), Write("wide.png", wide),
                                          Write("gray_wide.png", gray_wide)};
  EXPECT_TRUE(ReadGrayImage(Write("image.jpg", TestImage(3, 2))).empty());
  for (const std::string& path : paths) {
    const std::vector<uint8_t> bytes = ReadBytes(path);
    EXPECT_FALSE(DecodePngGrayFast(bytes.data(), bytes.size()).has_value()) << path;
    const cv::Mat expected = cv::imread(path, cv::IMREAD_GRAYSCALE);
    const cv::Mat read = ReadGrayImage(path);
    ASSERT_EQ(read.size(), expected.size()) << path;
    EXPECT_EQ(cv::countNonZero(read != expected), 0) << path;
    const cv::Mat colour = ReadImageAnyColour(path), expected_colour = cv::imread(path, cv::IMREAD_ANYCOLOR);
    ASSERT_EQ(colour.type(), expected_colour.type()) << path;
    EXPECT_EQ(cv::norm(colour, expected_colour, cv::NORM_INF), 0.0) << path;
  }
}

TEST_F(PngGray, DamagedOrMissingFilesAreNotDecodedByTheFastPath) {
  const std::string path = Write("image.png", TestImage(3, 5));
  std::vector<uint8_t> bytes = ReadBytes(path);
  ASSERT_TRUE(DecodePngGrayFast(bytes.data(), bytes.size()).has_value());
  for (const size_t at : {size_t{0}, size_t{20}, bytes.size() / 2, bytes.size() - 5}) {
    std::vector<uint8_t> damaged = bytes;
    damaged[at] ^= 0x5a;
    EXPECT_FALSE(DecodePngGrayFast(damaged.data(), damaged.size()).has_value()) << "byte " << at;
  }
  for (const size_t keep : {size_t{0}, size_t{7}, size_t{40}, bytes.size() - 12}) {
    EXPECT_FALSE(DecodePngGrayFast(bytes.data(), keep).has_value()) << "first " << keep << " bytes";
  }
  EXPECT_TRUE(ReadGrayImage((dir_ / "missing.png").string()).empty());
}

}  // namespace
}  // namespace rovo
