#pragma once
// OmniMVS rig calibration conventions (config.yaml of hyu-cvlab/omnimvs-pytorch) as rig cameras, and the
// `rovo4_real` preset built from them. The file reader is datasets/exchange/omnimvs.h.
//
// File conventions (as in the header of the ITBT rig's config.yaml):
//   poly: [n, a0..a(n-1)], z_ocam(rho) = sum a_i rho^i (a0 < 0); the OpenCV ray of a pixel is
//         (x, y, -z_ocam(rho)) after removing centre and affine.
//   inv_poly: [n, b0..b(n-1)], rho = sum b_i theta^i (theta = elevation from the image plane).
//   center: [row, col]; affine: [c, d, e]; image_size: [height, width]; max_fov in degrees.
//   pose: cam2rig = (Rodrigues rx ry rz, translation tx ty tz in metres) in the file's rig frame,
//         whose y axis points down and whose cameras lie in its xz-plane.
//
// Frame change to our rig frame (REP-103, x forward, y left, z up):
//   x_ours = x_file, y_ours = z_file, z_ours = -y_file,
// i.e. the file's x is forward. With this choice the file's first camera looks at yaw ~ +47 deg
// (front-left), then -45, -130, +137: the same order and directions as the `rovo4` preset.
//   cam_from_rig = (rig_ours_from_rig_file * cam2rig)^-1.
// Camera i of the file (cam_id i+1) becomes "cam<i>".
//
// Intrinsics: OmniMVS reads the file with OCamCalib's conventions (x_o along rows:
// (row, col) = [c d; e 1] (x_o, y_o) + center, OpenCV ray (y_o, x_o, -poly)). In our ocam layout
// [cx, cy, c', d', e', a0'..a4', b0..b(K-1)] (x along columns) that is, after scaling the sensor
// plane by c: cx = col, cy = row, c' = 1/c, d' = e/c, e' = d/c, a'_i = a_i c^(1-i). The file's own inverse polynomial
// is NOT used: it disagrees with its forward polynomial by pixels; the inverse is refitted (FitOcamInversePolynomial)
// over the full field of view.

#include <string>
#include <vector>

#include "datasets/rig.h"

namespace rovo {

// One camera entry of an OmniMVS config.yaml, numbers as in the file.
struct OmniMvsCamera {
  std::vector<double> poly;      // a0.. (without the leading count)
  std::vector<double> inv_poly;  // b0.. (without the leading count)
  double center_row = 0.0, center_col = 0.0;
  double affine[3] = {1.0, 0.0, 0.0};  // c, d, e
  int height = 0, width = 0;
  double pose[6] = {0, 0, 0, 0, 0, 0};  // cam2rig: Rodrigues rx ry rz, tx ty tz
  double max_fov_deg = 220.0;
};

// Rotation taking directions in the OmniMVS rig frame to our rig frame (see above).
Eigen::Matrix3d RigFromOmniMvsRigRotation();

// Forward ocam parameters [cx, cy, c, d, e, a0..a4] plus an inverse polynomial fitted over
// max_fov_deg; max_error_px (optional) receives the fit's maximum round-trip error in pixels.
// Throws std::runtime_error when no fit reaches 0.01 px.
std::vector<double> OcamParamsWithFittedInverse(const std::vector<double>& forward_params, double max_fov_deg,
                                                double* max_error_px);

// File entry `cam` as rig camera "cam<index>" (ocam, inverse refitted, frame changed as above). Throws
// std::runtime_error naming `where`; `report` (optional) gets a line on the inverse polynomials' errors.
RigCamera OmniMvsRigCamera(const OmniMvsCamera& cam, int index, const std::string& where, std::string* report);

// The `rovo4_real` preset: the numbers of the ITBT rig's config.yaml embedded in the source, converted
// exactly as ReadOmniMvsConfig does.
Rig MakeRovo4RealRig();

}  // namespace rovo
