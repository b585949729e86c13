// EuRoC/ASL files: camera sensor.yaml, image lists, the ground-truth csv.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "datasets/exchange/exchange.h"
#include "datasets/image_file.h"
#include "datasets/io.h"
#include "rovo/version.h"

namespace rovo {
namespace {

std::vector<double> ReadNumbers(const YAML::Node& node, const std::string& path, const std::string& field) {
  if (!node || !node.IsSequence()) throw std::runtime_error(path + ": " + field + ": missing or not a list");
  std::vector<double> out;
  try {
    for (const YAML::Node& v : node) out.push_back(v.as<double>());
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": " + field + ": not a list of numbers");
  }
  for (double v : out) {
    if (!std::isfinite(v)) throw std::runtime_error(path + ": " + field + ": not finite");
  }
  return out;
}

double SrgbToLinear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
double LinearToSrgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

// The 8-bit grey value of each 8-bit sRGB value triple is costly per pixel (pow), so per channel a
// table of linear values.
const std::vector<double>& LinearTable() {
  static const std::vector<double> table = [] {
    std::vector<double> t(256);
    for (int i = 0; i < 256; ++i) t[static_cast<size_t>(i)] = SrgbToLinear(i / 255.0);
    return t;
  }();
  return table;
}

}  // namespace

uint8_t GrayFromSrgb8(uint8_t r, uint8_t g, uint8_t b) {
  const std::vector<double>& lin = LinearTable();
  const double y = 0.2126 * lin[r] + 0.7152 * lin[g] + 0.0722 * lin[b];
  return static_cast<uint8_t>(std::clamp(std::lround(255.0 * LinearToSrgb(std::clamp(y, 0.0, 1.0))), 0L, 255L));
}

void WriteGrayPng(const std::string& from, const std::string& to) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(to, ec)) {  // resumable: a finished grey image is kept
    try {
      if (ReadImageHeader(to).channels == 1) return;
    } catch (const std::runtime_error&) {
      // written again below
    }
  }
  const bool colour = ReadImageHeader(from).channels >= 3;
  const Image8 image = ReadPng8(from, {colour ? 3 : 1, true});  // alpha dropped
  std::vector<uint8_t> gray(static_cast<size_t>(image.width) * image.height);
  for (size_t i = 0; i < gray.size(); ++i) {
    const uint8_t* p = &image.pixels[i * static_cast<size_t>(image.channels)];
    gray[i] = colour ? GrayFromSrgb8(p[0], p[1], p[2]) : p[0];
  }
  WritePng8(to, image.width, image.height, 1, gray, "rovo " ROVO_VERSION);  // as the renderer writes its PNGs
}

int64_t SecondsToNs(double seconds) { return std::llround(seconds * 1e9); }

std::string EurocSensorYaml(const ExchangeCamera& camera, double rate_hz, const std::string& comment) {
  const Eigen::Matrix4d body_from_sensor = camera.cam_from_rig.Inverse().Matrix4();
  std::vector<double> data;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) data.push_back(body_from_sensor(r, c));
  }
  const KalibrLensFields lens = ToKalibrFields(camera.model, camera.params);
  std::ostringstream out;
  out << "# General sensor definitions.\nsensor_type: camera\ncomment: " << comment << "\n\n"
      << "# Sensor extrinsics wrt. the body-frame (body = rovo rig: x forward, y left, z up; camera: x right,\n"
      << "# y down, z along the optical axis). T_BS maps camera coordinates to body coordinates.\n"
      << "T_BS:\n  cols: 4\n  rows: 4\n  data: " << YamlList(data) << "\n\n"
      << "# Camera specific definitions (Kalibr's names and parameter order; pixel centres at integers).\n"
      << "rate_hz: " << YamlNumber(rate_hz) << "\n"
      << "resolution: [" << camera.width << ", " << camera.height << "]\n"
      << "camera_model: " << lens.camera_model << "\n"
      << "intrinsics: " << YamlList(lens.intrinsics) << "\n"
      << "distortion_model: " << lens.distortion_model << "\n"
      << "distortion_coefficients: " << YamlList(lens.distortion_coeffs) << "\n"
      << "# Full field-of-view cone of the lens in degrees (rovo extension; other readers ignore it).\n"
      << "max_fov_deg: " << YamlNumber(camera.max_fov_deg) << "\n";
  return out.str();
}

