#pragma once
// Bilinear remap of 8-bit gray images through cv::convertMaps' fixed-point maps, with the pixels of
// cv::remap (OpenCV 4.6, x86-64) bit for bit, its inner loop in AVX2 gathers.
//
// OpenCV's arithmetic (modules/imgproc/src/imgwarp.cpp): map_fixed holds each pixel's integer source
// position (sx, sy), map_frac the index fy * 32 + fx of its fraction in 1/32 px; the four taps' weights
// are a 1024-entry table of 15-bit integers, and the pixel is (sum of tap * weight + 2^14) >> 15, with
// taps outside the image taken as the border value 0. Integer sums do not depend on their order, so
// sixteen pixels at a time give the same bytes as OpenCV's eight and its one-by-one border loop.

#include <opencv2/core.hpp>

namespace rovo {

// cv::remap(src, *dst, map_fixed, map_frac, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0)):
// computed here for 8-bit gray `src`, CV_16SC2 `map_fixed` and CV_16UC1 `map_frac` of the same size
// on a CPU with AVX2 (a row step below 32768 bytes, as OpenCV's SIMD path needs); by OpenCV otherwise.
// `dst` gets the maps' size (a region of that size is written in place).
void RemapBilinearGray(const cv::Mat& src, const cv::Mat& map_fixed, const cv::Mat& map_frac, cv::Mat* dst);

// Whether RemapBilinearGray computes these arguments itself (else it calls cv::remap).
bool RemapBilinearGrayApplies(const cv::Mat& src, const cv::Mat& map_fixed, const cv::Mat& map_frac,
                              const cv::Mat& dst);

}  // namespace rovo
