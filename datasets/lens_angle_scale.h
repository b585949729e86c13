#pragma once
// A lens whose angles off the optical axis are those of a given lens times one scale: the
// correction the start-up calibration estimates when a real rig's lens calibration understates (or
// overstates) angles near the rim (vo/ring_calibration.h, RingCalibrationReport::angle_scale).
//
// The scaled lens maps a bearing at angle alpha from the axis (azimuth phi) to the pixel where the
// given lens maps the bearing at alpha / scale (azimuth phi): pixels keep their place, and every
// pixel's bearing turns away from the axis by the factor `scale`. The field of view grows by it too
// (an ocam lens's by 0.06 deg more, so that the refit's error keeps its rim pixels).
//   equidistant: exact, r(alpha) = f d(alpha / scale) gives fx, fy / scale and k_i / scale^(2i).
//   ocam: the forward polynomial is refitted by least squares to alpha'(rho) = scale alpha(rho) over
//         the sensor radii of the field of view (all of a0..a4), the inverse polynomial
//         fitted to it (FitOcamInversePolynomial); the largest angle error is reported.
//   double sphere, extended unified: no such form (std::invalid_argument).

#include "datasets/camera.h"
#include "datasets/rig.h"

namespace rovo {

struct AngleScaledLens {
  Camera camera;
  double max_error_deg = 0.0;  // largest |alpha'(pixel) - scale alpha(pixel)| over the field of view
};

// Throws std::invalid_argument for a scale outside [0.9, 1.1], a model without a scaled form, or a
// refit that misses the scaled angles by more than 0.03 deg (the ocam forward polynomial of
// degree 4 reaches 0.02 deg for a scale of 1.016).
AngleScaledLens ScaleLensAngles(const Camera& camera, double scale);

// Every camera's lens scaled (extrinsics unchanged); `max_error_deg` (optional) receives the largest
// error over the cameras. A scale of exactly 1 returns `rig` unchanged.
Rig WithLensAngleScale(const Rig& rig, double scale, double* max_error_deg = nullptr);

}  // namespace rovo
