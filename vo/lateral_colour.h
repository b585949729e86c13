#pragma once
// Undoing a lens's lateral colour before the VO turns a colour image gray. A lens whose red and blue
// planes are magnified about the principal point relative to green (datasets/FORMAT.md, section
// Optics: R'(p) = R(p0 + (p - p0) / (1 + a_red))) moves the gray edge of a coloured surface by a share
// of a_red and a_blue that depends on its colours, a per-feature error that no camera model absorbs.
// The correction resamples red and blue back onto green, R(p) = R'(p0 + (p - p0) (1 + a_red)), as
// photo tools do with a lens profile's transverse chromatic aberration (lensfun's "TCA" model), and
// converts to gray afterwards.

#include <opencv2/core.hpp>

#include "datasets/camera.h"

namespace rovo {

// Magnification of the red and blue planes relative to green, minus 1 (dataset.json optics
// lateral_ca_red, lateral_ca_blue).
struct LateralColour {
  double red = 0.0;
  double blue = 0.0;
  bool Any() const { return red != 0.0 || blue != 0.0; }
};

class LateralColourCorrection {
 public:
  // The resampling maps of `camera`'s image (about p0 = the projection of the optical axis, the
  // image centre when the axis does not project), computed once.
  LateralColourCorrection(const Camera& camera, LateralColour colour);

  // An 8-bit BGR image of the camera's size, its red and blue planes resampled (bilinear; a pixel
  // whose source lies outside the image keeps its value), converted to gray as
  // cv::cvtColor(COLOR_BGR2GRAY) converts. Throws std::invalid_argument on another size or type.
  cv::Mat ToGray(const cv::Mat& bgr) const;

  const LateralColour& colour() const { return colour_; }
  int width() const { return size_.width; }
  int height() const { return size_.height; }

 private:
  LateralColour colour_;
  cv::Size size_;
  cv::Mat red_map_[2], blue_map_[2];  // fixed-point maps of cv::convertMaps (CV_16SC2, CV_16UC1)
};

}  // namespace rovo
