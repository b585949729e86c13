#include "datasets/exchange/ocamcalib.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "datasets/camera_models.h"
#include "datasets/ocam.h"

namespace rovo {
namespace {

std::string Fmt(double value) {
  std::ostringstream out;
  out.precision(8);
  out << value;
  return out.str();
}

}  // namespace

Camera ReadOcamCalibTxt(const std::string& path, double max_fov_deg, double* file_inverse_error_px) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open for reading");
  struct DataLine {
    int number;
    std::string text;
  };
  std::vector<DataLine> lines;
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    const size_t first = text.find_first_not_of(" \t\r");
    if (first == std::string::npos || text[first] == '#') continue;
    lines.push_back({number, text});
  }
  static const char* const kFields[5] = {"poly", "inverse poly", "center", "affine", "image size"};
  if (lines.size() < 5) {
    throw std::runtime_error(path + ": expected 5 data lines (poly, inverse poly, center, affine, image size), found " +
                             std::to_string(lines.size()));
  }
  auto error = [&](int index, const std::string& message) {
    return std::runtime_error(path + ":" + std::to_string(lines[index].number) + ": " + kFields[index] + ": " +
                              message);
  };
  auto numbers = [&](int index) {
    std::vector<double> values;
    std::istringstream tokens(lines[index].text);
    std::string token;
    while (tokens >> token) {
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(value)) {
        throw error(index, "'" + token + "' is not a finite number");
      }
      values.push_back(value);
    }
    return values;
  };
  // "n v0 .. v(n-1)": the count must be a whole number matching the values on the line.
  auto counted = [&](int index) {
    std::vector<double> values = numbers(index);
    if (values.empty() || values[0] != std::floor(values[0]) || values[0] < 0 ||
        values[0] != static_cast<double>(values.size() - 1)) {
      throw error(index, "expected a count followed by that many coefficients");
    }
    values.erase(values.begin());
    return values;
  };
  auto exactly = [&](int index, size_t count) {
    std::vector<double> values = numbers(index);
    if (values.size() != count) {
      throw error(index, "expected " + std::to_string(count) + " numbers, found " + std::to_string(values.size()));
    }
    return values;
  };

  const std::vector<double> poly = counted(0);
  const std::vector<double> inverse = counted(1);
  const std::vector<double> center = exactly(2, 2);  // row, column
  const std::vector<double> affine = exactly(3, 3);  // c, d, e
  const std::vector<double> size = exactly(4, 2);    // height, width
  if (poly.empty() || !(poly[0] < 0)) throw error(0, "a0 must be present and negative");
  for (size_t i = 5; i < poly.size(); ++i) {
    if (poly[i] != 0.0) throw error(0, "coefficient a" + std::to_string(i) + " is nonzero; only a0..a4 are supported");
  }
  const double c = affine[0], d = affine[1], e = affine[2];
  if (!(c > 0)) throw error(3, "c must be positive, got " + Fmt(c));
  if (!(std::abs(c - d * e) > 1e-9)) throw error(3, "the affine [c d; e 1] is singular");
  for (int k = 0; k < 2; ++k) {
    if (!(size[k] >= 1 && size[k] == std::floor(size[k]) && size[k] < 1e6)) {
      throw error(4, "height and width must be positive integers");
    }
  }

  Camera camera;
  camera.model = CameraModelId::kOcam;
  camera.height = static_cast<int>(size[0]);
  camera.width = static_cast<int>(size[1]);
  camera.max_fov_deg = max_fov_deg;
  // The mapping of the header comment: swap axes, normalise the affine by c, scale the sensor by c.
  camera.params = {center[1], center[0], 1.0 / c, e / c, d / c, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < std::min<size_t>(5, poly.size()); ++i) {
    camera.params[5 + i] = poly[i] * std::pow(c, 1.0 - static_cast<double>(i));
  }
  std::string problem;
  if (!OcamForwardMonotonic(camera.params, max_fov_deg, nullptr, &problem)) throw error(0, problem);

  double file_error = std::numeric_limits<double>::infinity();
  if (!inverse.empty()) {
    std::vector<double> with_file_inverse = camera.params;
    for (double b : inverse) with_file_inverse.push_back(c * b);
    file_error = OcamInverseMaxErrorPx(with_file_inverse, max_fov_deg);
    if (file_error < 0.01) camera.params = with_file_inverse;
  }
  if (file_inverse_error_px) *file_inverse_error_px = file_error;
  if (camera.params.size() == static_cast<size_t>(OcamModel::kNumFixedParams)) {
    const OcamInverseFit fit = FitOcamInversePolynomial(camera.params, max_fov_deg);
    if (!(fit.max_error_px < 0.01)) {
      throw error(0, "no inverse polynomial within 0.01 px over " + Fmt(max_fov_deg) + " deg (best " +
                         Fmt(fit.max_error_px) + " px)");
    }
    camera.params.insert(camera.params.end(), fit.inverse_poly.begin(), fit.inverse_poly.end());
  }
  try {
    camera.Check(path);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  return camera;
}

}  // namespace rovo
