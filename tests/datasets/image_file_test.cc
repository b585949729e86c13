// datasets/image_file.h against OpenCV's codecs (libpng and OpenEXR set up by another project).
#include "datasets/image_file.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
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

#include "datasets/io.h"

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

// PNG's CRC-32 (for a test to restate a chunk it changed).
uint32_t Crc32(const char* data, size_t size) {
  uint32_t crc = 0xffffffffu;
  for (size_t i = 0; i < size; ++i) {
    crc ^= static_cast<uint8_t>(data[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// What cv::imread gives with `flags` (without applying an eXIf orientation, which rovo ignores), in
// rovo's channel order (RGB).
cv::Mat OpenCvRgb(const std::string& path, int flags) {
  cv::Mat image = cv::imread(path, flags | cv::IMREAD_IGNORE_ORIENTATION);
  if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_BGR2RGB);
  return image;
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

// The fuzz corpus holds the PNG kinds cv::imwrite does not write (palette with tRNS, gray + alpha,
// 1-bit gray): both modes as OpenCV reads them.
TEST_F(ImageFileTest, EveryCorpusPngReadsAsOpenCvReadsIt) {
  int compared = 0;
  for (const auto& entry : fs::directory_iterator(std::string(ROVO_TEST_DATA_DIR) + "/../fuzz/corpus/image_file")) {
    const std::string path = entry.path().string();
    // (Not the PNG whose chunk claims 1.7 GB, which OpenCV's libpng would allocate.)
    if (entry.path().extension() != ".png" || !PngChunkProblem(path).empty()) continue;
    if (cv::imread(path, cv::IMREAD_GRAYSCALE).empty()) continue;
    EXPECT_TRUE(Equal(AsMat(ReadPng8(path, {1, false})), OpenCvRgb(path, cv::IMREAD_GRAYSCALE))) << path;
    EXPECT_TRUE(Equal(AsMat(ReadPng8(path, {0, false})), OpenCvRgb(path, cv::IMREAD_ANYCOLOR))) << path;
    ++compared;
  }
  EXPECT_GE(compared, 6);
}

// Flat images compress by hundreds: the size guard counts the stored rows, not the decoded pixels.
TEST_F(ImageFileTest, FlatAndBilevelImagesDecode) {
  WritePng8(Path("black.png"), 1920, 1080, 1, std::vector<uint8_t>(1920 * 1080, 0), "x", 12);
  ASSERT_LT(fs::file_size(Path("black.png")), 1920u * 1080u * 3u / 1100u);
  const Image8 black = ReadPng8(Path("black.png"), {3, true});
  EXPECT_EQ(black.pixels, std::vector<uint8_t>(1920 * 1080 * 3, 0));
  cv::Mat mask(1000, 1000, CV_8UC1, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(100, 200, 300, 400), cv::Scalar(255), cv::FILLED);
  ASSERT_TRUE(cv::imwrite(Path("mask.png"), mask, {cv::IMWRITE_PNG_BILEVEL, 1, cv::IMWRITE_PNG_COMPRESSION, 9}));
  EXPECT_EQ(ReadImageHeader(Path("mask.png")).bit_depth, 1);
  EXPECT_TRUE(Equal(AsMat(ReadPng8(Path("mask.png"), {1, false})), mask));
}

// Real cameras' JPEG frames (rovo study images): as OpenCV's libjpeg decodes them.
TEST_F(ImageFileTest, JpegReadsAsOpenCvReadsIt) {
  for (const auto& [name, type] :
       std::vector<std::pair<std::string, int>>{{"gray.jpg", CV_8UC1}, {"bgr.jpg", CV_8UC3}}) {
    const std::string path = WriteNoise(name, type, 9);
    const Image8 image = ReadPngOrJpeg8(path);
    EXPECT_TRUE(Equal(AsMat(image), OpenCvRgb(path, cv::IMREAD_UNCHANGED))) << name;
  }
  EXPECT_EQ(ReadPngOrJpeg8(WriteNoise("also.png", CV_8UC3, 1)).channels, 3);
  std::ofstream(Path("cut.jpg"), std::ios::binary).write("\xff\xd8\xff\xe0\x00\x10JFIF", 10);
  try {
    ReadPngOrJpeg8(Path("cut.jpg"));
    ADD_FAILURE() << "a cut JPEG was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(Path("cut.jpg") + ": unreadable JPEG: ", 0), 0u) << e.what();
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

// A data window away from the origin and half samples, as other programs write them.
TEST_F(ImageFileTest, ExrDataWindowAndHalfChannels) {
  const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(9, 9)), data(Imath::V2i(-3, 5), Imath::V2i(2, 8));
  Imf::Header header(display, data);
  header.channels().insert("Y", Imf::Channel(Imf::HALF));
  std::vector<Imath::half> halves(6 * 4);
  for (size_t i = 0; i < halves.size(); ++i) halves[i] = static_cast<float>(i) * 0.5f;
  {
    Imf::OutputFile file(Path("window.exr").c_str(), header);
    Imf::FrameBuffer frame;
    frame.insert("Y", Imf::Slice::Make(Imf::HALF, halves.data(), data));
    file.setFrameBuffer(frame);
    file.writePixels(4);
  }
  const FloatImage exr = ReadExr(Path("window.exr"));
  ASSERT_EQ(exr.width, 6);
  ASSERT_EQ(exr.height, 4);
  for (size_t i = 0; i < halves.size(); ++i) ASSERT_EQ(exr.planes[0][i], static_cast<float>(i) * 0.5f) << i;
  EXPECT_EQ(ReadImageHeader(Path("window.exr")).bit_depth, 16);
}

TEST_F(ImageFileTest, ExrWriteErrorsNameTheFileAndLeaveNothing) {
  std::ofstream(Path("blocker")) << "a file where a folder should be";
  EXPECT_THROW(WriteExrFloat(Path("blocker") + "/d.exr", 2, 2, std::vector<float>(4, 1.0f), "Z", "x"),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(Path("blocker") + "/d.exr"));
  EXPECT_THROW(WriteExrFloat(Path("d.exr"), 2, 2, std::vector<float>(3, 1.0f), "Z", "x"), std::invalid_argument);
  EXPECT_FALSE(fs::exists(Path("d.exr")));
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
  // A header that states far more pixels than the file can hold (its CRC restated), and one whose
  // CRC no longer matches.
  std::string huge = bytes;
  for (const int at : {16, 20}) {  // 900000 x 900000
    huge[at] = 0, huge[at + 1] = 0x0d, huge[at + 2] = static_cast<char>(0xbb), huge[at + 3] = static_cast<char>(0xa0);
  }
  const uint32_t crc = Crc32(huge.data() + 12, 17);
  for (int k = 0; k < 4; ++k) huge[29 + k] = static_cast<char>(crc >> (24 - 8 * k));
  const auto decode = [&](const std::string& png) {
    return message([&] { DecodePng8(reinterpret_cast<const uint8_t*>(png.data()), png.size(), {}, "mem.png"); });
  };
  EXPECT_NE(decode(huge).find("more than"), std::string::npos) << decode(huge);
  huge[29] ^= 1;
  EXPECT_NE(decode(huge).find("IHDR CRC error"), std::string::npos) << decode(huge);
  std::ofstream(Path("cut.exr"), std::ios::binary).write("\x76\x2f\x31\x01\x02\x00", 6);
  EXPECT_EQ(message([&] { ReadExr(Path("cut.exr")); }).rfind(Path("cut.exr") + ": unreadable OpenEXR file", 0), 0u);
}

}  // namespace
}  // namespace rovo
