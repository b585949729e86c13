#pragma once
// OmniMVS rig calibration files (config.yaml of hyu-cvlab/omnimvs-pytorch) and the real rig preset.
//
// File conventions (see the header of /work/shared/data/omnimvs_itbt_config.yaml):
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

// Rotation taking directions in the OmniMVS rig frame to our rig frame (see above).
Eigen::Matrix3d RigFromOmniMvsRigRotation();

// Forward ocam parameters [cx, cy, c, d, e, a0..a4] plus an inverse polynomial fitted over
// max_fov_deg; max_error_px (optional) receives the fit's maximum round-trip error in pixels.
// Throws std::runtime_error when no fit reaches 0.01 px.
std::vector<double> OcamParamsWithFittedInverse(const std::vector<double>& forward_params, double max_fov_deg,
                                                double* max_error_px);

// Reads an OmniMVS config.yaml (yaml-cpp). Throws std::runtime_error naming the file and field
// (e.g. "cameras[2].poly") on malformed input. `report` (optional) receives one line per camera:
// the refitted inverse's max error and how far the file's own inv_poly is off, in pixels.
Rig ReadOmniMvsConfig(const std::string& yaml_path, std::string* report);

// The `rovo4_real` preset: the numbers of /work/shared/data/omnimvs_itbt_config.yaml embedded in
// the source, converted exactly as ReadOmniMvsConfig does.
Rig MakeRovo4RealRig();

}  // namespace rovo

namespace rovo {

// A capture in an OmniMVS config's layout: `dataset: {img_fmt, start, end, step}` (img_fmt is a
// printf pattern of the camera id and the frame index, e.g. "cam%d/%05d.png") and each camera's
// `cam_id`.
struct OmniMvsCapture {
  std::string img_fmt = "cam%d/%05d.png";
  int start = 1, end = 1, step = 1;  // frame indices start, start + step, ... <= end
  std::vector<int> cam_ids;          // per camera, in the file's order
};
// Throws std::runtime_error naming the file and field; img_fmt must hold exactly two integer fields
// (%d, %i, %u, %x, %X or %o with optional flags and a width below 100; %% for a percent sign) in
// at most 200 characters, and the range at most 100000000 frames.
OmniMvsCapture ReadOmniMvsCapture(const std::string& yaml_path);
// The image file of camera `cam_id` at frame index `index`: img_fmt with its two fields filled.
std::string OmniMvsImageName(const OmniMvsCapture& capture, int cam_id, int index);

// Imports a whole capture as a dataset without ground-truth poses (datasets/FORMAT.md): the rig from
// the config (ReadOmniMvsConfig), images copied from `images_dir` (PNG, gray or RGB), frame k of the
// dataset = the capture's k-th index; `masks_dir` (optional) holds cam<i>.png per camera (0 = invalid)
// copied as static masks. Also writes three perturbed sets (sigma 5 deg, seeds recorded). Returns a
// report of what was imported. Throws naming the file and field on missing or wrong input.
std::string ImportOmniMvsCapture(const std::string& yaml_path, const std::string& images_dir,
                                 const std::string& masks_dir, const std::string& out_dir);

}  // namespace rovo
