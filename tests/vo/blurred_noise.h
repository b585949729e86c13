#pragma once
// Texture for KLT and front-end tests and benchmarks: uniform noise in [0, 255) drawn from `rng` (which
// callers go on drawing from), blurred with a Gaussian of sigma 2 px and stretched back to 0..255.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace rovo {

inline cv::Mat BlurredNoise(int width, int height, cv::RNG& rng) {
  cv::Mat image(height, width, CV_8UC1);
  rng.fill(image, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  cv::normalize(image, image, 0, 255, cv::NORM_MINMAX);
  return image;
}

}  // namespace rovo
