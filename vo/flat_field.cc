#include "vo/flat_field.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "datasets/optics_record.h"
#include "datasets/response_curve.h"

namespace rovo {
namespace {

constexpr int kEncodeSteps = 65535;

// The inverse of the response curve, by bisection (the curves are increasing).
double Decode(ResponseCurve curve, double y) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ApplyResponseCurve(curve, mid) < y ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double RelativeIllumination::At(double theta, double theta_max) const {
  return RelativeIlluminationAt(falloff_angle_scale, rim_illumination, theta, theta_max);
}

FlatFieldCorrection::FlatFieldCorrection(const Camera& camera, RelativeIllumination law, const std::string& response)
    : size_(camera.width, camera.height), encode_(kEncodeSteps + 1) {
  const ResponseCurve curve = ResponseCurveFromName(response);  // throws on an unknown name
  for (int code = 0; code < 256; ++code) decode_[code] = static_cast<float>(Decode(curve, code / 255.0));
  for (int i = 0; i <= kEncodeSteps; ++i) {
    const double y = ApplyResponseCurve(curve, static_cast<double>(i) / kEncodeSteps);
    encode_[i] = static_cast<uint8_t>(std::clamp(std::lround(255.0 * y), 0L, 255L));
  }
  const double theta_max = camera.max_fov_deg * M_PI / 360.0;
  gain_.assign(static_cast<size_t>(camera.width) * camera.height, 1.0f);
  tbb::parallel_for(0, camera.height, [&](int y) {
    for (int x = 0; x < camera.width; ++x) {
      const std::optional<Eigen::Vector3d> bearing = camera.Unproject(Eigen::Vector2d(x, y));
      if (!bearing) continue;
      const double theta = std::atan2(bearing->head<2>().norm(), bearing->z());
      const double e = law.At(std::min(theta, theta_max), theta_max);
      if (e > 0.0) gain_[static_cast<size_t>(y) * camera.width + x] = static_cast<float>(1.0 / e);
    }
  });
}

void FlatFieldCorrection::Apply(cv::Mat* gray) const {
  if (gray->type() != CV_8UC1 || gray->size() != size_) {
    throw std::invalid_argument("FlatFieldCorrection: expected an 8-bit gray image of " + std::to_string(size_.width) +
                                "x" + std::to_string(size_.height));
  }
  for (int y = 0; y < size_.height; ++y) {
    uint8_t* row = gray->ptr<uint8_t>(y);
    const float* gain = gain_.data() + static_cast<size_t>(y) * size_.width;
    for (int x = 0; x < size_.width; ++x) {
      const float linear = std::min(1.0f, decode_[row[x]] * gain[x]);
      // NOLINTNEXTLINE(bugprone-incorrect-roundings): linear >= 0, where adding 0.5 rounds correctly.
      row[x] = encode_[static_cast<size_t>(linear * kEncodeSteps + 0.5f)];
    }
  }
}

}  // namespace rovo
