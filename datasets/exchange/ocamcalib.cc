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

// The five data lines of an OCamCalib file (comments and blank lines skipped), with the parse
// errors of each: "<path>:<line>: <field>: <message>".
class OcamTxtLines {
 public:
  explicit OcamTxtLines(const std::string& path) : path_(path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open for reading");
    std::string text;
    for (int number = 1; std::getline(in, text); ++number) {
      const size_t first = text.find_first_not_of(" \t\r");
      if (first == std::string::npos || text[first] == '#') continue;
      lines_.push_back({number, text});
    }
    if (lines_.size() < 5) {
      throw std::runtime_error(path +
                               ": expected 5 data lines (poly, inverse poly, center, affine, image size), found " +
                               std::to_string(lines_.size()));
    }
  }

  std::runtime_error Error(int index, const std::string& message) const {
    static const char* const kFields[5] = {"poly", "inverse poly", "center", "affine", "image size"};
    return std::runtime_error(path_ + ":" + std::to_string(lines_[index].number) + ": " + kFields[index] + ": " +
                              message);
  }

  std::vector<double> Numbers(int index) const {
    std::vector<double> values;
    std::istringstream tokens(lines_[index].text);
    std::string token;
    while (tokens >> token) {
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(value)) {
        throw Error(index, "'" + token + "' is not a finite number");
      }
      values.push_back(value);
    }
    return values;
  }

  // "n v0 .. v(n-1)": the count must be a whole number matching the values on the line.
  std::vector<double> Counted(int index) const {
    std::vector<double> values = Numbers(index);
    if (values.empty() || values[0] != std::floor(values[0]) || values[0] < 0 ||
        values[0] != static_cast<double>(values.size() - 1)) {
      throw Error(index, "expected a count followed by that many coefficients");
    }
    values.erase(values.begin());
    return values;
  }

  std::vector<double> Exactly(int index, size_t count) const {
    std::vector<double> values = Numbers(index);
    if (values.size() != count) {
      throw Error(index, "expected " + std::to_string(count) + " numbers, found " + std::to_string(values.size()));
    }
    return values;
  }

 private:
  struct DataLine {
    int number;
    std::string text;
  };
  std::string path_;
  std::vector<DataLine> lines_;
};

// The numbers of an OCamCalib file, checked for the ranges the mapping to rovo's model needs.
struct OcamTxtFields {
  std::vector<double> poly, inverse;
  std::vector<double> center;  // row, column
  std::vector<double> affine;  // c, d, e
  std::vector<double> size;    // height, width
};

OcamTxtFields ParseOcamTxtFields(const OcamTxtLines& lines) {
  OcamTxtFields f;
  f.poly = lines.Counted(0);
  f.inverse = lines.Counted(1);
  f.center = lines.Exactly(2, 2);
  f.affine = lines.Exactly(3, 3);
  f.size = lines.Exactly(4, 2);
  if (f.poly.empty() || !(f.poly[0] < 0)) throw lines.Error(0, "a0 must be present and negative");
  for (size_t i = 5; i < f.poly.size(); ++i) {
    if (f.poly[i] != 0.0) {
      throw lines.Error(0, "coefficient a" + std::to_string(i) + " is nonzero; only a0..a4 are supported");
    }
  }
  const double c = f.affine[0], d = f.affine[1], e = f.affine[2];
  if (!(c > 0)) throw lines.Error(3, "c must be positive, got " + FormatParam(c, 8));
  if (!(std::abs(c - d * e) > 1e-9)) throw lines.Error(3, "the affine [c d; e 1] is singular");
  for (int k = 0; k < 2; ++k) {
    if (!(f.size[k] >= 1 && f.size[k] == std::floor(f.size[k]) && f.size[k] < 1e6)) {
      throw lines.Error(4, "height and width must be positive integers");
    }
  }
  return f;
}

// Appends the inverse polynomial: the file's own when within 0.01 px over the field of view, else a fit.
void AttachInversePolynomial(const OcamTxtLines& lines, const std::vector<double>& inverse, double c,
                             double max_fov_deg, Camera* camera, double* file_inverse_error_px) {
  double file_error = std::numeric_limits<double>::infinity();
  if (!inverse.empty()) {
    std::vector<double> with_file_inverse = camera->params;
    for (double b : inverse) with_file_inverse.push_back(c * b);
    file_error = OcamInverseMaxErrorPx(with_file_inverse, max_fov_deg);
    if (file_error < 0.01) camera->params = with_file_inverse;
  }
  if (file_inverse_error_px) *file_inverse_error_px = file_error;
  if (camera->params.size() == static_cast<size_t>(OcamModel::kNumFixedParams)) {
    const OcamInverseFit fit = FitOcamInversePolynomial(camera->params, max_fov_deg);
    if (!(fit.max_error_px < 0.01)) {
      throw lines.Error(0, "no inverse polynomial within 0.01 px over " + FormatParam(max_fov_deg, 8) + " deg (best " +
                               FormatParam(fit.max_error_px, 8) + " px)");
    }
    camera->params.insert(camera->params.end(), fit.inverse_poly.begin(), fit.inverse_poly.end());
  }
}

}  // namespace

Camera ReadOcamCalibTxt(const std::string& path, double max_fov_deg, double* file_inverse_error_px) {
  const OcamTxtLines lines(path);
  const OcamTxtFields f = ParseOcamTxtFields(lines);
  const double c = f.affine[0], d = f.affine[1], e = f.affine[2];

  Camera camera;
  camera.model = CameraModelId::kOcam;
  camera.height = static_cast<int>(f.size[0]);
  camera.width = static_cast<int>(f.size[1]);
  camera.max_fov_deg = max_fov_deg;
  // The mapping of the header comment: swap axes, normalise the affine by c, scale the sensor by c.
  camera.params = {f.center[1], f.center[0], 1.0 / c, e / c, d / c, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < std::min<size_t>(5, f.poly.size()); ++i) {
    camera.params[5 + i] = f.poly[i] * std::pow(c, 1.0 - static_cast<double>(i));
  }
  std::string problem;
  if (!OcamForwardMonotonic(camera.params, max_fov_deg, nullptr, &problem)) throw lines.Error(0, problem);

  AttachInversePolynomial(lines, f.inverse, c, max_fov_deg, &camera, file_inverse_error_px);
  try {
    camera.Check(path);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  return camera;
}

}  // namespace rovo
