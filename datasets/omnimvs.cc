#include "datasets/omnimvs.h"

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

// /work/shared/data/omnimvs_itbt_config.yaml, cameras 1..4 (rovo4_real).
const OmniMvsCamera kItbtCameras[4] = {
    {{-392.21983020642324, 0.0, 0.0012707685299884767, -1.7456026867522776E-6, 2.257655719602505E-9},
     {611.433, 386.965, -15.0504, -65.1466, -119.568, 27.7131, 355.781, 206.82, -667.654, -1290.67, -985.814, -361.63,
      -52.6566},
     756.215,
     811.661,
     {0.999876, -2.91382E-4, -1.66556E-4},
     1532,
     1600,
     {0.05287133304667693, 0.7411561834637101, 0.02981358273057615, 0.1485451015397448, -6.40692965168468E-5,
      0.14722476953097846},
     220.0},
    {{-393.2636335626606, 0.0, 0.0013030161088532755, -1.8689651365463267E-6, 2.3792432009042225E-9},
     {611.562, 383.54, -22.3448, -47.6112, -41.6246, 10.0601, -37.4865, -278.722, -487.074, -433.682, -222.271,
      -63.4335, -7.90549},
     793.1,
     817.845,
     {1.00028, -0.032979, 0.0327437},
     1532,
     1600,
     {-0.01748403647284513, 2.3597683150646245, -0.051198752155718716, 0.14783151534302344, 6.437518511735495E-5,
      -0.14432158757883862},
     220.0},
    {{-397.8543380457763, 0.0, 0.0014956852335708303, -2.272212930459553E-6, 2.6072875869332744E-9},
     {607.095, 381.297, -21.3511, -43.0875, -56.1323, -71.1995, -22.3406, 318.49, 865.72, 1041.49, 665.323, 220.271,
      29.8479},
     769.23,
     809.789,
     {1.00032, -0.00668755, 0.00648385},
     1532,
     1600,
     {0.006337812304309649, -2.4506787246407957, -0.02780629345273642, -0.14783151534302352, -6.297664270220886E-5,
      -0.15046281430153374},
     220.0},
    {{-392.9083750477403, 0.0, 0.0013458091464087045, -1.9466309855382977E-6, 2.4144190106312376E-9},
     {609.338, 384.453, -20.1199, -45.4585, -36.506, -26.2937, -130.633, -175.538, 77.9449, 334.117, 279.3, 99.8473,
      13.3981},
     797.373,
     819.266,
     {1.00004, -0.0140823, 0.0149072},
     1532,
     1600,
     {0.04659071698722346, -0.8132957468650718, 0.022361144111398168, -0.14854510153974484, 6.267075410156638E-5,
      0.1475596323493941},
     220.0},
};

// Forward ocam parameters [cx, cy, c, d, e, a0..a4] of a file entry; `where` names it in errors.
std::vector<double> ForwardParams(const OmniMvsCamera& cam, const std::string& where) {
  if (cam.poly.empty()) throw std::runtime_error(where + ".poly: no coefficients");
  for (size_t i = 5; i < cam.poly.size(); ++i) {
    if (cam.poly[i] != 0.0) {
      throw std::runtime_error(where + ".poly: degree above 4 is not supported (a" + std::to_string(i) + " != 0)");
    }
  }
  // OCamCalib's convention, as OmniMVS reads it: (row, col) = [c d; e 1] (x_o, y_o) + (center_row,
  // center_col), x_o along rows, and the OpenCV ray is (y_o, x_o, -poly(rho)). Our layout has x
  // along columns and v's y-coefficient 1; scaling the sensor plane by c (X = c y_o, Y = c x_o)
  // gives u = X / c + (e / c) Y + cx, v = (d / c) X + Y + cy, and the same rays with
  // a'_i = a_i c^(1 - i) (see ReadOcamCalibTxt in ocam.h for the same mapping).
  const double c = cam.affine[0], d = cam.affine[1], e = cam.affine[2];
  if (!(std::abs(c) > 1e-6) || !(std::abs(c - d * e) > 1e-9)) {
    throw std::runtime_error(where + ".affine: singular stretch matrix");
  }
  std::vector<double> params = {cam.center_col, cam.center_row, 1.0 / c, e / c, d / c};
  for (size_t i = 0; i < 5; ++i) params.push_back((i < cam.poly.size() ? cam.poly[i] : 0.0) * std::pow(c, 1.0 - i));
  return params;
}

