// The IMU in EuRoC, Kalibr and Basalt exports and imports (exchange_imu.h).
#include "datasets/exchange/exchange_imu.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "datasets/continuous_trajectory.h"
#include "datasets/exchange/exchange.h"
#include "datasets/imu_model.h"
#include "datasets/io.h"

namespace rovo {
namespace fs = std::filesystem;
namespace {

constexpr const char* kEurocImuCsvHeader =
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
    "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";

std::string Imu0(const std::string& dir, const std::string& file) {
  return (fs::path(dir) / "mav0" / "imu0" / file).string();
}
std::string GroundTruthCsv(const std::string& dir) {
  return (fs::path(dir) / "mav0" / "state_groundtruth_estimate0" / "data.csv").string();
}

std::string ImuCsv(const std::vector<ImuSample>& samples) {
  std::string out = kEurocImuCsvHeader;
  for (const ImuSample& s : samples) {
    out += std::to_string(SecondsToNs(s.timestamp));
    for (int i = 0; i < 3; ++i) out += "," + YamlNumber(s.angular_velocity[i]);
    for (int i = 0; i < 3; ++i) out += "," + YamlNumber(s.linear_acceleration[i]);
    out += "\n";
  }
  return out;
}

std::vector<double> Row(const Rigid3& b_from_a) {
  const Eigen::Matrix4d m = b_from_a.Matrix4();
  std::vector<double> data;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) data.push_back(m(r, c));
  }
  return data;
}

// EuRoC's ground-truth columns at every IMU sample, the body being the IMU (frame S).
std::string ImuGroundTruthCsv(const Trajectory& frames, const DatasetInfo& info, const ImuStreams& streams) {
  const std::vector<ImuGroundTruthState> states =
      ImuGroundTruthStream(ContinuousTrajectory(frames), *info.rig.imu_from_rig, *info.imu);
  if (states.size() != streams.bias.size()) {
    throw std::runtime_error("imu/bias.csv: " + std::to_string(streams.bias.size()) + " samples, the IMU record " +
                             std::to_string(states.size()));
  }
  std::ostringstream out;
  out << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
         "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
         "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  for (size_t k = 0; k < states.size(); ++k) {
    const double t = states[k].timestamp - info.imu->time_offset_s;  // the dataset's (camera) clock
    const Rigid3& world_from_imu = states[k].world_from_imu;
    const Eigen::Vector3d& velocity = states[k].velocity;
    const Eigen::Quaterniond& q = world_from_imu.rotation;
    out << SecondsToNs(t);
    for (double v : {world_from_imu.translation.x(), world_from_imu.translation.y(), world_from_imu.translation.z(),
                     q.w(), q.x(), q.y(), q.z(), velocity.x(), velocity.y(), velocity.z()}) {
      out << "," << YamlNumber(v);
    }
    const ImuBiasSample& b = streams.bias[k];
    for (int i = 0; i < 3; ++i) out << "," << YamlNumber(b.gyroscope_bias[i]);
    for (int i = 0; i < 3; ++i) out << "," << YamlNumber(b.accelerometer_bias[i]);
    out << "\n";
  }
  return out.str();
}

// Rows of a EuRoC csv: (timestamp ns, the other columns), `columns` numbers after the stamp.
std::vector<std::pair<int64_t, std::vector<double>>> ReadCsvRows(const std::string& path, size_t columns) {
  std::istringstream in(ReadFile(path));
  std::vector<std::pair<int64_t, std::vector<double>>> rows;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::string where = path + ": line " + std::to_string(number) + ": ";
    std::istringstream fields(line);
    std::string field;
    std::vector<std::string> parts;
    while (std::getline(fields, field, ',')) parts.push_back(field);
    if (parts.size() != columns + 1) {
      throw std::runtime_error(where + std::to_string(parts.size()) + " columns, expected " +
                               std::to_string(columns + 1));
    }
    std::pair<int64_t, std::vector<double>> row;
    try {
      size_t used = 0;
      row.first = std::stoll(parts[0], &used);
      if (used != parts[0].size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw std::runtime_error(where + "timestamp [ns]: not an integer");
    }
    for (size_t c = 1; c < parts.size(); ++c) {
      double v = 0;
      try {
        size_t used = 0;
        v = std::stod(parts[c], &used);
        if (parts[c].find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument("trailing");
      } catch (const std::exception&) {
        throw std::runtime_error(where + "column " + std::to_string(c + 1) + ": not a number");
      }
      if (!std::isfinite(v)) throw std::runtime_error(where + "column " + std::to_string(c + 1) + ": not finite");
      row.second.push_back(v);
    }
    if (!rows.empty() && row.first <= rows.back().first) throw std::runtime_error(where + "timestamps not increasing");
    rows.push_back(std::move(row));
  }
  return rows;
}

std::vector<ImuSample> ReadEurocImuCsv(const std::string& path) {
  std::vector<ImuSample> out;
  for (const auto& [stamp, v] : ReadCsvRows(path, 6)) {
    out.push_back(
        {static_cast<double>(stamp) * 1e-9, Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Vector3d(v[3], v[4], v[5])});
  }
  return out;
}

double YamlDouble(const YAML::Node& root, const std::string& key, const std::string& path, bool required,
                  double fallback) {
  if (!root[key]) {
    if (required) throw std::runtime_error(path + ": " + key + ": missing");
    return fallback;
  }
  double v = 0;
  try {
    v = root[key].as<double>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": " + key + ": not a number");
  }
  if (!std::isfinite(v)) throw std::runtime_error(path + ": " + key + ": not finite");
  return v;
}

