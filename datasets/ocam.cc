#include "datasets/ocam.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "datasets/camera_models.h"

namespace rovo {
namespace {

constexpr double kAxisElevation = -M_PI / 2;  // theta on the optical axis
constexpr double kMarchStepPx = 0.25;         // resolution of the monotonicity scan
constexpr double kMaxSensorRadiusPx = 1e5;    // give up beyond this radius
constexpr int kErrorGridSize = 4001;          // theta samples for the error measure
constexpr int kFitSamples = 1200;             // Chebyshev-Lobatto nodes for the least squares

// Elevation of the forward ray at sensor radius rho: atan2(f(rho), rho).
double Elevation(const double* params, double rho) { return std::atan2(OcamModel::ForwardPoly(params, rho), rho); }

double EdgeElevation(double max_fov_deg) { return 0.5 * max_fov_deg * kDegToRad + kAxisElevation; }

// Largest singular value of A = [c d; e 1]: bounds |A delta| / |delta|.
double AffineGain(const double* params) {
  const double c = params[2], d = params[3], e = params[4];
  const double sum_sq = c * c + d * d + e * e + 1.0;
  const double det = c - d * e;
  return std::sqrt(0.5 * (sum_sq + std::sqrt(std::max(0.0, sum_sq * sum_sq - 4.0 * det * det))));
}

void CheckBasics(const std::vector<double>& params, double max_fov_deg, const char* function) {
  const std::string where = std::string(function) + ": ";
  if (params.size() < static_cast<size_t>(OcamModel::kNumFixedParams)) {
    throw std::invalid_argument(where + "params: need at least 10 values (cx, cy, c, d, e, a0..a4), got " +
                                std::to_string(params.size()));
  }
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i]))
      throw std::invalid_argument(where + "params[" + std::to_string(i) + "] is not finite");
  }
  if (!(params[5] < 0))
    throw std::invalid_argument(where + "params[5] (a0): must be negative, got " + FormatParam(params[5], 8));
  if (!(std::abs(params[2] - params[3] * params[4]) > 1e-9)) {
    throw std::invalid_argument(where + "params[2..4] (c, d, e): the affine is singular");
  }
  if (!(max_fov_deg > 0 && max_fov_deg < 360)) {
    throw std::invalid_argument(where + "max_fov_deg: must be in (0, 360), got " + FormatParam(max_fov_deg, 8));
  }
}

// Scans rho upwards from 0 until the elevation reaches `theta_target`, requiring it to increase at
// every step; then refines the crossing by bisection. False (with a description) otherwise.
bool MarchToElevation(const double* params, double theta_target, double* rho_out, std::string* problem) {
  double previous = kAxisElevation;
  for (int k = 1;; ++k) {
    const double rho = k * kMarchStepPx;
    const double theta = Elevation(params, rho);
    if (!(theta > previous)) {
      if (problem) {
        *problem = "the elevation atan2(poly(rho), rho) stops increasing at rho = " + FormatParam(rho, 8) + " px (" +
                   FormatParam(previous / kDegToRad + 90, 8) + " deg from the axis), before reaching " +
                   FormatParam(theta_target / kDegToRad + 90, 8) + " deg";
      }
      return false;
    }
    if (theta >= theta_target) {
      double lo = rho - kMarchStepPx, hi = rho;
      for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
        const double mid = 0.5 * (lo + hi);
        (Elevation(params, mid) < theta_target ? lo : hi) = mid;
      }
      *rho_out = 0.5 * (lo + hi);
      return true;
    }
    if (rho > kMaxSensorRadiusPx) {
      if (problem) {
        *problem = "the elevation does not reach " + FormatParam(theta_target / kDegToRad + 90, 8) +
                   " deg from the axis within " + FormatParam(kMaxSensorRadiusPx, 8) + " px";
      }
      return false;
    }
    previous = theta;
  }
}

