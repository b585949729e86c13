#pragma once
// OCamCalib / OmniMVS polynomial cameras (OcamModel in camera_models.h): fitting the inverse
// polynomial, measuring its error, building cameras, and reading OCamCalib's calib_results.txt.
//
// Notation (rovo's ocam layout, camera_models.h):
//   params = [cx, cy, c, d, e, a0, a1, a2, a3, a4, b0, ..., b(K-1)]
//   forward:  ray(rho) = (x, y, -f(rho)),  f(rho) = a0 + a1 rho + ... + a4 rho^4,  rho = |(x, y)|
//   elevation of that ray above the image plane: theta(rho) = atan2(-z, rho) = atan2(f(rho), rho),
//   which is -pi/2 on the axis (rho = 0) and increases with rho for a valid lens.
//   inverse:  rho(theta) = sum b_i theta^i, the inverse function of theta(rho), approximated.
// An angle alpha from the optical axis corresponds to the elevation theta = alpha - pi/2; the FOV
// edge of a lens with max_fov_deg is at theta_edge = max_fov/2 - 90 degrees (+20 deg for 220).
// Errors in pixels are |rho_fit(theta) - rho_true(theta)| times the largest singular value of the
// affine A = [c d; e 1] (a bound on the pixel displacement), maximised over a dense theta grid
// covering [-pi/2, theta_edge].

#include <string>
#include <vector>

#include "datasets/camera.h"

namespace rovo {

struct OcamInverseFit {
  std::vector<double> inverse_poly;  // b0..b(K-1), in increasing powers of theta
  double max_error_px = 0.0;         // over the FOV, see above
  double rms_error_px = 0.0;
};

// Least-squares fit of rho(theta) to the forward model over theta in [-pi/2, theta_edge + 2 deg]
// (or up to where the forward model stays monotonic, if that is less), in a Chebyshev basis on the
// interval mapped to [-1, 1] (solved with Eigen's ColPivHouseholderQR) and converted to monomials
// in theta. The basis is (theta + pi/2) T_k, so rho(-pi/2) = 0: the axis maps to the centre. The degree increases from
// 3 until max_error_px < tolerance_px; returns the first fit that meets it, else the one with the smallest max error up
// to max_degree (check max_error_px). `params`: at least the first 10 values (cx .. a4); any inverse coefficients are
// ignored. Throws std::invalid_argument when a0 >= 0, the affine is singular, max_fov_deg is not in (0, 360), or
// theta(rho) is not increasing up to the FOV edge (message says where).
OcamInverseFit FitOcamInversePolynomial(const std::vector<double>& params, double max_fov_deg,
                                        double tolerance_px = 0.01, int max_degree = 20);

// Max disagreement (pixels, see above) of the inverse polynomial in `params` (10 + K values,
// K >= 1) with the forward one over the FOV. Throws like FitOcamInversePolynomial.
double OcamInverseMaxErrorPx(const std::vector<double>& params, double max_fov_deg);

// True when theta(rho) is strictly increasing from rho = 0 until it reaches the FOV edge;
// `rho_edge` (optional) receives the sensor radius of the edge. `problem` (optional) receives a
// description otherwise. Needs the first 10 params.
bool OcamForwardMonotonic(const std::vector<double>& params, double max_fov_deg, double* rho_edge = nullptr,
                          std::string* problem = nullptr);

// An ocam Camera with the inverse polynomial fitted to `forward_poly` = {a0, .., a4} (fewer values
// are zero-padded). cx, cy in rovo pixels (column, row). Throws std::invalid_argument when the
// fit does not reach tolerance_px or the parameters are invalid.
Camera MakeOcamCamera(int width, int height, double cx, double cy, double c, double d, double e,
                      const std::vector<double>& forward_poly, double max_fov_deg = 220.0, double tolerance_px = 0.01);

// OCamCalib's calib_results.txt and its mapping to this layout: ReadOcamCalibTxt in
// datasets/exchange/ocamcalib.h.

}  // namespace rovo