std::vector<double> YamlDoubles(const YAML::Node& root, const std::string& key, const std::string& path, size_t count) {
  std::vector<double> out;
  try {
    for (const YAML::Node& v : root[key]) out.push_back(v.as<double>());
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": " + key + ": not a list of numbers");
  }
  if (out.size() != count)
    throw std::runtime_error(path + ": " + key + ": expected " + std::to_string(count) + " numbers");
  for (double v : out) {
    if (!std::isfinite(v)) throw std::runtime_error(path + ": " + key + ": not finite");
  }
  return out;
}

// mav0/imu0/sensor.yaml: EuRoC's rate and noise keys, and the rovo_* extension when present.
void ReadImuSensorYaml(const std::string& path, ExchangeImu* imu) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error(path + ": not a YAML map");
  ImuRecord& r = imu->record;
  r.rate_hz = YamlDouble(root, "rate_hz", path, true, 0);
  if (!(r.rate_hz > 0)) throw std::runtime_error(path + ": rate_hz: not positive");
  r.noise.gyroscope_noise_density = YamlDouble(root, "gyroscope_noise_density", path, true, 0);
  r.noise.gyroscope_random_walk = YamlDouble(root, "gyroscope_random_walk", path, true, 0);
  r.noise.accelerometer_noise_density = YamlDouble(root, "accelerometer_noise_density", path, true, 0);
  r.noise.accelerometer_random_walk = YamlDouble(root, "accelerometer_random_walk", path, true, 0);
  r.time_offset_s = YamlDouble(root, "rovo_time_offset_s", path, false, 0.0);
  r.gravity_m_s2 = YamlDouble(root, "rovo_gravity_m_s2", path, false, 9.81);
  r.noise_profile = "custom";
  try {
    if (root["rovo_noise_profile"]) r.noise_profile = root["rovo_noise_profile"].as<std::string>();
    if (root["rovo_seed"]) r.seed = root["rovo_seed"].as<uint64_t>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": rovo_noise_profile or rovo_seed: wrong type");
  }
  if (root["rovo_gyroscope_initial_bias"]) {
    const std::vector<double> b = YamlDoubles(root, "rovo_gyroscope_initial_bias", path, 3);
    r.noise.gyroscope_initial_bias = Eigen::Vector3d(b[0], b[1], b[2]);
  }
  if (root["rovo_accelerometer_initial_bias"]) {
    const std::vector<double> b = YamlDoubles(root, "rovo_accelerometer_initial_bias", path, 3);
    r.noise.accelerometer_initial_bias = Eigen::Vector3d(b[0], b[1], b[2]);
  }
  if (root["rovo_imu_from_rig"]) {
    const std::vector<double> m = YamlDoubles(root, "rovo_imu_from_rig", path, 16);
    Eigen::Matrix3d rotation;
    for (size_t i = 0; i < 9; ++i) {
      rotation(static_cast<Eigen::Index>(i / 3), static_cast<Eigen::Index>(i % 3)) = m[4 * (i / 3) + i % 3];
    }
    if ((rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 || rotation.determinant() < 0) {
      throw std::runtime_error(path + ": rovo_imu_from_rig: the 3x3 block is not a rotation");
    }
    imu->imu_from_rig = Rigid3(rotation, Eigen::Vector3d(m[3], m[7], m[11]));
  }
}

}  // namespace