// Inverse of Elevation on [0, rho_hi] where it is increasing (bisection to machine precision).
double RhoOfElevation(const double* params, double theta, double rho_hi) {
  if (theta <= kAxisElevation) return 0.0;
  double lo = 0.0, hi = rho_hi;
  for (int i = 0; i < 200 && hi - lo > 1e-14 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (Elevation(params, mid) < theta ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The theta grid of the error measure and the true radius at each sample.
struct ErrorGrid {
  std::vector<double> theta, rho;
  double gain = 1.0;
};

ErrorGrid MakeErrorGrid(const double* params, double max_fov_deg, const char* function) {
  const double theta_edge = EdgeElevation(max_fov_deg);
  double rho_edge = 0;
  std::string problem;
  if (!MarchToElevation(params, theta_edge, &rho_edge, &problem)) {
    throw std::invalid_argument(std::string(function) + ": params[5..9] (a0..a4): " + problem);
  }
  ErrorGrid grid;
  grid.gain = AffineGain(params);
  grid.theta.resize(kErrorGridSize);
  grid.rho.resize(kErrorGridSize);
  for (int i = 0; i < kErrorGridSize; ++i) {
    const double theta = kAxisElevation + (theta_edge - kAxisElevation) * i / (kErrorGridSize - 1);
    grid.theta[i] = theta;
    grid.rho[i] = RhoOfElevation(params, theta, rho_edge);
  }
  return grid;
}

// Max and RMS pixel error of the inverse polynomial `b` against the grid, evaluated exactly as
// OcamModel::InversePoly does (Horner in double).
void InverseErrors(const ErrorGrid& grid, const std::vector<double>& b, double* max_px, double* rms_px) {
  double max_error = 0, sum_sq = 0;
  for (size_t i = 0; i < grid.theta.size(); ++i) {
    double rho = b.back();
    for (int k = static_cast<int>(b.size()) - 2; k >= 0; --k) rho = rho * grid.theta[i] + b[k];
    const double error = std::abs(rho - grid.rho[i]);
    if (!(error <= max_error)) max_error = error;  // also propagates NaN
    sum_sq += error * error;
  }
  *max_px = max_error * grid.gain;
  *rms_px = std::sqrt(sum_sq / grid.theta.size()) * grid.gain;
}

// Chebyshev coefficients on s in [-1, 1], s = alpha theta + beta, to monomial coefficients in theta.
// The polynomial is (1 + s) sum c_k T_k(s), one degree higher than the Chebyshev series.
std::vector<double> ChebyshevToMonomial(const Eigen::VectorXd& chebyshev, double alpha, double beta) {
  const int n = static_cast<int>(chebyshev.size()) + 1;
  using Poly = std::vector<long double>;
  // Monomial coefficients (in s) of sum c_k T_k(s), T_{k+1} = 2 s T_k - T_{k-1}.
  std::vector<Poly> chebyshev_basis(n, Poly(n, 0.0L));
  chebyshev_basis[0][0] = 1.0L;
  if (n > 1) chebyshev_basis[1][1] = 1.0L;
  for (int k = 2; k < n; ++k) {
    for (int j = 0; j + 1 < n; ++j) chebyshev_basis[k][j + 1] = 2.0L * chebyshev_basis[k - 1][j];
    for (int j = 0; j < n; ++j) chebyshev_basis[k][j] -= chebyshev_basis[k - 2][j];
  }
  Poly in_s(n, 0.0L);
  for (int k = 0; k < chebyshev.size(); ++k) {
    for (int j = 0; j < n; ++j) in_s[j] += static_cast<long double>(chebyshev[k]) * chebyshev_basis[k][j];
  }
  for (int j = n - 1; j >= 1; --j) in_s[j] += in_s[j - 1];  // times (1 + s)
  // Substitute s = alpha theta + beta: sum_k in_s[k] (beta + alpha theta)^k.
  Poly in_theta(n, 0.0L), power(n, 0.0L);
  power[0] = 1.0L;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) in_theta[j] += in_s[k] * power[j];
    Poly next(n, 0.0L);
    for (int j = 0; j < n; ++j) {
      next[j] += static_cast<long double>(beta) * power[j];
      if (j + 1 < n) next[j + 1] += static_cast<long double>(alpha) * power[j];
    }
    power = next;
  }
  return std::vector<double>(in_theta.begin(), in_theta.end());
}

}  // namespace

bool OcamForwardMonotonic(const std::vector<double>& params, double max_fov_deg, double* rho_edge,
                          std::string* problem) {
  if (params.size() < static_cast<size_t>(OcamModel::kNumFixedParams) || !(params[5] < 0)) {
    if (problem) *problem = "needs at least 10 params with a0 < 0";
    return false;
  }
  double rho = 0;
  if (!MarchToElevation(params.data(), EdgeElevation(max_fov_deg), &rho, problem)) return false;
  if (rho_edge) *rho_edge = rho;
  return true;
}