ExchangeCamera ReadEurocSensorYaml(const std::string& path, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  ExchangeCamera camera;
  camera.name = name;
  if (!root.IsMap() || !root["T_BS"] || !root["T_BS"].IsMap()) throw std::runtime_error(path + ": T_BS: missing");
  const std::vector<double> data = ReadNumbers(root["T_BS"]["data"], path, "T_BS/data");
  if (data.size() != 16) throw std::runtime_error(path + ": T_BS/data: expected 16 numbers");
  Eigen::Matrix4d body_from_sensor;
  for (int i = 0; i < 16; ++i) body_from_sensor(i / 4, i % 4) = data[static_cast<size_t>(i)];
  const Eigen::Matrix3d rotation = body_from_sensor.topLeftCorner<3, 3>();
  if ((rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 || rotation.determinant() < 0) {
    throw std::runtime_error(path + ": T_BS/data: the 3x3 block is not a rotation");
  }
  camera.cam_from_rig = Rigid3(Eigen::Matrix3d(body_from_sensor.topLeftCorner<3, 3>()),
                               Eigen::Vector3d(body_from_sensor.topRightCorner<3, 1>()))
                            .Inverse();
  const std::vector<double> resolution = ReadNumbers(root["resolution"], path, "resolution");
  if (resolution.size() != 2) throw std::runtime_error(path + ": resolution: expected [width, height]");
  for (double v : resolution) {
    if (!(v >= 1 && v <= 65536 && v == std::floor(v))) {
      throw std::runtime_error(path + ": resolution: expected whole numbers in [1, 65536]");
    }
  }
  camera.width = static_cast<int>(resolution[0]);
  camera.height = static_cast<int>(resolution[1]);
  KalibrLensFields lens;
  if (!root["camera_model"]) throw std::runtime_error(path + ": camera_model: missing");
  try {
    lens.camera_model = root["camera_model"].as<std::string>();
    if (root["distortion_model"]) lens.distortion_model = root["distortion_model"].as<std::string>();
    if (root["max_fov_deg"]) camera.max_fov_deg = root["max_fov_deg"].as<double>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": camera_model, distortion_model or max_fov_deg: wrong type");
  }
  lens.intrinsics = ReadNumbers(root["intrinsics"], path, "intrinsics");
  if (!root["distortion_model"]) lens.distortion_model = "none";
  if (root["distortion_coefficients"]) {
    lens.distortion_coeffs = ReadNumbers(root["distortion_coefficients"], path, "distortion_coefficients");
  }
  FromKalibrFields(lens, path, &camera.model, &camera.params);
  return camera;
}

std::string EurocGroundTruthCsv(const Trajectory& world_from_rig) {
  std::ostringstream out;
  out << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
         "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
         "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  const size_t n = world_from_rig.size();
  for (size_t i = 0; i < n; ++i) {
    // Velocity of the rig origin in the world frame: central difference (one-sided at the ends).
    const size_t a = i > 0 ? i - 1 : i, b = i + 1 < n ? i + 1 : i;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    const double dt = world_from_rig[b].timestamp - world_from_rig[a].timestamp;
    if (b != a && dt > 0) {
      velocity = (world_from_rig[b].world_from_rig.translation - world_from_rig[a].world_from_rig.translation) / dt;
    }
    const Rigid3& pose = world_from_rig[i].world_from_rig;
    const Eigen::Quaterniond& q = pose.rotation;
    out << SecondsToNs(world_from_rig[i].timestamp);
    for (double v : {pose.translation.x(), pose.translation.y(), pose.translation.z(), q.w(), q.x(), q.y(), q.z(),
                     velocity.x(), velocity.y(), velocity.z()}) {
      out << "," << YamlNumber(v);
    }
    out << ",0,0,0,0,0,0\n";
  }
  return out.str();
}

std::vector<std::pair<int64_t, std::string>> ReadEurocImageList(const std::string& path) {
  std::istringstream in(ReadFile(path));
  std::vector<std::pair<int64_t, std::string>> out;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const size_t comma = line.find(',');
    const std::string where = path + ": line " + std::to_string(line_number) + ": ";
    if (comma == std::string::npos) throw std::runtime_error(where + "expected `timestamp [ns],filename`");
    int64_t stamp = 0;
    try {
      size_t used = 0;
      stamp = std::stoll(line.substr(0, comma), &used);
      if (used != comma) throw std::invalid_argument("trailing characters");
    } catch (const std::exception&) {
      throw std::runtime_error(where + "timestamp [ns]: not an integer");
    }
    std::string file = line.substr(comma + 1);
    file.erase(0, file.find_first_not_of(" \t"));
    if (file.empty() || file.find('/') != std::string::npos) throw std::runtime_error(where + "filename: invalid");
    if (!out.empty() && stamp <= out.back().first) throw std::runtime_error(where + "timestamps not increasing");
    out.emplace_back(stamp, file);
  }
  return out;
}

}  // namespace rovo