std::vector<Rigid3> ExchangeCamFromBody(const DatasetInfo& info, const std::vector<Rigid3>& cam_from_rig) {
  if (!info.imu || !info.rig.imu_from_rig) return cam_from_rig;
  const Rigid3 rig_from_imu = info.rig.imu_from_rig->Inverse();
  std::vector<Rigid3> out;
  out.reserve(cam_from_rig.size());
  for (const Rigid3& c : cam_from_rig) out.push_back(c * rig_from_imu);
  return out;
}

std::string EurocImuSensorYaml(const ImuRecord& imu, const Rigid3& imu_from_rig) {
  const ImuNoise& n = imu.noise;
  auto vec = [](const Eigen::Vector3d& v) { return YamlList({v.x(), v.y(), v.z()}); };
  std::ostringstream out;
  out << "# General sensor definitions.\nsensor_type: imu\ncomment: rovo IMU, noise profile " << imu.noise_profile
      << "\n\n# Sensor extrinsics wrt. the body-frame (the body is this IMU).\nT_BS:\n  cols: 4\n  rows: 4\n  data: "
      << YamlList(Row(Rigid3::Identity())) << "\nrate_hz: " << YamlNumber(imu.rate_hz) << "\n\n"
      << "# inertial sensor noise model parameters (static)\n"
      << "gyroscope_noise_density: " << YamlNumber(n.gyroscope_noise_density) << "  # [ rad / s / sqrt(Hz) ]\n"
      << "gyroscope_random_walk: " << YamlNumber(n.gyroscope_random_walk) << "  # [ rad / s^2 / sqrt(Hz) ]\n"
      << "accelerometer_noise_density: " << YamlNumber(n.accelerometer_noise_density) << "  # [ m / s^2 / sqrt(Hz) ]\n"
      << "accelerometer_random_walk: " << YamlNumber(n.accelerometer_random_walk) << "  # [ m / s^3 / sqrt(Hz) ]\n\n"
      << "# rovo extension (other readers ignore it): the rest of the IMU record and the mount on the rig,\n"
      << "# x_in_imu = rovo_imu_from_rig x_in_rig (row-major 4x4). t_imu = t_cam + rovo_time_offset_s.\n"
      << "rovo_noise_profile: " << imu.noise_profile << "\nrovo_seed: " << imu.seed
      << "\nrovo_time_offset_s: " << YamlNumber(imu.time_offset_s)
      << "\nrovo_gravity_m_s2: " << YamlNumber(imu.gravity_m_s2)
      << "\nrovo_gyroscope_initial_bias: " << vec(n.gyroscope_initial_bias)
      << "\nrovo_accelerometer_initial_bias: " << vec(n.accelerometer_initial_bias)
      << "\nrovo_imu_from_rig: " << YamlList(Row(imu_from_rig)) << "\n";
  return out.str();
}

std::string KalibrImuYaml(const ImuRecord& imu) {
  const ImuNoise& n = imu.noise;
  return "# rovo IMU (noise profile " + imu.noise_profile + "), Kalibr's imu.yaml keys.\n" +
         "accelerometer_noise_density: " + YamlNumber(n.accelerometer_noise_density) +
         "  # m/s^2/sqrt(Hz), continuous time\naccelerometer_random_walk: " + YamlNumber(n.accelerometer_random_walk) +
         "  # m/s^3/sqrt(Hz)\ngyroscope_noise_density: " + YamlNumber(n.gyroscope_noise_density) +
         "  # rad/s/sqrt(Hz), continuous time\ngyroscope_random_walk: " + YamlNumber(n.gyroscope_random_walk) +
         "  # rad/s^2/sqrt(Hz)\nrostopic: /imu0\nupdate_rate: " + YamlNumber(imu.rate_hz) + "  # Hz\n";
}

std::string WithKalibrTimeshift(const std::string& camchain, const DatasetInfo& info) {
  if (!info.imu) return camchain;
  // Every camera block has one `  cam_overlaps:` line (KalibrCamchainYaml); the shift follows it.
  std::istringstream in(camchain);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    out += line + "\n";
    if (line.rfind("  cam_overlaps:", 0) == 0)
      out += "  timeshift_cam_imu: " + YamlNumber(info.imu->time_offset_s) + "\n";
  }
  return out;
}