RigCamera ConvertCamera(const OmniMvsCamera& cam, int index, const std::string& where, std::string* report) {
  RigCamera rc;
  rc.name = "cam" + std::to_string(index);
  rc.camera.model = CameraModelId::kOcam;
  rc.camera.width = cam.width;
  rc.camera.height = cam.height;
  rc.camera.max_fov_deg = cam.max_fov_deg;
  const std::vector<double> forward = ForwardParams(cam, where);
  double fit_error_px = 0.0;
  try {
    rc.camera.params = OcamParamsWithFittedInverse(forward, cam.max_fov_deg, &fit_error_px);
  } catch (const std::exception& e) {
    throw std::runtime_error(where + ".poly: " + e.what());
  }
  if (report) {
    char line[256];
    if (cam.inv_poly.empty()) {
      std::snprintf(line, sizeof(line), "%s: refitted inverse polynomial (%zu coefficients) max error %.5f px\n",
                    rc.name.c_str(), rc.camera.params.size() - 10, fit_error_px);
    } else {
      // The file's inverse gives rho in the unscaled sensor plane: b'_i = c b_i.
      std::vector<double> with_file_inverse = forward;
      for (double b : cam.inv_poly) with_file_inverse.push_back(b * cam.affine[0]);
      const double file_error_px = OcamInverseMaxErrorPx(with_file_inverse, cam.max_fov_deg);
      std::snprintf(line, sizeof(line),
                    "%s: file inv_poly (%zu coefficients) off by up to %.3f px; refitted (%zu coefficients) max "
                    "error %.5f px\n",
                    rc.name.c_str(), cam.inv_poly.size(), file_error_px, rc.camera.params.size() - 10, fit_error_px);
    }
    *report += line;
  }
  // cam2rig in the file's frame, then the frame change to ours.
  const Eigen::Vector3d rotation_vector(cam.pose[0], cam.pose[1], cam.pose[2]);
  const Rigid3 file_rig_from_cam =
      Rigid3::FromAxisAngle(rotation_vector, Eigen::Vector3d(cam.pose[3], cam.pose[4], cam.pose[5]));
  const Rigid3 rig_from_file_rig(RigFromOmniMvsRigRotation(), Eigen::Vector3d::Zero());
  rc.cam_from_rig = (rig_from_file_rig * file_rig_from_cam).Inverse();
  return rc;
}

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

Eigen::Matrix3d RigFromOmniMvsRigRotation() {
  Eigen::Matrix3d m;
  m << 1, 0, 0,  //  x_ours = x_file (forward)
      0, 0, 1,   //  y_ours = z_file (left)
      0, -1, 0;  //  z_ours = -y_file (up; the file's y points down)
  return m;
}

std::vector<double> OcamParamsWithFittedInverse(const std::vector<double>& forward_params, double max_fov_deg,
                                                double* max_error_px) {
  const OcamInverseFit fit = FitOcamInversePolynomial(forward_params, max_fov_deg, 0.01);
  if (!(fit.max_error_px < 0.01)) {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "inverse polynomial fit reaches only %.4f px (need < 0.01 px)", fit.max_error_px);
    throw std::runtime_error(buf);
  }
  std::vector<double> params(forward_params.begin(), forward_params.begin() + 10);
  params.insert(params.end(), fit.inverse_poly.begin(), fit.inverse_poly.end());
  if (max_error_px) *max_error_px = fit.max_error_px;
  return params;
}

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
      rig.cameras.push_back(ConvertCamera(cam, static_cast<int>(i), where, report));
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(where + "." + field + ": " + e.what());
    }
  }
  return rig;
}

Rig MakeRovo4RealRig() {
  Rig rig;
  for (int i = 0; i < 4; ++i) {
    rig.cameras.push_back(ConvertCamera(kItbtCameras[i], i, "rovo4_real cameras[" + std::to_string(i) + "]", nullptr));
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
