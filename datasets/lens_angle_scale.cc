#include "datasets/lens_angle_scale.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

#include "datasets/ocam.h"

namespace rovo {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kMaxErrorDeg = 0.03;
constexpr int kSamples = 2000;
constexpr double kFovMarginDeg = 2.0 * kMaxErrorDeg;

AngleScaledLens ScaleEquidistant(const Camera& camera, double scale) {
  AngleScaledLens out{camera, 0.0};
  std::vector<double>& p = out.camera.params;
  p[0] /= scale;
  p[1] /= scale;
  double factor = 1.0;
  for (int i = 4; i < 8; ++i) {
    factor /= scale * scale;
    p[i] *= factor;
  }
  out.camera.max_fov_deg = camera.max_fov_deg * scale;
  return out;
}

double OcamForward(const std::vector<double>& a, double rho) {
  return a[0] + rho * (a[1] + rho * (a[2] + rho * (a[3] + rho * a[4])));
}

// The forward polynomial {a0..a4} whose angle from the axis, atan2(rho, -f(rho)), is `scale` times
// the given one's over rho in [0, rho_edge]: least squares on f, each sample off the axis weighted
// by d(angle)/d(f) so that the fit minimises angle errors, the axis sample (f(0) = a0 / scale) weighted
// 1 / |a0|, which pins it; all five coefficients are fitted (with a1 held at 0 the fit missed the
// scaled angles by 0.03 deg, with it 0.02 deg).
std::vector<double> ScaledOcamForward(const std::vector<double>& a, double rho_edge, double scale) {
  const std::vector<int> powers = {0, 1, 2, 3, 4};
  Eigen::MatrixXd design(kSamples + 1, static_cast<int>(powers.size()));
  Eigen::VectorXd target(kSamples + 1);
  for (int i = 0; i <= kSamples; ++i) {
    const double rho = rho_edge * i / kSamples;
    const double alpha = std::atan2(rho, -OcamForward(a, rho)) * scale;
    // f = -rho cot(alpha'), and f(0) = a0 / scale (the slope of alpha' at the axis).
    const double f = i == 0 ? a[0] / scale : -rho * std::cos(alpha) / std::sin(alpha);
    const double weight = i == 0 ? 1.0 / std::abs(a[0]) : rho / (rho * rho + f * f);
    for (size_t k = 0; k < powers.size(); ++k) design(i, k) = weight * std::pow(rho / rho_edge, powers[k]);
    target(i) = weight * f;
  }
  const Eigen::VectorXd coef = design.colPivHouseholderQr().solve(target);
  std::vector<double> out(5, 0.0);
  for (size_t k = 0; k < powers.size(); ++k) out[powers[k]] = coef(k) / std::pow(rho_edge, powers[k]);
  return out;
}

AngleScaledLens ScaleOcam(const Camera& camera, double scale) {
  const std::vector<double>& p = camera.params;
  double rho_edge = 0.0;
  std::string problem;
  if (!OcamForwardMonotonic(p, camera.max_fov_deg, &rho_edge, &problem)) {
    throw std::invalid_argument("ScaleLensAngles: ocam lens: " + problem);
  }
  const std::vector<double> a(p.begin() + 5, p.begin() + 10);
  const std::vector<double> scaled = ScaledOcamForward(a, rho_edge, scale);
  AngleScaledLens out;
  // The field of view keeps its rim pixels despite the refit's error (kFovMarginDeg).
  out.camera = MakeOcamCamera(camera.width, camera.height, p[0], p[1], p[2], p[3], p[4], scaled,
                              camera.max_fov_deg * scale + kFovMarginDeg);
  for (int i = 1; i <= kSamples; ++i) {
    const double rho = rho_edge * i / kSamples;
    const double wanted = std::atan2(rho, -OcamForward(a, rho)) * scale;
    const double fitted = std::atan2(rho, -OcamForward(scaled, rho));
    out.max_error_deg = std::max(out.max_error_deg, std::abs(fitted - wanted) * kRadToDeg);
  }
  return out;
}

}  // namespace

AngleScaledLens ScaleLensAngles(const Camera& camera, double scale) {
  if (!(scale >= 0.9 && scale <= 1.1)) {
    throw std::invalid_argument("ScaleLensAngles: scale " + std::to_string(scale) + " outside [0.9, 1.1]");
  }
  AngleScaledLens out;
  switch (camera.model) {
    case CameraModelId::kEquidistant:
      out = ScaleEquidistant(camera, scale);
      break;
    case CameraModelId::kOcam:
      out = ScaleOcam(camera, scale);
      break;
    default:
      throw std::invalid_argument("ScaleLensAngles: the " + CameraModelName(camera.model) +
                                  " model has no angle-scaled form (equidistant and ocam have)");
  }
  if (!(out.max_error_deg <= kMaxErrorDeg)) {
    throw std::invalid_argument("ScaleLensAngles: the refitted lens misses the scaled angles by " +
                                std::to_string(out.max_error_deg) + " deg (more than " + std::to_string(kMaxErrorDeg) +
                                ")");
  }
  return out;
}

Rig WithLensAngleScale(const Rig& rig, double scale, double* max_error_deg) {
  if (max_error_deg) *max_error_deg = 0.0;
  if (scale == 1.0) return rig;
  Rig out = rig;
  for (size_t j = 0; j < rig.cameras.size(); ++j) {
    try {
      const AngleScaledLens lens = ScaleLensAngles(rig.cameras[j].camera, scale);
      out.cameras[j].camera = lens.camera;
      if (max_error_deg) *max_error_deg = std::max(*max_error_deg, lens.max_error_deg);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("camera " + rig.cameras[j].name + ": " + e.what());
    }
  }
  return out;
}

}  // namespace rovo
