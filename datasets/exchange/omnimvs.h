#pragma once
// OmniMVS files (config.yaml of hyu-cvlab/omnimvs-pytorch): the rig calibration and whole captures.
// The file's conventions and their frame change are in datasets/omnimvs_rig.h.

#include <string>
#include <vector>

#include "datasets/omnimvs_rig.h"

namespace rovo {

// Reads an OmniMVS config.yaml (yaml-cpp). Throws std::runtime_error naming the file and field
// (e.g. "cameras[2].poly") on malformed input. `report` (optional) receives one line per camera:
// the refitted inverse's max error and how far the file's own inv_poly is off, in pixels.
Rig ReadOmniMvsConfig(const std::string& yaml_path, std::string* report);

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