void SetBasaltImu(const ImuRecord& imu, nlohmann::json* calibration) {
  nlohmann::json& value = (*calibration)["value0"];
  const ImuNoise& n = imu.noise;
  auto triple = [](double v) { return std::vector<double>{v, v, v}; };
  value["imu_update_rate"] = imu.rate_hz;
  value["accel_noise_std"] = triple(n.accelerometer_noise_density);  // continuous time (Basalt's calibration.hpp)
  value["gyro_noise_std"] = triple(n.gyroscope_noise_density);
  value["accel_bias_std"] = triple(n.accelerometer_random_walk);
  value["gyro_bias_std"] = triple(n.gyroscope_random_walk);
  value["cam_time_offset_ns"] = SecondsToNs(imu.time_offset_s);  // t_imu = t_cam + offset
}

void WriteExchangeImu(const std::string& dataset_dir, const DatasetInfo& info, bool kalibr,
                      const std::string& out_dir) {
  if (!info.imu) return;
  if (!info.rig.imu_from_rig) throw std::runtime_error(DatasetJsonPath(dataset_dir) + ": /rig/imu_from_rig: missing");
  const ImuStreams streams = ReadImuStreams(dataset_dir);
  WriteFileAtomic(Imu0(out_dir, "data.csv"), ImuCsv(streams.measured));
  WriteFileAtomic(Imu0(out_dir, "rovo_exact.csv"), ImuCsv(streams.exact));
  WriteFileAtomic(Imu0(out_dir, "sensor.yaml"), EurocImuSensorYaml(*info.imu, *info.rig.imu_from_rig));
  if (info.has_ground_truth && fs::exists(GroundTruthPath(dataset_dir))) {
    WriteFileAtomic(GroundTruthCsv(out_dir), ImuGroundTruthCsv(ReadTum(GroundTruthPath(dataset_dir)), info, streams));
  }
  if (kalibr) WriteFileAtomic((fs::path(out_dir) / "imu.yaml").string(), KalibrImuYaml(*info.imu));
}

std::optional<ExchangeImu> ReadExchangeImu(const std::string& in_dir) {
  const std::string data = Imu0(in_dir, "data.csv"), exact = Imu0(in_dir, "rovo_exact.csv");
  const std::string sensor = Imu0(in_dir, "sensor.yaml"), gt = GroundTruthCsv(in_dir);
  if (!fs::exists(data) || !fs::exists(exact) || !fs::exists(gt) || !fs::exists(sensor)) return std::nullopt;
  ExchangeImu imu;
  imu.streams.measured = ReadEurocImuCsv(data);
  imu.streams.exact = ReadEurocImuCsv(exact);
  const auto gt_rows = ReadCsvRows(gt, 16);
  if (imu.streams.measured.empty()) throw std::runtime_error(data + ": no samples");
  if (imu.streams.exact.size() != imu.streams.measured.size() || gt_rows.size() != imu.streams.measured.size()) {
    throw std::runtime_error(data + ": " + std::to_string(imu.streams.measured.size()) + " samples, but " + exact +
                             " has " + std::to_string(imu.streams.exact.size()) + " and " + gt + " " +
                             std::to_string(gt_rows.size()));
  }
  for (size_t k = 0; k < gt_rows.size(); ++k) {
    const std::vector<double>& v = gt_rows[k].second;
    imu.streams.bias.push_back({imu.streams.measured[k].timestamp, Eigen::Vector3d(v[10], v[11], v[12]),
                                Eigen::Vector3d(v[13], v[14], v[15])});
  }
  ReadImuSensorYaml(sensor, &imu);
  imu.record.sample_count = static_cast<int>(imu.streams.measured.size());
  imu.record.first_timestamp = imu.streams.measured.front().timestamp;
  return imu;
}

bool ApplyExchangeImu(const std::string& in_dir, const std::string& out_dir, DatasetInfo* info, Trajectory* gt) {
  const std::optional<ExchangeImu> imu = ReadExchangeImu(in_dir);
  if (!imu) return false;
  for (RigCamera& c : info->rig.cameras) c.cam_from_rig = c.cam_from_rig * imu->imu_from_rig;
  for (PerturbedExtrinsics& set : info->perturbed) {
    for (Rigid3& c : set.cam_from_rig) c = c * imu->imu_from_rig;
  }
  for (StampedPose& pose : *gt) pose.world_from_rig = pose.world_from_rig * imu->imu_from_rig;
  info->imu = imu->record;
  info->rig.imu_from_rig = imu->imu_from_rig;
  WriteImuStreams(out_dir, imu->streams);
  return true;
}

}  // namespace rovo
