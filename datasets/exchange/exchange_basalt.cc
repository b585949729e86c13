// Basalt calibration JSON: the cereal object under "value0" that Basalt's loader needs whole
// (T_imu_cam per camera with the rig as the IMU, intrinsics with camera_type, integer
// resolutions, IMU biases and noise, cam_time_offset_ns, vignette).
#include <cmath>
#include <stdexcept>

#include "datasets/exchange/exchange.h"
#include "datasets/io.h"

namespace rovo {
namespace {

nlohmann::json PoseJson(const Rigid3& b_from_a) {
  const Eigen::Quaterniond q = b_from_a.rotation.normalized();
  return {{"px", b_from_a.translation.x()},
          {"py", b_from_a.translation.y()},
          {"pz", b_from_a.translation.z()},
          {"qx", q.x()},
          {"qy", q.y()},
          {"qz", q.z()},
          {"qw", q.w()}};
}

// Basalt's intrinsics keys per camera type, in rovo's parameter order (lens_fit.h).
std::vector<std::string> IntrinsicKeys(ExchangeLensModel model) {
  switch (model) {
    case ExchangeLensModel::kDoubleSphere:
      return {"fx", "fy", "cx", "cy", "xi", "alpha"};
    case ExchangeLensModel::kExtendedUnified:
      return {"fx", "fy", "cx", "cy", "alpha", "beta"};
    case ExchangeLensModel::kKannalaBrandt4:
      return {"fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"};
    case ExchangeLensModel::kOmniRadtan:
      break;
  }
  throw std::invalid_argument("Basalt has no omni camera type: export with ds, eucm or kb4");
}

double Number(const nlohmann::json& object, const std::string& key, const std::string& what) {
  if (!object.is_object() || !object.contains(key) || !object[key].is_number()) {
    throw std::runtime_error(what + "/" + key + ": missing or not a number");
  }
  const double value = object[key].get<double>();
  if (!std::isfinite(value)) throw std::runtime_error(what + "/" + key + ": not finite");
  return value;
}

}  // namespace

nlohmann::json BasaltCalibrationJson(const std::vector<ExchangeCamera>& cameras) {
  nlohmann::json value = nlohmann::json::object();
  value["T_imu_cam"] = nlohmann::json::array();
  value["intrinsics"] = nlohmann::json::array();
  value["resolution"] = nlohmann::json::array();
  for (const ExchangeCamera& camera : cameras) {
    value["T_imu_cam"].push_back(PoseJson(camera.cam_from_rig.Inverse()));
    const std::vector<std::string> keys = IntrinsicKeys(camera.model);
    nlohmann::json intrinsics = nlohmann::json::object();
    for (size_t i = 0; i < keys.size(); ++i) intrinsics[keys[i]] = camera.params.at(i);
    value["intrinsics"].push_back({{"camera_type", ExchangeLensModelName(camera.model)}, {"intrinsics", intrinsics}});
    value["resolution"].push_back({camera.width, camera.height});
  }
  // No IMU in a rovo dataset: zero biases and Basalt's EuRoC noise figures as placeholders.
  value["calib_accel_bias"] = std::vector<double>(9, 0.0);
  value["calib_gyro_bias"] = std::vector<double>(12, 0.0);
  value["imu_update_rate"] = 200.0;
  value["accel_noise_std"] = {0.016, 0.016, 0.016};
  value["gyro_noise_std"] = {0.000282, 0.000282, 0.000282};
  value["accel_bias_std"] = {0.001, 0.001, 0.001};
  value["gyro_bias_std"] = {0.0001, 0.0001, 0.0001};
  value["T_mocap_world"] = PoseJson(Rigid3::Identity());
  value["T_imu_marker"] = PoseJson(Rigid3::Identity());
  value["mocap_time_offset_ns"] = 0;
  value["mocap_to_imu_offset_ns"] = 0;
  value["cam_time_offset_ns"] = 0;
  value["vignette"] = nlohmann::json::array();
  return {{"value0", value}};
}

std::vector<ExchangeCamera> ReadBasaltCalibration(const std::string& path) {
  const nlohmann::json root = ReadJsonFile(path);
  if (!root.contains("value0") || !root["value0"].is_object()) throw std::runtime_error(path + ": /value0: missing");
  const nlohmann::json& value = root["value0"];
  for (const char* key : {"T_imu_cam", "intrinsics", "resolution"}) {
    if (!value.contains(key) || !value[key].is_array()) {
      throw std::runtime_error(path + ": /value0/" + key + ": missing or not an array");
    }
  }
  const size_t n = value["intrinsics"].size();
  if (n == 0 || value["T_imu_cam"].size() != n || value["resolution"].size() != n) {
    throw std::runtime_error(path + ": /value0: T_imu_cam, intrinsics and resolution must have one entry per camera");
  }
  std::vector<ExchangeCamera> cameras;
  for (size_t i = 0; i < n; ++i) {
    const std::string where = path + ": /value0/";
    const std::string index = "/" + std::to_string(i);
    ExchangeCamera camera;
    camera.name = "cam" + std::to_string(i);
    const nlohmann::json& lens = value["intrinsics"][i];
    if (!lens.contains("camera_type") || !lens["camera_type"].is_string()) {
      throw std::runtime_error(where + "intrinsics" + index + "/camera_type: missing");
    }
    const std::string type = lens["camera_type"].get<std::string>();
    if (type != "ds" && type != "eucm" && type != "kb4") {
      throw std::runtime_error(where + "intrinsics" + index + "/camera_type: '" + type +
                               "' has no rovo camera model (ds, eucm and kb4 do)");
    }
    camera.model = ExchangeLensModelFromName(type);
    for (const std::string& key : IntrinsicKeys(camera.model)) {
      camera.params.push_back(
          Number(lens.value("intrinsics", nlohmann::json()), key, where + "intrinsics" + index + "/intrinsics"));
    }
    const nlohmann::json& resolution = value["resolution"][i];
    if (!resolution.is_array() || resolution.size() != 2 || !resolution[0].is_number_integer() ||
        !resolution[1].is_number_integer()) {
      throw std::runtime_error(where + "resolution" + index + ": expected [width, height] integers");
    }
    for (const nlohmann::json& v : resolution) {
      if (v.get<int64_t>() < 1 || v.get<int64_t>() > 65536) {
        throw std::runtime_error(where + "resolution" + index + ": expected [width, height] in [1, 65536]");
      }
    }
    camera.width = resolution[0].get<int>();
    camera.height = resolution[1].get<int>();
    const nlohmann::json& pose = value["T_imu_cam"][i];
    const std::string pose_what = where + "T_imu_cam" + index;
    const Eigen::Quaterniond q(Number(pose, "qw", pose_what), Number(pose, "qx", pose_what),
                               Number(pose, "qy", pose_what), Number(pose, "qz", pose_what));
    if (std::abs(q.norm() - 1.0) > 1e-6) throw std::runtime_error(pose_what + ": quaternion is not normalised");
    const Eigen::Vector3d t(Number(pose, "px", pose_what), Number(pose, "py", pose_what),
                            Number(pose, "pz", pose_what));
    camera.cam_from_rig = Rigid3(q, t).Inverse();
    cameras.push_back(camera);
  }
  return cameras;
}

}  // namespace rovo
