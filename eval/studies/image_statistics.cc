// Image-quality statistics of fisheye frames (image_statistics.h gives the definitions).
#include "eval/studies/image_statistics.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "datasets/image_file.h"

namespace rovo {

namespace {

// The luminance of an 8-bit image as CV_32F.
cv::Mat GrayFloat(const cv::Mat& image) {
  cv::Mat gray;
  if (image.channels() == 3)
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4)
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  else
    gray = image;
  cv::Mat f;
  gray.convertTo(f, CV_32F);
  return f;
}

// High-frequency share and spectrum slope of the Hann-windowed central crop.
void SpectrumStatistics(const cv::Mat& gray, int crop, ImageStatistics* stats) {
  const cv::Rect roi((gray.cols - crop) / 2, (gray.rows - crop) / 2, crop, crop);
  cv::Mat patch = gray(roi).clone();
  patch -= cv::mean(patch)[0];
  cv::Mat window;
  cv::createHanningWindow(window, patch.size(), CV_32F);
  patch = patch.mul(window);
  cv::Mat spectrum;
  cv::dft(patch, spectrum, cv::DFT_COMPLEX_OUTPUT);
  const int half = crop / 2;
  std::vector<double> ring_sum(half + 1, 0.0);
  std::vector<int> ring_count(half + 1, 0);
  double total = 0.0, high = 0.0;
  for (int y = 0; y < crop; ++y) {
    const int v = y < half ? y : y - crop;
    for (int x = 0; x < crop; ++x) {
      const int u = x < half ? x : x - crop;
      if (u == 0 && v == 0) continue;
      const cv::Vec2f c = spectrum.at<cv::Vec2f>(y, x);
      const double power = static_cast<double>(c[0]) * c[0] + static_cast<double>(c[1]) * c[1];
      const double r = std::hypot(u, v);
      total += power;
      if (r > crop / 8.0) high += power;  // 1/4 of Nyquist (0.5 cycles/pixel) = crop / 8 cycles per crop
      const int k = static_cast<int>(std::lround(r));
      if (k <= half) {
        ring_sum[k] += power;
        ++ring_count[k];
      }
    }
  }
  stats->high_frequency_share = total > 0.0 ? high / total : 0.0;
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  int n = 0;
  for (int k = 2; k < half; ++k) {
    if (ring_count[k] == 0 || ring_sum[k] <= 0.0) continue;
    const double lx = std::log10(static_cast<double>(k)), ly = std::log10(ring_sum[k] / ring_count[k]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++n;
  }
  const double denom = n * sxx - sx * sx;
  stats->spectrum_slope = n > 1 && denom != 0.0 ? (n * sxy - sx * sy) / denom : 0.0;
}

// Immerkaer's noise estimate over the pixels whose 3x3 neighbourhood lies within the valid circle.
double ImmerkaerSigma(const cv::Mat& gray, double radius) {
  const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(gray, response, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT);
  const double cx = 0.5 * (gray.cols - 1), cy = 0.5 * (gray.rows - 1);
  const double r2 = (radius - 1.5) * (radius - 1.5);
  double sum = 0.0;
  int64_t count = 0;
  for (int y = 1; y + 1 < gray.rows; ++y) {
    const float* row = response.ptr<float>(y);
    for (int x = 1; x + 1 < gray.cols; ++x) {
      if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > r2) continue;
      sum += std::abs(row[x]);
      ++count;
    }
  }
  return count > 0 ? std::sqrt(M_PI / 2.0) / 6.0 * sum / static_cast<double>(count) : 0.0;
}

// Mean of the ring [r0, r1) over the mean of the disc [0, rc).
double RimOverCentre(const cv::Mat& gray, double r0, double r1, double rc) {
  const double cx = 0.5 * (gray.cols - 1), cy = 0.5 * (gray.rows - 1);
  double ring = 0.0, disc = 0.0;
  int64_t n_ring = 0, n_disc = 0;
  for (int y = 0; y < gray.rows; ++y) {
    const float* row = gray.ptr<float>(y);
    for (int x = 0; x < gray.cols; ++x) {
      const double r = std::hypot(x - cx, y - cy);
      if (r < rc) {
        disc += row[x];
        ++n_disc;
      } else if (r >= r0 && r < r1) {
        ring += row[x];
        ++n_ring;
      }
    }
  }
  if (n_ring == 0 || n_disc == 0 || disc <= 0.0) return 0.0;
  return (ring / static_cast<double>(n_ring)) / (disc / static_cast<double>(n_disc));
}

}  // namespace

void ImageStatisticsOptions::Check() const {
  if (crop < 16 || crop % 2 != 0) throw std::invalid_argument("--crop must be an even number >= 16");
  if (!(circle_fraction > 0.0 && circle_fraction <= 0.75)) throw std::invalid_argument("--circle must be in (0, 0.75]");
  if (!(ring_inner >= 0.0 && ring_inner < ring_outer && ring_outer <= 0.75))
    throw std::invalid_argument("--ring must satisfy 0 <= inner < outer <= 0.75");
  if (!(centre_fraction > 0.0 && centre_fraction <= ring_inner))
    throw std::invalid_argument("--centre must be in (0, ring inner]");
}

