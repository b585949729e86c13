// datasets/image_file.h against OpenCV's codecs (libpng and OpenEXR set up by another project).
#include "datasets/image_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

namespace rovo {
namespace {

namespace fs = std::filesystem;

class ImageFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rovo_image_file_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // A noisy image of `type` written by OpenCV as PNG; returns its path.
  std::string WriteNoise(const std::string& name, int type, uint32_t seed) {
    cv::Mat image(23, 37, type);
    cv::RNG rng(seed);
    rng.fill(image, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
    EXPECT_TRUE(cv::imwrite(Path(name), image));
    return Path(name);
  }

  fs::path dir_;
};

cv::Mat AsMat(const Image8& image) {
  return cv::Mat(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
}

bool Equal(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST_F(ImageFileTest, GrayReadsAsOpenCvReadsItFromEveryKindOfPng) {
  for (const auto& [name, type] : std::vector<std::pair<std::string, int>>{{"gray.png", CV_8UC1},
                                                                           {"bgr.png", CV_8UC3},
                                                                           {"bgra.png", CV_8UC4},
                                                                           {"gray16.png", CV_16UC1},
                                                                           {"bgr16.png", CV_16UC3}}) {
    const std::string path = WriteNoise(name, type, 7);
    const cv::Mat expected = cv::imread(path, cv::IMREAD_GRAYSCALE);
    EXPECT_TRUE(Equal(AsMat(ReadPng8(path, {1, false})), expected)) << name;
    cv::Mat colour = cv::imread(path, cv::IMREAD_ANYCOLOR);
    if (colour.channels() == 3) cv::cvtColor(colour, colour, cv::COLOR_BGR2RGB);
    EXPECT_TRUE(Equal(AsMat(ReadPng8(path, {0, false})), colour)) << name;
  }
}

TEST_F(ImageFileTest, SixteenBitSamplesRoundOrKeepTheirHighByte) {
  const std::string path = WriteNoise("gray16.png", CV_16UC1, 3);
  const cv::Mat wide = cv::imread(path, cv::IMREAD_UNCHANGED);
  cv::Mat rounded;
  wide.convertTo(rounded, CV_8U, 1.0 / 257.0);
  EXPECT_TRUE(Equal(AsMat(ReadPng8(path, {1, true})), rounded));
  const Image8 rgb = ReadPng8(path, {3, true});
  ASSERT_EQ(rgb.channels, 3);
  for (size_t i = 0; i < rgb.pixels.size(); i += 3) {
    ASSERT_EQ(rgb.pixels[i], rgb.pixels[i + 1]);
    ASSERT_EQ(rgb.pixels[i], rgb.pixels[i + 2]);
  }
}

TEST_F(ImageFileTest, HeadersOfPngAndExr) {
  ImageHeader h = ReadImageHeader(WriteNoise("bgra.png", CV_8UC4, 1));
  EXPECT_EQ(h.width, 37);
  EXPECT_EQ(h.height, 23);
  EXPECT_EQ(h.channels, 4);
  EXPECT_EQ(h.bit_depth, 8);
  h = ReadImageHeader(WriteNoise("gray16.png", CV_16UC1, 1));
  EXPECT_EQ(h.channels, 1);
  EXPECT_EQ(h.bit_depth, 16);
  const std::vector<float> depth(5 * 4, 2.5f);
  WriteExrFloat(Path("d.exr"), 5, 4, depth, "Z", "rovo test");
  h = ReadImageHeader(Path("d.exr"));
  EXPECT_EQ(h.width, 5);
  EXPECT_EQ(h.height, 4);
  EXPECT_EQ(h.channels, 1);
  EXPECT_EQ(h.bit_depth, 32);
}

TEST_F(ImageFileTest, ExrRoundTripsExactly) {
  std::vector<float> values(31 * 17);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uniform(0.0f, 1000.0f);
  for (float& v : values) v = uniform(rng);
  values[3] = std::numeric_limits<float>::infinity();
  WriteExrFloat(Path("z.exr"), 31, 17, values, "Z", "rovo test");
  const FloatImage exr = ReadExr(Path("z.exr"));
  ASSERT_EQ(exr.Channel("Z"), 0);
  EXPECT_EQ(exr.Channel("R"), -1);
  EXPECT_EQ(exr.width, 31);
  EXPECT_EQ(exr.height, 17);
  EXPECT_EQ(exr.planes[0], values);
}

TEST_F(ImageFileTest, PngRoundTripsThroughTheWriter) {
  std::vector<uint8_t> rgb(9 * 4 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 37);
  WritePng8(Path("w.png"), 9, 4, 3, rgb, "rovo test");
  EXPECT_EQ(ReadPng8(Path("w.png"), {3, true}).pixels, rgb);
  cv::Mat by_opencv = cv::imread(Path("w.png"), cv::IMREAD_UNCHANGED);
  cv::cvtColor(by_opencv, by_opencv, cv::COLOR_BGR2RGB);
  EXPECT_TRUE(Equal(by_opencv, AsMat(ReadPng8(Path("w.png")))));
  EXPECT_THROW(WritePng8(Path("bad.png"), 9, 4, 3, std::vector<uint8_t>(5), "x"), std::invalid_argument);
}

TEST_F(ImageFileTest, BadFilesNameTheFileAndTheProblem) {
  std::ofstream(Path("text.png")) << "this is not a PNG\n";
  const auto message = [](const std::function<void()>& read) {
    try {
      read();
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([&] { ReadPng8(Path("text.png")); }), Path("text.png") + ": not a PNG file");
  EXPECT_EQ(message([&] { ReadImageHeader(Path("text.png")); }), Path("text.png") + ": not a PNG or OpenEXR file");
  EXPECT_NE(message([&] { ReadPng8(Path("missing.png")); }).find(Path("missing.png")), std::string::npos);
  // A PNG cut in the middle of its image data.
  const std::string good = WriteNoise("cut.png", CV_8UC3, 2);
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(Path("cut.png"), std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  EXPECT_EQ(message([&] { ReadPng8(Path("cut.png")); }).rfind(Path("cut.png") + ": unreadable PNG: ", 0), 0u);
  // A header that states far more pixels than the file can hold.
  std::string huge = bytes;
  huge[16] = 0x7f;  // width 2^30 and more
  EXPECT_NE(message([&] {
              DecodePng8(reinterpret_cast<const uint8_t*>(huge.data()), huge.size(), {}, "huge");
            }).find("more than"),
            std::string::npos);
  std::ofstream(Path("cut.exr"), std::ios::binary).write("\x76\x2f\x31\x01\x02\x00", 6);
  EXPECT_EQ(message([&] { ReadExr(Path("cut.exr")); }).rfind(Path("cut.exr") + ": unreadable OpenEXR file", 0), 0u);
}

}  // namespace
}  // namespace rovo
