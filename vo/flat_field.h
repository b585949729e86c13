#pragma once
// Undoing a lens's relative illumination (vignetting) before the VO sees an image: a flat-field
// correction from the lens profile. The realistic lens darkens the rim to a fifth of the centre
// (datasets/FORMAT.md, section Optics: E(theta) = cos^4(k theta) (1 - (1 - rim_illumination) u^2)),
// and the ring overlaps the start-up calibration matches lie there, 90-115 degrees off the axis; in
// dark scenes their corners then sink below the detector's threshold. The correction decodes each
// 8-bit value through the sensor's response curve, divides the linear value by E and encodes it
// again (clipped), so edges at the rim get their contrast back (and their noise with it).

#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "datasets/camera.h"

namespace rovo {

// dataset.json optics falloff_angle_scale (k) and rim_illumination; none when k = 0 and rim = 1.
struct RelativeIllumination {
  double falloff_angle_scale = 0.0;
  double rim_illumination = 1.0;
  bool Any() const { return falloff_angle_scale != 0.0 || rim_illumination != 1.0; }
  // E at `theta` radians off the axis of a lens whose field reaches theta_max.
  double At(double theta, double theta_max) const;
};

class FlatFieldCorrection {
 public:
  // The gain 1 / E of every pixel of `camera` (1 where it sees nothing), and the response curve's
  // tables ("srgb", "bt709" or "linear", dataset.json sensor.response); throws std::invalid_argument
  // on another curve name.
  FlatFieldCorrection(const Camera& camera, RelativeIllumination law, const std::string& response);

  // An 8-bit gray image of the camera's size, corrected in place. Throws std::invalid_argument on
  // another size or type.
  void Apply(cv::Mat* gray) const;

 private:
  cv::Size size_;
  std::vector<float> gain_;          // row-major, one per pixel
  std::array<float, 256> decode_{};  // 8-bit code -> linear [0, 1]
  std::vector<uint8_t> encode_;      // linear in [0, 1] at kEncodeSteps + 1 points -> 8-bit code
};

}  // namespace rovo
