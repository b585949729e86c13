#include "datasets/response_curve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rovo {

std::string ResponseCurveName(ResponseCurve curve) {
  switch (curve) {
    case ResponseCurve::kSrgb:
      return "srgb";
    case ResponseCurve::kBt709:
      return "bt709";
    case ResponseCurve::kLinear:
      return "linear";
  }
  return "srgb";
}

ResponseCurve ResponseCurveFromName(const std::string& name) {
  if (name == "srgb") return ResponseCurve::kSrgb;
  if (name == "bt709") return ResponseCurve::kBt709;
  if (name == "linear") return ResponseCurve::kLinear;
  throw std::invalid_argument("--response '" + name + "': unknown response curve (known: srgb, bt709, linear)");
}

double ApplyResponseCurve(ResponseCurve curve, double v) {
  v = std::clamp(v, 0.0, 1.0);
  switch (curve) {
    case ResponseCurve::kSrgb:
      return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    case ResponseCurve::kBt709:
      return v < 0.018 ? 4.5 * v : 1.099 * std::pow(v, 0.45) - 0.099;
    case ResponseCurve::kLinear:
      return v;
  }
  return v;
}

}  // namespace rovo
