// Kalibr camchain.yaml: per camera camera_model, intrinsics, distortion_model, distortion_coeffs,
// resolution, rostopic, cam_overlaps, T_cn_cnm1 (camN_from_cam(N-1), from cam1 on) and T_cam_imu
// (cam_from_rig: the rig stands in for Kalibr's IMU).
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "datasets/exchange/exchange.h"
#include "datasets/io.h"

namespace rovo {
namespace {

void WriteMatrix(std::ostringstream& out, const std::string& key, const Rigid3& b_from_a) {
  const Eigen::Matrix4d m = b_from_a.Matrix4();
  out << "  " << key << ":\n";
  for (int r = 0; r < 4; ++r) out << "  - " << YamlList({m(r, 0), m(r, 1), m(r, 2), m(r, 3)}) << "\n";
}

std::vector<double> Numbers(const YAML::Node& node, const std::string& what) {
  if (!node || !node.IsSequence()) throw std::runtime_error(what + ": missing or not a list");
  std::vector<double> out;
  try {
    for (const YAML::Node& v : node) out.push_back(v.as<double>());
  } catch (const YAML::Exception&) {
    throw std::runtime_error(what + ": not a list of numbers");
  }
  for (double v : out) {
    if (!std::isfinite(v)) throw std::runtime_error(what + ": not finite");
  }
  return out;
}

// [width, height]: whole numbers in [1, 65536] (the dataset format's bound).
void ReadResolution(const YAML::Node& node, const std::string& what, int* width, int* height) {
  const std::vector<double> resolution = Numbers(node, what);
  if (resolution.size() != 2) throw std::runtime_error(what + ": expected [width, height]");
  for (double v : resolution) {
    if (!(v >= 1 && v <= 65536 && v == std::floor(v))) {
      throw std::runtime_error(what + ": expected whole numbers in [1, 65536]");
    }
  }
  *width = static_cast<int>(resolution[0]);
  *height = static_cast<int>(resolution[1]);
}

std::string Text(const YAML::Node& node, const std::string& what) {
  try {
    return node.as<std::string>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(what + ": not a string");
  }
}

Rigid3 ReadMatrix(const YAML::Node& node, const std::string& what) {
  if (!node.IsSequence() || node.size() != 4) throw std::runtime_error(what + ": expected 4 rows");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const std::vector<double> row = Numbers(node[r], what + "[" + std::to_string(r) + "]");
    if (row.size() != 4) throw std::runtime_error(what + "[" + std::to_string(r) + "]: expected 4 numbers");
    for (int c = 0; c < 4; ++c) m(r, c) = row[static_cast<size_t>(c)];
  }
  const Eigen::Matrix3d rotation = m.topLeftCorner<3, 3>();
  if ((rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 || rotation.determinant() < 0) {
    throw std::runtime_error(what + ": the 3x3 block is not a rotation");
  }
  return Rigid3(rotation, Eigen::Vector3d(m.topRightCorner<3, 1>()));
}

// Cameras i and j overlap when the angle between their optical axes is below the mean of their
// FOVs (the two cones intersect).
std::vector<int> Overlaps(const std::vector<ExchangeCamera>& cameras, size_t i) {
  std::vector<int> out;
  const Eigen::Vector3d axis_i = cameras[i].cam_from_rig.rotation.conjugate() * Eigen::Vector3d::UnitZ();
  for (size_t j = 0; j < cameras.size(); ++j) {
    if (j == i) continue;
    const Eigen::Vector3d axis_j = cameras[j].cam_from_rig.rotation.conjugate() * Eigen::Vector3d::UnitZ();
    const double angle_deg = std::atan2(axis_i.cross(axis_j).norm(), axis_i.dot(axis_j)) * 180.0 / M_PI;
    if (angle_deg < 0.5 * (cameras[i].max_fov_deg + cameras[j].max_fov_deg)) out.push_back(static_cast<int>(j));
  }
  return out;
}

}  // namespace

std::string KalibrCamchainYaml(const std::vector<ExchangeCamera>& cameras, const std::string& header) {
  std::ostringstream out;
  std::istringstream header_lines(header);
  for (std::string line; std::getline(header_lines, line);) out << "# " << line << "\n";
  for (size_t i = 0; i < cameras.size(); ++i) {
    const ExchangeCamera& camera = cameras[i];
    const KalibrLensFields lens = ToKalibrFields(camera.model, camera.params);
    out << "cam" << i << ":\n";
    if (i > 0) WriteMatrix(out, "T_cn_cnm1", camera.cam_from_rig * cameras[i - 1].cam_from_rig.Inverse());
    WriteMatrix(out, "T_cam_imu", camera.cam_from_rig);
    std::string overlaps;
    for (int j : Overlaps(cameras, i)) overlaps += (overlaps.empty() ? "" : ", ") + std::to_string(j);
    out << "  cam_overlaps: [" << overlaps << "]\n"
        << "  camera_model: " << lens.camera_model << "\n"
        << "  distortion_coeffs: " << YamlList(lens.distortion_coeffs) << "\n"
        << "  distortion_model: " << lens.distortion_model << "\n"
        << "  intrinsics: " << YamlList(lens.intrinsics) << "\n"
        << "  resolution: [" << camera.width << ", " << camera.height << "]\n"
        << "  rostopic: /" << camera.name << "/image_raw\n";
  }
  return out.str();
}

std::vector<ExchangeCamera> ReadKalibrCamchain(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error(path + ": expected a map of cameras cam0, cam1, ...");
  std::vector<ExchangeCamera> cameras;
  bool all_have_imu = true;
  for (int i = 0; root["cam" + std::to_string(i)]; ++i) {
    const std::string key = "cam" + std::to_string(i);
    const std::string what = path + ": " + key;
    const YAML::Node node = root[key];
    ExchangeCamera camera;
    camera.name = key;
    KalibrLensFields lens;
    if (!node.IsMap() || !node["camera_model"]) throw std::runtime_error(what + "/camera_model: missing");
    lens.camera_model = Text(node["camera_model"], what + "/camera_model");
    lens.intrinsics = Numbers(node["intrinsics"], what + "/intrinsics");
    lens.distortion_model =
        node["distortion_model"] ? Text(node["distortion_model"], what + "/distortion_model") : "none";
    if (node["distortion_coeffs"])
      lens.distortion_coeffs = Numbers(node["distortion_coeffs"], what + "/distortion_coeffs");
    FromKalibrFields(lens, what, &camera.model, &camera.params);
    ReadResolution(node["resolution"], what + "/resolution", &camera.width, &camera.height);
    if (node["T_cam_imu"]) {
      camera.cam_from_rig = ReadMatrix(node["T_cam_imu"], what + "/T_cam_imu");
    } else {
      all_have_imu = false;
    }
    cameras.push_back(camera);
  }
  if (cameras.empty()) throw std::runtime_error(path + ": cam0: missing (no cameras)");
  if (!all_have_imu) {
    // Without T_cam_imu on every camera the rig frame is camera 0's (chain from T_cn_cnm1).
    for (size_t i = 0; i < cameras.size(); ++i) {
      if (i == 0) {
        cameras[i].cam_from_rig = Rigid3::Identity();
      } else {
        const YAML::Node chain = root[cameras[i].name]["T_cn_cnm1"];
        if (!chain) {
          throw std::runtime_error(path + ": " + cameras[i].name + "/T_cn_cnm1: missing (needed without T_cam_imu)");
        }
        cameras[i].cam_from_rig =
            ReadMatrix(chain, path + ": " + cameras[i].name + "/T_cn_cnm1") * cameras[i - 1].cam_from_rig;
      }
    }
  }
  return cameras;
}

}  // namespace rovo
