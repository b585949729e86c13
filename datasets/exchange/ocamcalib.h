#pragma once
// Scaramuzza's OCamCalib calibration files as ocam cameras (datasets/ocam.h).

#include <string>

#include "datasets/camera.h"

namespace rovo {

// Reads Scaramuzza's OCamCalib calib_results.txt. After comment lines ('#') and blank lines come,
// one per line:
//   poly length, then a0 .. a(n-1)        (cam2world: ocam z = sum a_i rho^i, a0 < 0)
//   inverse poly length, then b0 .. b(m-1) (world2cam: rho = sum b_i theta^i)
//   xc yc                                  (distortion centre: row, column, 0-based)
//   c d e                                  (affine)
//   height width
// OCamCalib's frame: x_o along rows (down), y_o along columns (right), z_o pointing backwards,
// out of the lens (a forward ray has z_o = f(rho) < 0); pixel (row, col) = [c d; e 1] (x_o, y_o)
// + (xc, yc). rovo's frame is X = y_o, Y = x_o, Z = -z_o (a proper rotation). Writing the same
// affine with x along columns and the y-coefficient of v normalised to 1 needs a uniform scale of
// the sensor plane by c (x = c y_o, y = c x_o), giving
//   cx = yc, cy = xc, c' = 1/c, d' = e/c, e' = d/c, a'_i = a_i c^(1-i), b'_i = c b_i.
// Polynomials longer than 5 must have zero coefficients beyond a4. The file's inverse polynomial
// is kept when it agrees with the forward one to 0.01 px over the FOV and refitted otherwise;
// `file_inverse_error_px` (optional) receives the file's own inverse error. Errors name the file,
// the line and the field (std::runtime_error).
Camera ReadOcamCalibTxt(const std::string& path, double max_fov_deg = 220.0, double* file_inverse_error_px = nullptr);

}  // namespace rovo
