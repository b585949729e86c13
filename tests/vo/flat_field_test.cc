// The flat-field correction (vo/flat_field.h) against its closed form: a uniformly lit scene seen
// through the lens's relative illumination E(theta) (datasets/FORMAT.md, section Optics) and encoded by
// the sensor's response curve comes back uniform.
#include "vo/flat_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

namespace rovo {
namespace {

Camera TestCamera() {
  Camera c;
  c.model = CameraModelId::kEquidistant;
  c.width = 320;
  c.height = 240;
  c.params = {50.0, 50.0, 160.0, 120.0, 0.0, 0.0, 0.0, 0.0};  // 50 px per radian: 96 px to the 110-degree rim
  c.max_fov_deg = 220.0;
  return c;
}

double Srgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

TEST(FlatField, UniformSceneComesBackUniform) {
  const Camera camera = TestCamera();
  const RelativeIllumination law{0.30, 0.40};  // the realistic profile: E = 0.20 at the rim
  const double theta_max = camera.max_fov_deg * M_PI / 360.0;
  constexpr double kRadiance = 0.5;
  const auto code = [](double linear) { return static_cast<int>(std::lround(255.0 * Srgb(linear))); };
  cv::Mat image(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
  double darkest = 1.0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const std::optional<Eigen::Vector3d> b = camera.Unproject(Eigen::Vector2d(x, y));
      if (!b) continue;
      const double theta = std::min(std::atan2(b->head<2>().norm(), b->z()), theta_max);
      darkest = std::min(darkest, law.At(theta, theta_max));
      image.at<uint8_t>(y, x) = static_cast<uint8_t>(code(kRadiance * law.At(theta, theta_max)));
    }
  }
  ASSERT_LT(darkest, 0.25);  // the rim is in the image
  const cv::Mat before = image.clone();
  FlatFieldCorrection(camera, law, "srgb").Apply(&image);
  int worst = 0, worst_before = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      if (!camera.Unproject(Eigen::Vector2d(x, y))) continue;
      worst = std::max(worst, std::abs(image.at<uint8_t>(y, x) - code(kRadiance)));
      worst_before = std::max(worst_before, std::abs(before.at<uint8_t>(y, x) - code(kRadiance)));
    }
  }
  // The input's rounding to 8 bits, magnified by the gain where the rim is darkest (at most 5x in
  // linear, about 2x in sRGB codes).
  EXPECT_LE(worst, 2);
  EXPECT_GE(worst_before, 80);
}

TEST(FlatField, LawMatchesTheFormatAndRejectsBadInput) {
  const RelativeIllumination law{0.30, 0.40};
  const double theta_max = 110.0 * M_PI / 180.0;
  EXPECT_DOUBLE_EQ(law.At(0.0, theta_max), 1.0);
  const double c = std::cos(0.30 * theta_max);
  EXPECT_NEAR(law.At(theta_max, theta_max), c * c * c * c * 0.40, 1e-12);
  EXPECT_FALSE(RelativeIllumination{}.Any());
  EXPECT_THROW(FlatFieldCorrection(TestCamera(), law, "gamma22"), std::invalid_argument);
  cv::Mat wrong(10, 10, CV_8UC1);
  EXPECT_THROW(FlatFieldCorrection(TestCamera(), law, "srgb").Apply(&wrong), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
