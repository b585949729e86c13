#pragma once
// The fuzz targets' independent gray decoder: OpenCV's, without the eXIf orientation it would apply
// (rovo keeps pixels as stored). Empty when OpenCV cannot read the bytes (it throws on no bytes), and
// for a PNG whose chunk list rovo refuses (PngChunkProblem): OpenCV's libpng would allocate a chunk's
// stated length first, up to 4 GB, and time out.
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "datasets/io.h"

namespace rovo::fuzz {

inline cv::Mat OpenCvGray(const uint8_t* data, size_t size) {
  if (size == 0 || !PngChunkProblem(data, size).empty()) return cv::Mat();
  try {
    return cv::imdecode(cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<uint8_t*>(data)),
                        cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION);
  } catch (const cv::Exception&) {
    return cv::Mat();
  }
}

}  // namespace rovo::fuzz
