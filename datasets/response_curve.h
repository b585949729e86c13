#pragma once
// Camera response curves, y = CRF(v) for v in [0, 1] (v = DN / (2^b - 1)): the sensor model's
// encoding (render/sensor.h) and dataset.json sensor.response, which the VO's flat-field correction
// decodes (vo/flat_field.h).
//   kSrgb:   IEC 61966-2-1: 12.92 v for v <= 0.0031308, else 1.055 v^(1/2.4) - 0.055
//   kBt709:  ITU-R BT.709 camera OETF: 4.5 v for v < 0.018, else 1.099 v^0.45 - 0.099
//   kLinear: v

#include <string>

namespace rovo {

enum class ResponseCurve { kSrgb, kBt709, kLinear };
std::string ResponseCurveName(ResponseCurve curve);
// Throws std::invalid_argument listing the names (srgb, bt709, linear).
ResponseCurve ResponseCurveFromName(const std::string& name);
double ApplyResponseCurve(ResponseCurve curve, double v);  // v clamped to [0, 1]

}  // namespace rovo
