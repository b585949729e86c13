// The IMU in ROS 2 bags (ros2_bag_internal.h): /imu0 with the measurements, and the dataset's IMU
// ground truth on /ground_truth/imu0/exact and /ground_truth/imu0/bias, so an import gets all three
// streams back.
#include <cmath>
#include <stdexcept>

#include "datasets/exchange/exchange.h"
#include "datasets/exchange/ros2_bag.h"
#include "datasets/exchange/ros2_bag_internal.h"
#include "datasets/imu.h"

namespace rovo {
namespace {

RosImu ImuMessage(double timestamp, const Eigen::Vector3d& angular_velocity, const Eigen::Vector3d& acceleration,
                  double gyro_variance, double accel_variance) {
  RosImu m;
  m.header.stamp = RosTimeFromNs(SecondsToNs(timestamp));
  m.header.frame_id = "imu";
  m.orientation_covariance[0] = -1;  // no orientation estimate
  m.angular_velocity = angular_velocity;
  m.linear_acceleration = acceleration;
  for (size_t i = 0; i < 3; ++i) {  // the diagonal of the row-major 3x3
    m.angular_velocity_covariance[4 * i] = gyro_variance;
    m.linear_acceleration_covariance[4 * i] = accel_variance;
  }
  return m;
}

// The IMU record as MCAP metadata, every number at full precision.
McapStringMap RecordMetadata(const ImuRecord& r) {
  const ImuNoise& n = r.noise;
  auto vec = [](const Eigen::Vector3d& v) { return YamlList({v.x(), v.y(), v.z()}); };
  return {{"rovo_imu_rate_hz", YamlNumber(r.rate_hz)},
          {"rovo_imu_noise_profile", r.noise_profile},
          {"rovo_imu_gyroscope_noise_density", YamlNumber(n.gyroscope_noise_density)},
          {"rovo_imu_gyroscope_random_walk", YamlNumber(n.gyroscope_random_walk)},
          {"rovo_imu_accelerometer_noise_density", YamlNumber(n.accelerometer_noise_density)},
          {"rovo_imu_accelerometer_random_walk", YamlNumber(n.accelerometer_random_walk)},
          {"rovo_imu_gyroscope_initial_bias", vec(n.gyroscope_initial_bias)},
          {"rovo_imu_accelerometer_initial_bias", vec(n.accelerometer_initial_bias)},
          {"rovo_imu_seed", std::to_string(r.seed)},
          {"rovo_imu_time_offset_s", YamlNumber(r.time_offset_s)},
          {"rovo_imu_gravity_m_s2", YamlNumber(r.gravity_m_s2)}};
}

std::string Lookup(const McapStringMap& map, const std::string& key, const std::string& what) {
  for (const auto& [k, v] : map) {
    if (k == key) return v;
  }
  throw std::runtime_error(what + ": Metadata rovo: " + key + ": missing (the bag has IMU ground truth)");
}

double Number(const McapStringMap& map, const std::string& key, const std::string& what) {
  const std::string text = Lookup(map, key, what);
  try {
    size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw std::runtime_error(what + ": Metadata rovo: " + key + ": '" + text + "' is not a finite number");
}

Eigen::Vector3d Vector(const McapStringMap& map, const std::string& key, const std::string& what) {
  const std::string text = Lookup(map, key, what);
  Eigen::Vector3d v;
  if (std::sscanf(text.c_str(), "[%lf, %lf, %lf]", &v.x(), &v.y(), &v.z()) != 3 || !v.allFinite()) {
    throw std::runtime_error(what + ": Metadata rovo: " + key + ": '" + text + "' is not [x, y, z]");
  }
  return v;
}

ImuRecord RecordFromMetadata(const McapStringMap& m, const std::string& what) {
  ImuRecord r;
  r.rate_hz = Number(m, "rovo_imu_rate_hz", what);
  r.noise_profile = Lookup(m, "rovo_imu_noise_profile", what);
  r.noise.gyroscope_noise_density = Number(m, "rovo_imu_gyroscope_noise_density", what);
  r.noise.gyroscope_random_walk = Number(m, "rovo_imu_gyroscope_random_walk", what);
  r.noise.accelerometer_noise_density = Number(m, "rovo_imu_accelerometer_noise_density", what);
  r.noise.accelerometer_random_walk = Number(m, "rovo_imu_accelerometer_random_walk", what);
  r.noise.gyroscope_initial_bias = Vector(m, "rovo_imu_gyroscope_initial_bias", what);
  r.noise.accelerometer_initial_bias = Vector(m, "rovo_imu_accelerometer_initial_bias", what);
  try {
    r.seed = std::stoull(Lookup(m, "rovo_imu_seed", what));
  } catch (const std::logic_error&) {
    throw std::runtime_error(what + ": Metadata rovo: rovo_imu_seed: not an unsigned integer");
  }
  r.time_offset_s = Number(m, "rovo_imu_time_offset_s", what);
  r.gravity_m_s2 = Number(m, "rovo_imu_gravity_m_s2", what);
  return r;
}

std::vector<ImuSample> Samples(const std::vector<RosImu>& messages) {
  std::vector<ImuSample> out;
  out.reserve(messages.size());
  for (const RosImu& m : messages) {
    out.push_back({static_cast<double>(RosTimeToNs(m.header.stamp)) * 1e-9, m.angular_velocity, m.linear_acceleration});
  }
  return out;
}

}  // namespace

Ros2ImuExport ReadRos2ImuExport(const std::string& dataset_dir, const DatasetInfo& info) {
  Ros2ImuExport out;
  if (!info.imu) return out;
  if (!info.rig.imu_from_rig) throw std::runtime_error(DatasetJsonPath(dataset_dir) + ": /rig/imu_from_rig: missing");
  out.imu_from_rig = *info.rig.imu_from_rig;
  const ImuStreams streams = ReadImuStreams(dataset_dir);
  const ImuRecord& r = *info.imu;
  // Per-sample variance of the white noise: density^2 x rate (Kalibr's discrete-time sigma^2).
  const double gyro_var = r.noise.gyroscope_noise_density * r.noise.gyroscope_noise_density * r.rate_hz;
  const double accel_var = r.noise.accelerometer_noise_density * r.noise.accelerometer_noise_density * r.rate_hz;
  for (const ImuSample& s : streams.measured) {
    out.samples.push_back(ImuMessage(s.timestamp, s.angular_velocity, s.linear_acceleration, gyro_var, accel_var));
  }
  for (const ImuSample& s : streams.exact) {
    out.exact.push_back(ImuMessage(s.timestamp, s.angular_velocity, s.linear_acceleration, 0, 0));
  }
  for (const ImuBiasSample& s : streams.bias) {
    out.bias.push_back(ImuMessage(s.timestamp, s.gyroscope_bias, s.accelerometer_bias, 0, 0));
  }
  out.metadata = RecordMetadata(r);
  return out;
}

bool ImportRos2Imu(const Ros2ImuImport& in, const std::string& what, const std::string& out_dir, DatasetInfo* info) {
  if (in.samples.empty()) return false;
  if (in.exact.size() != in.samples.size() || in.bias.size() != in.samples.size()) return false;  // no IMU ground truth
  ImuStreams streams;
  streams.measured = Samples(in.samples);
  streams.exact = Samples(in.exact);
  for (const ImuSample& s : Samples(in.bias)) {
    streams.bias.push_back({s.timestamp, s.angular_velocity, s.linear_acceleration});
  }
  for (size_t k = 0; k < streams.measured.size(); ++k) {
    if (streams.exact[k].timestamp != streams.measured[k].timestamp ||
        streams.bias[k].timestamp != streams.measured[k].timestamp) {
      throw std::runtime_error(what + ": " + kRos2ImuTopic + " sample " + std::to_string(k) +
                               ": header.stamp: differs from the IMU ground truth's stamp");
    }
  }
  ImuRecord record = RecordFromMetadata(in.metadata, what);
  record.sample_count = static_cast<int>(streams.measured.size());
  record.first_timestamp = streams.measured.front().timestamp;
  info->imu = record;
  info->rig.imu_from_rig = in.imu_from_rig;
  WriteImuStreams(out_dir, streams);
  return true;
}

}  // namespace rovo
