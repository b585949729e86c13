#include "datasets/exchange/omnimvs.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/ocam.h"
#include "rovo/version.h"

namespace rovo {
namespace {

// "[n, v0, .., v(n-1)]" with n equal to the number of values that follow.
std::vector<double> CountedList(const YAML::Node& node, const std::string& where) {
  if (!node || !node.IsSequence() || node.size() < 1) {
    throw std::runtime_error(where + ": expected a list [count, coefficients...]");
  }
  const double count = node[0].as<double>();
  if (count != static_cast<double>(node.size() - 1)) {
    throw std::runtime_error(where + ": count " + std::to_string(count) + " but " + std::to_string(node.size() - 1) +
                             " coefficients follow");
  }
  std::vector<double> values;
  for (size_t i = 1; i < node.size(); ++i) values.push_back(node[i].as<double>());
  return values;
}

std::vector<double> FixedList(const YAML::Node& node, size_t size, const std::string& where) {
  if (!node || !node.IsSequence() || node.size() != size) {
    throw std::runtime_error(where + ": expected a list of " + std::to_string(size) + " numbers");
  }
  std::vector<double> values;
  for (size_t i = 0; i < size; ++i) values.push_back(node[i].as<double>());
  return values;
}

void RequireFinite(const std::vector<double>& values, const std::string& where) {
  for (double v : values) {
    if (!std::isfinite(v)) throw std::runtime_error(where + ": NaN or Inf");
  }
}

}  // namespace

Rig ReadOmniMvsConfig(const std::string& yaml_path, std::string* report) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(yaml_path + ": cannot parse YAML: " + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error(yaml_path + ": expected a map with `cameras`");
  const YAML::Node cameras = root["cameras"];
  if (!cameras || !cameras.IsSequence() || cameras.size() == 0) {
    throw std::runtime_error(yaml_path + ": cameras: expected a non-empty list");
  }
  if (report) report->clear();
  Rig rig;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const YAML::Node node = cameras[i];
    const std::string where = yaml_path + ": cameras[" + std::to_string(i) + "]";
    std::string field = "model";
    try {
      const std::string model = node["model"] ? node["model"].as<std::string>() : "";
      if (model != "ocam") throw std::runtime_error(where + ".model: `" + model + "` is not supported (only ocam)");
      OmniMvsCamera cam;
      field = "poly";
      cam.poly = CountedList(node["poly"], where + ".poly");
      RequireFinite(cam.poly, where + ".poly");
      field = "inv_poly";
      if (node["inv_poly"]) {
        cam.inv_poly = CountedList(node["inv_poly"], where + ".inv_poly");
        RequireFinite(cam.inv_poly, where + ".inv_poly");
      }
      field = "center";
      const std::vector<double> center = FixedList(node["center"], 2, where + ".center");
      RequireFinite(center, where + ".center");
      cam.center_row = center[0];
      cam.center_col = center[1];
      field = "affine";
      const std::vector<double> affine = FixedList(node["affine"], 3, where + ".affine");
      RequireFinite(affine, where + ".affine");
      for (int k = 0; k < 3; ++k) cam.affine[k] = affine[k];
      field = "image_size";
      const std::vector<double> size = FixedList(node["image_size"], 2, where + ".image_size");
      if (!(size[0] >= 1 && size[1] >= 1 && size[0] <= 65536 && size[1] <= 65536 && size[0] == std::floor(size[0]) &&
            size[1] == std::floor(size[1]))) {
        throw std::runtime_error(where + ".image_size: expected whole numbers [height, width] in [1, 65536]");
      }
      cam.height = static_cast<int>(size[0]);
      cam.width = static_cast<int>(size[1]);
      field = "pose";
      const std::vector<double> pose = FixedList(node["pose"], 6, where + ".pose");
      RequireFinite(pose, where + ".pose");
      for (int k = 0; k < 6; ++k) cam.pose[k] = pose[k];
      field = "max_fov";
      cam.max_fov_deg = node["max_fov"] ? node["max_fov"].as<double>() : 220.0;
      if (!(cam.max_fov_deg > 0.0 && cam.max_fov_deg < 360.0)) {
        throw std::runtime_error(where + ".max_fov: expected degrees in (0, 360)");
      }
      field = "poly";
      rig.cameras.push_back(OmniMvsRigCamera(cam, static_cast<int>(i), where, report));
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(where + "." + field + ": " + e.what());
    }
  }
  return rig;
}

}  // namespace rovo

