#pragma once
// `rovo study images`: image-quality statistics of fisheye frames, to compare rendered images with real
// ones (docs/results.md, section "Optics"). Per 8-bit image (colour images are reduced to their luminance,
// 0.299 R + 0.587 G + 0.114 B, OpenCV's conversion), with c the image centre and s the short side:
//
//   high-frequency share  the power spectrum of the Hann-windowed central crop (crop x crop pixels, mean
//                         removed) above a quarter of the Nyquist frequency (radius > 0.125 cycles/pixel),
//                         over the whole spectrum without DC
//   spectrum slope        least-squares slope of log10(radially averaged power) against log10(frequency),
//                         over the integer radii 2 .. crop/2 - 1 (cycles per crop)
//   noise sigma           Immerkaer's estimator (Fast noise variance estimation, CVIU 64(2), 1996):
//                         sqrt(pi/2) / 6 * mean |I * N|, N = [1 -2 1; -2 4 -2; 1 -2 1], over the pixels
//                         within circle_fraction * s of c (8-bit units)
//   noise per channel     the same estimator on each colour channel, averaged: the noise of one
//                         photosite, which is what a monochrome camera's pixel holds (the luminance of
//                         three independent channels averages their noise down); = noise sigma for gray
//   rim / centre          mean brightness of the ring ring_inner..ring_outer * s from c over the mean of
//                         the disc within centre_fraction * s
//
// The defaults are the ones of issue 36's table (the real frames' 220-degree lens circles fill the short
// side; the ring lies inside them).

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace rovo {

struct ImageStatisticsOptions {
  int crop = 256;                 // side of the central crop of the spectrum, pixels (even, <= the short side)
  double circle_fraction = 0.47;  // valid circle of the noise estimate, fraction of the short side
  double ring_inner = 0.40;       // rim ring, fraction of the short side
  double ring_outer = 0.47;
  double centre_fraction = 0.2;  // central disc, fraction of the short side
  // Throws std::invalid_argument naming the option.
  void Check() const;
};

struct ImageStatistics {
  double high_frequency_share = 0.0;  // in [0, 1]
  double spectrum_slope = 0.0;
  double noise_sigma = 0.0;              // 8-bit units, of the luminance
  double noise_sigma_per_channel = 0.0;  // 8-bit units, mean over the colour channels
  double rim_over_centre = 0.0;
};

// The statistics of one 8-bit image (CV_8UC1, or CV_8UC3 in OpenCV's BGR order). Throws
// std::invalid_argument when the image is smaller than the crop.
ImageStatistics ComputeImageStatistics(const cv::Mat& image, const ImageStatisticsOptions& options);

// The statistics of every image file (PNG or JPEG, ReadPngOrJpeg8; 16-bit images are scaled to 8 bits); throws
// std::runtime_error naming the file that cannot be read.
std::vector<ImageStatistics> ComputeImageFileStatistics(const std::vector<std::string>& paths,
                                                        const ImageStatisticsOptions& options);

// The PNG/JPEG files of a folder and its subfolders (sorted), or the file itself.
std::vector<std::string> ListImageFiles(const std::string& path);

// Markdown table: one row per image (file name) and rows mean, min, max.
std::string ImageStatisticsTable(const std::vector<std::string>& paths, const std::vector<ImageStatistics>& stats);

}  // namespace rovo