OcamInverseFit FitOcamInversePolynomial(const std::vector<double>& params, double max_fov_deg, double tolerance_px,
                                        int max_degree) {
  CheckBasics(params, max_fov_deg, "FitOcamInversePolynomial");
  const double* p = params.data();
  const ErrorGrid grid = MakeErrorGrid(p, max_fov_deg, "FitOcamInversePolynomial");

  // Fit interval: a little beyond the FOV edge, as far as the forward model stays monotonic.
  const double theta_edge = EdgeElevation(max_fov_deg);
  double theta_hi = theta_edge, rho_hi = grid.rho.back();
  for (double margin_deg : {2.0, 1.0, 0.5}) {
    double rho = 0;
    if (MarchToElevation(p, theta_edge + margin_deg * kDegToRad, &rho, nullptr)) {
      theta_hi = theta_edge + margin_deg * kDegToRad;
      rho_hi = rho;
      break;
    }
  }
  const double theta_lo = kAxisElevation;
  const double alpha = 2.0 / (theta_hi - theta_lo);
  const double beta = -(theta_hi + theta_lo) / (theta_hi - theta_lo);

  Eigen::VectorXd s(kFitSamples), rho(kFitSamples);
  for (int j = 0; j < kFitSamples; ++j) {
    s[j] = -std::cos(M_PI * j / (kFitSamples - 1));  // Chebyshev-Lobatto nodes, ends included
    const double theta = (s[j] - beta) / alpha;
    rho[j] = RhoOfElevation(p, theta, rho_hi);
  }

  OcamInverseFit best;
  best.max_error_px = std::numeric_limits<double>::infinity();
  best.rms_error_px = std::numeric_limits<double>::infinity();
  for (int degree = 3; degree <= std::max(3, max_degree); ++degree) {
    // rho(theta) = (1 + s) sum_{k < degree} c_k T_k(s): the factor makes rho vanish on the axis
    // (s = -1) exactly, so the projection has no hole at the image centre.
    Eigen::MatrixXd basis(kFitSamples, degree);
    for (int j = 0; j < kFitSamples; ++j) {
      Eigen::VectorXd chebyshev_row(degree);
      chebyshev_row[0] = 1.0;
      if (degree > 1) chebyshev_row[1] = s[j];
      for (int k = 2; k < degree; ++k) chebyshev_row[k] = 2.0 * s[j] * chebyshev_row[k - 1] - chebyshev_row[k - 2];
      basis.row(j) = (1.0 + s[j]) * chebyshev_row.transpose();
    }
    const Eigen::VectorXd chebyshev = basis.colPivHouseholderQr().solve(rho);
    OcamInverseFit fit;
    fit.inverse_poly = ChebyshevToMonomial(chebyshev, alpha, beta);
    InverseErrors(grid, fit.inverse_poly, &fit.max_error_px, &fit.rms_error_px);
    if (fit.max_error_px < best.max_error_px) best = fit;
    if (best.max_error_px < tolerance_px) break;
  }
  return best;
}

double OcamInverseMaxErrorPx(const std::vector<double>& params, double max_fov_deg) {
  CheckBasics(params, max_fov_deg, "OcamInverseMaxErrorPx");
  if (params.size() < static_cast<size_t>(OcamModel::kMinNumParams)) {
    throw std::invalid_argument("OcamInverseMaxErrorPx: params: no inverse polynomial (need 10 + K values, K >= 1)");
  }
  const ErrorGrid grid = MakeErrorGrid(params.data(), max_fov_deg, "OcamInverseMaxErrorPx");
  const std::vector<double> b(params.begin() + OcamModel::kNumFixedParams, params.end());
  double max_px = 0, rms_px = 0;
  InverseErrors(grid, b, &max_px, &rms_px);
  return max_px;
}

Camera MakeOcamCamera(int width, int height, double cx, double cy, double c, double d, double e,
                      const std::vector<double>& forward_poly, double max_fov_deg, double tolerance_px) {
  if (forward_poly.empty()) throw std::invalid_argument("MakeOcamCamera: forward_poly: empty");
  for (size_t i = 5; i < forward_poly.size(); ++i) {
    if (forward_poly[i] != 0.0) {
      throw std::invalid_argument("MakeOcamCamera: forward_poly[" + std::to_string(i) +
                                  "]: only a0..a4 are supported, got a nonzero coefficient");
    }
  }
  Camera camera;
  camera.model = CameraModelId::kOcam;
  camera.width = width;
  camera.height = height;
  camera.max_fov_deg = max_fov_deg;
  camera.params = {cx, cy, c, d, e, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < std::min<size_t>(5, forward_poly.size()); ++i) camera.params[5 + i] = forward_poly[i];
  const OcamInverseFit fit = FitOcamInversePolynomial(camera.params, max_fov_deg, tolerance_px);
  if (!(fit.max_error_px < tolerance_px)) {
    throw std::invalid_argument("MakeOcamCamera: inverse polynomial: the best fit (degree " +
                                std::to_string(fit.inverse_poly.size() - 1) + ") is off by " +
                                FormatParam(fit.max_error_px, 8) + " px, more than the tolerance " +
                                FormatParam(tolerance_px, 8) + " px");
  }
  camera.params.insert(camera.params.end(), fit.inverse_poly.begin(), fit.inverse_poly.end());
  camera.Check("MakeOcamCamera");
  return camera;
}

}  // namespace rovo
