#include "vo/lateral_colour.h"

#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "vo/opencv_threads.h"

namespace rovo {
namespace {

// The map of a plane magnified by (1 + a) about p0: destination p samples p0 + (p - p0) (1 + a).
void MagnificationMap(const cv::Size& size, const Eigen::Vector2d& p0, double a, cv::Mat map[2]) {
  cv::Mat map_x(size, CV_32FC1), map_y(size, CV_32FC1);
  const double s = 1.0 + a;
  for (int y = 0; y < size.height; ++y) {
    auto* mx = map_x.ptr<float>(y);
    auto* my = map_y.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      mx[x] = static_cast<float>(p0.x() + (x - p0.x()) * s);
      my[x] = static_cast<float>(p0.y() + (y - p0.y()) * s);
    }
  }
  cv::convertMaps(map_x, map_y, map[0], map[1], CV_16SC2);
}

}  // namespace

LateralColourCorrection::LateralColourCorrection(const Camera& camera, LateralColour colour)
    : colour_(colour), size_(camera.width, camera.height) {
  const std::optional<Eigen::Vector2d> axis = camera.Project(Eigen::Vector3d::UnitZ());
  const Eigen::Vector2d p0 = axis ? *axis : Eigen::Vector2d(0.5 * (camera.width - 1), 0.5 * (camera.height - 1));
  if (colour_.red != 0.0) MagnificationMap(size_, p0, colour_.red, red_map_);
  if (colour_.blue != 0.0) MagnificationMap(size_, p0, colour_.blue, blue_map_);
}

cv::Mat LateralColourCorrection::ToGray(const cv::Mat& bgr) const {
  if (bgr.type() != CV_8UC3 || bgr.size() != size_) {
    throw std::invalid_argument("LateralColourCorrection: expected an 8-bit BGR image of " +
                                std::to_string(size_.width) + "x" + std::to_string(size_.height));
  }
  // OpenCV serial while this runs: the prefetch thread calls it beside another run's front-end, and
  // OpenCV's thread pool must not be reset under a running call (vo/opencv_threads.h).
  const ScopedOpenCvThreads serial_opencv;
  cv::Mat planes[3];
  cv::split(bgr, planes);
  const auto resample = [&](int channel, const cv::Mat map[2]) {
    if (map[0].empty()) return;
    cv::Mat corrected = planes[channel].clone();  // BORDER_TRANSPARENT keeps it where the source is outside
    cv::remap(planes[channel], corrected, map[0], map[1], cv::INTER_LINEAR, cv::BORDER_TRANSPARENT);
    planes[channel] = corrected;
  };
  resample(2, red_map_);
  resample(0, blue_map_);
  cv::Mat merged, gray;
  cv::merge(planes, 3, merged);
  cv::cvtColor(merged, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

}  // namespace rovo
