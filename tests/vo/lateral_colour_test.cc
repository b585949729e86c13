// Undoing lateral colour (vo/lateral_colour.h) against its closed form: rings f(r) about the principal
// point, with red and blue magnified as datasets/FORMAT.md's lens does (R'(p) = f(|p - p0| / (1 + a))),
// come back as f(r) in all three planes; and FrameReader (vo/image_loader.h) reads colour images
// through it and gray ones as they are.
#include "vo/lateral_colour.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "vo/image_loader.h"

namespace rovo {
namespace {

constexpr int kWidth = 320, kHeight = 240;
const Eigen::Vector2d kP0(170.3, 115.6);

Camera TestCamera() {
  Camera c;
  c.model = CameraModelId::kEquidistant;
  c.width = kWidth;
  c.height = kHeight;
  c.params = {90.0, 90.0, kP0.x(), kP0.y(), 0.0, 0.0, 0.0, 0.0};
  c.max_fov_deg = 220.0;
  return c;
}

double Rings(double r) { return 128.0 + 100.0 * std::sin(2.0 * M_PI * r / 24.0); }

// Each plane f(|p - p0| / (1 + a_plane)): the image of rings through a lens with lateral colour.
cv::Mat RingsThroughLens(LateralColour colour) {
  cv::Mat bgr(kHeight, kWidth, CV_8UC3);
  const double a[3] = {colour.blue, 0.0, colour.red};  // B, G, R
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double r = (Eigen::Vector2d(x, y) - kP0).norm();
      for (int c = 0; c < 3; ++c) bgr.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uint8_t>(Rings(r / (1.0 + a[c])));
    }
  }
  return bgr;
}

cv::Mat Gray(const cv::Mat& bgr) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

// Largest difference over pixels at least `margin` inside the image.
double MaxDiffInside(const cv::Mat& a, const cv::Mat& b, int margin) {
  const cv::Rect inner(margin, margin, kWidth - 2 * margin, kHeight - 2 * margin);
  double max_diff = 0.0;
  cv::minMaxLoc(cv::abs(cv::Mat_<int>(a(inner)) - cv::Mat_<int>(b(inner))), nullptr, &max_diff);
  return max_diff;
}

TEST(LateralColour, UndoesTheMagnificationOfRedAndBlue) {
  const LateralColour colour{0.01, -0.015};  // 1.7 px and 2.6 px at the corners' 170 px
  const cv::Mat truth = Gray(RingsThroughLens({}));
  const cv::Mat through_lens = RingsThroughLens(colour);
  const LateralColourCorrection correction(TestCamera(), colour);
  const cv::Mat corrected = correction.ToGray(through_lens);
  // Bilinear resampling of rings 24 px apart (peak slope 26 codes/px) plus the 8-bit rounding of the input.
  EXPECT_LE(MaxDiffInside(corrected, truth, 4), 3.0);
  // Without it, the coloured planes' shift shows: at 150 px, red is 1.5 px out, blue 2.25 px in.
  EXPECT_GE(MaxDiffInside(Gray(through_lens), truth, 4), 8.0);
}

TEST(LateralColour, MagnifiesAboutTheProjectionOfTheOpticalAxis) {
  // A red-only dot out at (p0 + 100 px) moves by a * 100 px along the ray from p0, no matter where p0 is.
  const LateralColour colour{0.03, 0.0};
  cv::Mat bgr(kHeight, kWidth, CV_8UC3, cv::Scalar::all(0));
  const Eigen::Vector2d dot = kP0 + Eigen::Vector2d(100.0, 0.0) * (1.0 + colour.red);
  cv::circle(bgr, cv::Point(static_cast<int>(std::lround(dot.x())), static_cast<int>(std::lround(dot.y()))), 0,
             cv::Scalar(0, 0, 255), cv::FILLED);
  const cv::Mat gray = LateralColourCorrection(TestCamera(), colour).ToGray(bgr);
  cv::Point brightest;
  cv::minMaxLoc(gray, nullptr, nullptr, nullptr, &brightest);
  EXPECT_NEAR(brightest.x, kP0.x() + 100.0, 1.0);
  EXPECT_NEAR(brightest.y, kP0.y(), 1.0);
}

TEST(LateralColour, RejectsAnImageOfAnotherSize) {
  const LateralColourCorrection correction(TestCamera(), {0.01, 0.0});
  EXPECT_THROW(correction.ToGray(cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(correction.ToGray(cv::Mat(kHeight, kWidth, CV_8UC1)), std::invalid_argument);
}

TEST(LateralColour, FrameReaderCorrectsColourImagesAndReadsGrayOnesAsTheyAre) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rovo_lateral_colour_" + std::to_string(::getpid()));
  fs::create_directories(dir / "cam0");
  fs::create_directories(dir / "cam1");
  Rig rig;
  rig.cameras.push_back({"cam0", TestCamera(), {}});
  rig.cameras.push_back({"cam1", TestCamera(), {}});
  const LateralColour colour{0.01, -0.015};
  const cv::Mat through_lens = RingsThroughLens(colour);
  cv::imwrite((dir / "cam0" / "000000.png").string(), through_lens);
  cv::imwrite((dir / "cam1" / "000000.png").string(), Gray(through_lens));

  const LoadedFrame corrected = FrameReader(dir.string(), rig, {colour, {}, "srgb"}).Load(0);
  const LoadedFrame plain = FrameReader(dir.string(), rig).Load(0);
  ASSERT_TRUE(corrected.problems.empty()) << corrected.problems;
  EXPECT_EQ(
      cv::norm(corrected.images[0], LateralColourCorrection(TestCamera(), colour).ToGray(through_lens), cv::NORM_INF),
      0.0);
  const cv::Mat decoded_gray = cv::imread((dir / "cam0" / "000000.png").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(cv::norm(plain.images[0], decoded_gray, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(corrected.images[1], Gray(through_lens), cv::NORM_INF), 0.0);  // a gray image: nothing to undo
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rovo
