#pragma once
// The fuzz targets' independent gray decoder of PNGs: OpenCV's, without the eXIf orientation it would
// apply (rovo keeps pixels as stored). Empty when OpenCV cannot read the bytes, for other formats
// (OpenCV's other decoders, GDCM's DICOM among them, allocate gigabytes on some inputs), and for a PNG
// whose chunk list rovo refuses (PngChunkProblem): OpenCV's libpng would allocate a chunk's stated
// length first, up to 4 GB, and time out.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "datasets/io.h"

namespace rovo::fuzz {

inline cv::Mat OpenCvGray(const uint8_t* data, size_t size) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  const bool png = size >= 8 && std::memcmp(data, kSignature, 8) == 0;  // else OpenCV tries GDCM, which asserts
  if (!png || !PngChunkProblem(data, size).empty()) return cv::Mat();
  try {
    return cv::imdecode(cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<uint8_t*>(data)),
                        cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION);
  } catch (const cv::Exception&) {
    return cv::Mat();
  }
}

}  // namespace rovo::fuzz