namespace rovo {

namespace {

// Why `format` is not a printf pattern of exactly two int arguments, or "" when it is.
std::string ImageFormatProblem(const std::string& format) {
  if (format.size() > 200) return "longer than 200 characters";
  int fields = 0;
  for (size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') continue;
    if (++i < format.size() && format[i] == '%') continue;
    while (i < format.size() && std::strchr("-+ 0#", format[i])) ++i;
    size_t width_digits = 0;
    while (i < format.size() && std::isdigit(static_cast<unsigned char>(format[i]))) ++i, ++width_digits;
    if (i >= format.size() || width_digits > 2 || !std::strchr("diuxXo", format[i])) {
      return "field " + std::to_string(fields + 1) +
             " is not %d, %i, %u, %x, %X or %o with flags and a width below 100";
    }
    ++fields;
  }
  if (fields != 2) return std::to_string(fields) + " printf fields, expected 2 (camera id, frame index)";
  return "";
}

}  // namespace

std::string OmniMvsImageName(const OmniMvsCapture& capture, int cam_id, int index) {
  const std::string problem = ImageFormatProblem(capture.img_fmt);
  if (!problem.empty()) throw std::invalid_argument("img_fmt `" + capture.img_fmt + "`: " + problem);
  char name[512];
  const int n = std::snprintf(name, sizeof name, capture.img_fmt.c_str(), cam_id, index);
  if (n < 0 || n >= static_cast<int>(sizeof name)) {
    throw std::invalid_argument("img_fmt `" + capture.img_fmt + "`: the file name is too long");
  }
  return name;
}

OmniMvsCapture ReadOmniMvsCapture(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(yaml_path + ": cannot parse YAML: " + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error(yaml_path + ": expected a map with `dataset` and `cameras`");
  OmniMvsCapture capture;
  const YAML::Node dataset = root["dataset"];
  std::string field = "dataset";
  try {
    if (dataset) {
      field = "dataset.img_fmt";
      if (dataset["img_fmt"]) capture.img_fmt = dataset["img_fmt"].as<std::string>();
      field = "dataset.start";
      if (dataset["start"]) capture.start = dataset["start"].as<int>();
      field = "dataset.end";
      capture.end = dataset["end"] ? dataset["end"].as<int>() : capture.start;
      field = "dataset.step";
      if (dataset["step"]) capture.step = dataset["step"].as<int>();
    }
    const YAML::Node cameras = root["cameras"];
    for (size_t i = 0; cameras && i < cameras.size(); ++i) {
      field = "cameras[" + std::to_string(i) + "].cam_id";
      capture.cam_ids.push_back(cameras[i]["cam_id"] ? cameras[i]["cam_id"].as<int>() : static_cast<int>(i) + 1);
    }
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(yaml_path + ": " + field + ": " + e.what());
  }
  if (capture.step < 1 || capture.end < capture.start) {
    throw std::runtime_error(yaml_path + ": dataset: start " + std::to_string(capture.start) + ", end " +
                             std::to_string(capture.end) + ", step " + std::to_string(capture.step) +
                             " is not a non-empty range");
  }
  const int64_t frames = (static_cast<int64_t>(capture.end) - capture.start) / capture.step + 1;
  if (frames > 100000000) {
    throw std::runtime_error(yaml_path + ": dataset: start " + std::to_string(capture.start) + ", end " +
                             std::to_string(capture.end) + ", step " + std::to_string(capture.step) + " gives " +
                             std::to_string(frames) + " frames (at most 100000000)");
  }
  const std::string problem = ImageFormatProblem(capture.img_fmt);
  if (!problem.empty()) {
    throw std::runtime_error(yaml_path + ": dataset.img_fmt: `" + capture.img_fmt + "`: " + problem);
  }
  return capture;
}

std::string ImportOmniMvsCapture(const std::string& yaml_path, const std::string& images_dir,
                                 const std::string& masks_dir, const std::string& out_dir) {
  namespace fs = std::filesystem;
  std::string report;
  DatasetInfo info;
  info.rig = ReadOmniMvsConfig(yaml_path, &report);
  const OmniMvsCapture capture = ReadOmniMvsCapture(yaml_path);
  if (capture.cam_ids.size() != info.rig.cameras.size()) {
    throw std::runtime_error(yaml_path + ": cameras: cam_id count differs from the camera count");
  }
  info.generator = "rovo dataset import-omnimvs";
  info.generator_version = ROVO_VERSION;
  info.preset = "";
  info.scene_hash = "";
  info.frame_rate = 1.0;
  info.has_ground_truth = false;
  info.has_static_masks = !masks_dir.empty();
  std::vector<int> indices;
  for (int64_t k = capture.start; k <= capture.end; k += capture.step) indices.push_back(static_cast<int>(k));
  info.frame_count = static_cast<int>(indices.size());
  fs::create_directories(out_dir);
  for (size_t c = 0; c < info.rig.cameras.size(); ++c) {
    const std::string& name = info.rig.cameras[c].name;
    fs::create_directories(fs::path(out_dir) / name);
    for (size_t f = 0; f < indices.size(); ++f) {
      const fs::path source = fs::path(images_dir) / OmniMvsImageName(capture, capture.cam_ids[c], indices[f]);
      if (!fs::is_regular_file(source)) {
        throw std::runtime_error(source.string() + ": missing (camera " + std::to_string(capture.cam_ids[c]) +
                                 ", frame index " + std::to_string(indices[f]) + ", from " + yaml_path +
                                 ": dataset.img_fmt)");
      }
      if (source.extension() != ".png") throw std::runtime_error(source.string() + ": only PNG images are imported");
      const std::string target = ImagePath(out_dir, name, static_cast<int>(f));
      WriteFileAtomic(target, ReadFile(source.string()));
    }
    if (info.has_static_masks) {
      const fs::path mask = fs::path(masks_dir) / (name + ".png");
      if (!fs::is_regular_file(mask))
        throw std::runtime_error(mask.string() + ": missing static mask of camera " + name);
      fs::create_directories(fs::path(out_dir) / "static_masks");
      WriteFileAtomic(StaticMaskPath(out_dir, name), ReadFile(mask.string()));
    }
  }
  for (int k = 0; k < 3; ++k) info.perturbed.push_back(PerturbExtrinsics(info.rig, 5.0, 0.0, 1000003ull + k));
  WriteDatasetInfo(out_dir, info);
  report += "imported " + std::to_string(info.frame_count) + " frames x " + std::to_string(info.rig.NumCameras()) +
            " cameras into " + out_dir + " (no ground-truth poses" + (info.has_static_masks ? ", static masks" : "") +
            ")\n";
  return report;
}

}  // namespace rovo
