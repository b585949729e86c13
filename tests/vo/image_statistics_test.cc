// rovo study images (eval/studies/image_statistics.h) against analytic expectations: white noise has a
// flat spectrum (slope 0, the share of the spectrum outside the quarter-Nyquist disc equal to its area)
// and Immerkaer's estimate equals its sigma; blur moves power to low frequencies; the rim/centre ratio of
// a two-level image.
#include "eval/studies/image_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace rovo {
namespace {

cv::Mat WhiteNoise(int width, int height, double sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  cv::Mat image(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(128.0 + normal(rng));
  return image;
}

TEST(ImageStatisticsTest, WhiteNoiseHasAFlatSpectrumAndItsSigma) {
  const ImageStatistics s = ComputeImageStatistics(WhiteNoise(600, 560, 6.0, 1), ImageStatisticsOptions{});
  // Outside the disc of radius 1/8 cycle/pixel in the unit square of frequencies: 1 - pi / 64.
  EXPECT_NEAR(s.high_frequency_share, 1.0 - M_PI / 64.0, 0.01);
  EXPECT_NEAR(s.spectrum_slope, 0.0, 0.08);
  // Rounding to 8 bits adds 1/12 to the variance.
  EXPECT_NEAR(s.noise_sigma, std::sqrt(36.0 + 1.0 / 12.0), 0.15);
  EXPECT_EQ(s.noise_sigma_per_channel, s.noise_sigma);
  EXPECT_NEAR(s.rim_over_centre, 1.0, 0.01);
}

// Three independent noise planes: each channel keeps its sigma, the luminance (OpenCV's weights 0.299,
// 0.587, 0.114) averages it down to sqrt(0.299^2 + 0.587^2 + 0.114^2) = 0.668 of it.
TEST(ImageStatisticsTest, ColourNoisePerChannelAndOfTheLuminance) {
  cv::Mat colour;
  cv::merge(
      std::vector<cv::Mat>{WhiteNoise(600, 560, 6.0, 1), WhiteNoise(600, 560, 6.0, 2), WhiteNoise(600, 560, 6.0, 3)},
      colour);
  const ImageStatistics s = ComputeImageStatistics(colour, ImageStatisticsOptions{});
  EXPECT_NEAR(s.noise_sigma_per_channel, std::sqrt(36.0 + 1.0 / 12.0), 0.15);
  EXPECT_NEAR(s.noise_sigma, 0.668 * 6.0, 0.25);
}

TEST(ImageStatisticsTest, BlurMovesPowerToLowFrequencies) {
  const cv::Mat noise = WhiteNoise(600, 560, 20.0, 2);
  cv::Mat blurred;
  cv::GaussianBlur(noise, blurred, cv::Size(0, 0), 1.5);
  const ImageStatistics sharp = ComputeImageStatistics(noise, ImageStatisticsOptions{});
  const ImageStatistics soft = ComputeImageStatistics(blurred, ImageStatisticsOptions{});
  // A Gaussian of sigma 1.5 px keeps exp(-4 pi^2 sigma^2 f^2) of the power: at 1/8 cycle/pixel 0.50.
  EXPECT_LT(soft.high_frequency_share, 0.5 * sharp.high_frequency_share);
  EXPECT_LT(soft.spectrum_slope, -2.0);
  EXPECT_LT(soft.noise_sigma, 0.2 * sharp.noise_sigma);
}

TEST(ImageStatisticsTest, RimOverCentreOfATwoLevelImage) {
  cv::Mat image(500, 600, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Point centre(300, 250);                                    // the image centre (599 / 2, 499 / 2) rounded up
  cv::circle(image, centre, 240, cv::Scalar(60, 60, 60), cv::FILLED);  // the ring 0.40-0.47 of 500: 200-235
  cv::circle(image, centre, 150, cv::Scalar(120, 120, 120), cv::FILLED);  // covers the central disc (100)
  const ImageStatistics s = ComputeImageStatistics(image, ImageStatisticsOptions{});
  EXPECT_NEAR(s.rim_over_centre, 0.5, 0.005);
  ImageStatisticsOptions bad;
  bad.crop = 1024;
  EXPECT_THROW(ComputeImageStatistics(image, bad), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
