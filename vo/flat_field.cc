#include "vo/flat_field.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace rovo {
namespace {

constexpr int kEncodeSteps = 65535;

// The sensor's response curve y = CRF(v) of linear v in [0, 1] (render/sensor.h states the same curves).
double Encode(const std::string& response, double v) {
  if (response == "srgb") return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  if (response == "bt709") return v < 0.018 ? 4.5 * v : 1.099 * std::pow(v, 0.45) - 0.099;
  if (response == "linear") return v;
  throw std::invalid_argument("flat-field correction: unknown response curve '" + response +
                              "' (dataset.json sensor.response: srgb, bt709 or linear)");
}

// Its inverse, by bisection (the curves are increasing).
double Decode(const std::string& response, double y) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (Encode(response, mid) < y ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double RelativeIllumination::At(double theta, double theta_max) const {
  const double u = theta / theta_max;
  const double c = std::cos(falloff_angle_scale * theta);
  return c * c * c * c * (1.0 - (1.0 - rim_illumination) * u * u);
}

FlatFieldCorrection::FlatFieldCorrection(const Camera& camera, RelativeIllumination law, const std::string& response)
    : size_(camera.width, camera.height), encode_(kEncodeSteps + 1) {
  for (int code = 0; code < 256; ++code) decode_[code] = static_cast<float>(Decode(response, code / 255.0));
  for (int i = 0; i <= kEncodeSteps; ++i) {
    const double y = Encode(response, static_cast<double>(i) / kEncodeSteps);
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
