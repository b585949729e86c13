// Fuzz target: the image file readers (datasets/image_file.h): a PNG decoded from memory with every
// set of PngReadOptions and from its file, the header, the same bytes as a PNG or JPEG (by their
// signature) and as an OpenEXR file. Besides
// the error contract: a decoded PNG has the size of its header and the channels asked for, and
// whenever OpenCV's decoder reads the bytes as gray, they are read, and the gray decoding equals
// OpenCV's (libpng set up as OpenCV sets it up; no eXIf orientation applied).
#include "datasets/image_file.h"
#include "tests/fuzz/fuzz_util.h"
#include "tests/fuzz/opencv_gray.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("image_file");
  static const std::string dir = scratch.Fresh("images");
  const std::string png = dir + "/image.png", exr = dir + "/image.exr";
  rovo::fuzz::WriteBytes(png, data, size);
  rovo::fuzz::WriteBytes(exr, data, size);
  const cv::Mat expected = rovo::fuzz::OpenCvGray(data, size);
  const bool is_png = size >= 4 && data[1] == 'P' && data[2] == 'N' && data[3] == 'G';
  for (const int channels : {0, 1, 3}) {
    for (const bool round : {true, false}) {
      const bool read = rovo::fuzz::ExpectClearError({"memory.png"}, [&] {
        const rovo::Image8 image = rovo::DecodePng8(data, size, {channels, round}, "memory.png");
        const rovo::ImageHeader header = rovo::ReadImageHeader(png);
        if (image.width != header.width || image.height != header.height ||
            (channels != 0 && image.channels != channels) ||
            image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
          rovo::fuzz::Finding("decoded PNG of the wrong size", png);
        }
        if (channels == 1 && !round) {
          const cv::Mat ours(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data()));
          if (!expected.empty() && (expected.size() != ours.size() || cv::countNonZero(expected != ours) != 0)) {
            rovo::fuzz::Finding("gray PNG differs from OpenCV's", png);
          }
        }
      });
      if (!read && is_png && !expected.empty()) rovo::fuzz::Finding("a PNG OpenCV reads is refused", png);
    }
  }
  rovo::fuzz::ExpectClearError({png}, [&] { rovo::ReadPng8(png); });
  rovo::fuzz::ExpectClearError({png}, [&] {
    const rovo::Image8 image = rovo::ReadPngOrJpeg8(png);  // a JPEG when the bytes start as one
    if (image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
      rovo::fuzz::Finding("decoded image of the wrong size", png);
    }
  });
  rovo::fuzz::ExpectClearError({exr}, [&] {
    const rovo::FloatImage image = rovo::ReadExr(exr);
    for (const std::vector<float>& plane : image.planes) {
      if (plane.size() != static_cast<size_t>(image.width) * image.height) {
        rovo::fuzz::Finding("EXR plane of the wrong size", exr);
      }
    }
  });
  rovo::fuzz::ExpectClearError({exr}, [&] { rovo::ReadImageHeader(exr); });
  return 0;
}