ImageStatistics ComputeImageStatistics(const cv::Mat& image, const ImageStatisticsOptions& options) {
  options.Check();
  if (image.depth() != CV_8U) throw std::invalid_argument("image statistics: the image must be 8-bit");
  const int short_side = std::min(image.cols, image.rows);
  if (short_side < options.crop)
    throw std::invalid_argument("image statistics: the image (" + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + ") is smaller than the crop of " +
                                std::to_string(options.crop) + " pixels (--crop)");
  const cv::Mat gray = GrayFloat(image);
  ImageStatistics stats;
  SpectrumStatistics(gray, options.crop, &stats);
  stats.noise_sigma = ImmerkaerSigma(gray, options.circle_fraction * short_side);
  stats.noise_sigma_per_channel = stats.noise_sigma;
  if (image.channels() >= 3) {
    std::vector<cv::Mat> planes;
    cv::split(image, planes);
    stats.noise_sigma_per_channel = 0.0;
    for (int c = 0; c < 3; ++c) {
      cv::Mat plane;
      planes[c].convertTo(plane, CV_32F);
      stats.noise_sigma_per_channel += ImmerkaerSigma(plane, options.circle_fraction * short_side) / 3.0;
    }
  }
  stats.rim_over_centre = RimOverCentre(gray, options.ring_inner * short_side, options.ring_outer * short_side,
                                        options.centre_fraction * short_side);
  return stats;
}

std::vector<ImageStatistics> ComputeImageFileStatistics(const std::vector<std::string>& paths,
                                                        const ImageStatisticsOptions& options) {
  std::vector<ImageStatistics> out;
  for (const std::string& path : paths) {
    Image8 file = ReadPngOrJpeg8(path);  // 16-bit samples rounded to 8 bits
    cv::Mat image(file.height, file.width, CV_8UC(file.channels), file.pixels.data());
    if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_RGB2BGR);  // in place
    try {
      out.push_back(ComputeImageStatistics(image, options));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
  }
  return out;
}

std::vector<std::string> ListImageFiles(const std::string& path) {
  namespace fs = std::filesystem;
  if (!fs::exists(path)) throw std::runtime_error(path + ": no such file or folder");
  if (!fs::is_directory(path)) return {path};
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(path)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    const std::string name = entry.path().filename().string();
    if ((ext == ".png" || ext == ".jpg" || ext == ".jpeg") && name.rfind("mask", 0) != 0)
      files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ImageStatisticsTable(const std::vector<std::string>& paths, const std::vector<ImageStatistics>& stats) {
  std::ostringstream out;
  out << "| image | share of spectral power above 1/4 Nyquist | spectrum slope | noise sigma (8-bit) | noise sigma "
         "per channel | rim / centre brightness |\n|---|---|---|---|---|---|\n";
  char line[256];
  auto row = [&](const std::string& name, const ImageStatistics& s) {
    std::snprintf(line, sizeof(line), "| %s | %.1f %% | %.2f | %.2f | %.2f | %.2f |\n", name.c_str(),
                  100.0 * s.high_frequency_share, s.spectrum_slope, s.noise_sigma, s.noise_sigma_per_channel,
                  s.rim_over_centre);
    out << line;
  };
  for (size_t i = 0; i < stats.size(); ++i) row(paths[i], stats[i]);
  if (stats.empty()) return out.str();
  ImageStatistics mean, lo = stats[0], hi = stats[0];
  for (const ImageStatistics& s : stats) {
    mean.high_frequency_share += s.high_frequency_share / stats.size();
    mean.spectrum_slope += s.spectrum_slope / stats.size();
    mean.noise_sigma += s.noise_sigma / stats.size();
    mean.noise_sigma_per_channel += s.noise_sigma_per_channel / stats.size();
    mean.rim_over_centre += s.rim_over_centre / stats.size();
    lo.high_frequency_share = std::min(lo.high_frequency_share, s.high_frequency_share);
    lo.spectrum_slope = std::min(lo.spectrum_slope, s.spectrum_slope);
    lo.noise_sigma = std::min(lo.noise_sigma, s.noise_sigma);
    lo.noise_sigma_per_channel = std::min(lo.noise_sigma_per_channel, s.noise_sigma_per_channel);
    lo.rim_over_centre = std::min(lo.rim_over_centre, s.rim_over_centre);
    hi.high_frequency_share = std::max(hi.high_frequency_share, s.high_frequency_share);
    hi.spectrum_slope = std::max(hi.spectrum_slope, s.spectrum_slope);
    hi.noise_sigma = std::max(hi.noise_sigma, s.noise_sigma);
    hi.noise_sigma_per_channel = std::max(hi.noise_sigma_per_channel, s.noise_sigma_per_channel);
    hi.rim_over_centre = std::max(hi.rim_over_centre, s.rim_over_centre);
  }
  row("**mean** (" + std::to_string(stats.size()) + " images)", mean);
  row("min", lo);
  row("max", hi);
  return out.str();
}

}  // namespace rovo
