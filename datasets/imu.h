#pragma once
// The IMU of a dataset (datasets/FORMAT.md, section "IMU"): its dataset.json record and the three
// streams under imu/ (the measurements, the noise-free values, the true biases), with their readers
// and writers. The simulation that makes them is datasets/imu_model.h.
//
// Frames and units. The IMU frame is mounted on the rig at Rig::imu_from_rig (datasets/rig.h).
// Every sample is in the IMU frame: angular_velocity is the rate of the IMU frame relative to the
// world in rad/s, linear_acceleration the specific force in m/s^2 (the acceleration of the IMU's
// origin minus gravity; gravity is 9.81 m/s^2 along -z of the world, REP-103, so an IMU at rest with
// its z up reads +9.81 on z).
//
// Time. Every stamp is in seconds on the IMU's clock. The IMU clock runs ahead of the camera clock
// (the dataset's clock: image and groundtruth.tum times) by time_offset_s, as Kalibr's
// timeshift_cam_imu states it (t_imu = t_cam + shift) and Basalt's cam_time_offset_ns: a sample
// stamped s was measured at the dataset time s - time_offset_s.

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "datasets/dataset_validate.h"

namespace rovo {

class JsonChecker;

// Noise as Kalibr and EuRoC state it (continuous-time densities). A stream sampled every dt seconds
// gets white noise of standard deviation density / sqrt(dt) per sample and a bias that is a random
// walk with steps of standard deviation random_walk * sqrt(dt).
struct ImuNoise {
  double gyroscope_noise_density = 0.0;      // rad/s/sqrt(Hz)   (Kalibr gyroscope_noise_density)
  double gyroscope_random_walk = 0.0;        // rad/s^2/sqrt(Hz) (Kalibr gyroscope_random_walk)
  double accelerometer_noise_density = 0.0;  // m/s^2/sqrt(Hz)   (Kalibr accelerometer_noise_density)
  double accelerometer_random_walk = 0.0;    // m/s^3/sqrt(Hz)   (Kalibr accelerometer_random_walk)
  Eigen::Vector3d gyroscope_initial_bias = Eigen::Vector3d::Zero();      // rad/s, at the first sample
  Eigen::Vector3d accelerometer_initial_bias = Eigen::Vector3d::Zero();  // m/s^2, at the first sample
  bool operator==(const ImuNoise& other) const;
  bool operator!=(const ImuNoise& other) const { return !(*this == other); }
};

// dataset.json "imu": how the IMU streams were made. Absent when the dataset has no IMU.
struct ImuRecord {
  double rate_hz = 200.0;              // samples per second of the IMU clock
  std::string noise_profile = "none";  // "none" (exact), "adis16448", "custom"
  ImuNoise noise;                      // the values used (initial biases as drawn)
  uint64_t seed = 0;                   // seed of the noise and bias draws
  double time_offset_s = 0.0;          // t_imu = t_cam + time_offset_s (Kalibr timeshift_cam_imu)
  double gravity_m_s2 = 9.81;          // along -z of the world
  int sample_count = 0;                // lines of each stream
  double first_timestamp = 0.0;        // stamp of sample 0 on the IMU clock, s; sample k at first + k / rate
  bool operator==(const ImuRecord& other) const;
  bool operator!=(const ImuRecord& other) const { return !(*this == other); }
};

// One IMU sample in the IMU frame.
struct ImuSample {
  double timestamp = 0.0;                                         // seconds, IMU clock
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // rad/s
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // specific force, m/s^2
};

// The true biases at one sample: measured = exact + bias + white noise.
struct ImuBiasSample {
  double timestamp = 0.0;                                        // seconds, IMU clock
  Eigen::Vector3d gyroscope_bias = Eigen::Vector3d::Zero();      // rad/s
  Eigen::Vector3d accelerometer_bias = Eigen::Vector3d::Zero();  // m/s^2
};

// All IMU streams of a dataset, sample k of each at the same stamp.
struct ImuStreams {
  std::vector<ImuSample> measured;  // imu/data.csv
  std::vector<ImuSample> exact;     // imu/exact.csv (noise-free, bias-free)
  std::vector<ImuBiasSample> bias;  // imu/bias.csv
};

// Paths inside a dataset folder.
std::string ImuDataPath(const std::string& dataset_dir);   // imu/data.csv
std::string ImuExactPath(const std::string& dataset_dir);  // imu/exact.csv
std::string ImuBiasPath(const std::string& dataset_dir);   // imu/bias.csv

// Headers of the csv files (units in datasets/FORMAT.md).
inline constexpr const char* kImuCsvHeader = "timestamp,w_x,w_y,w_z,a_x,a_y,a_z";
inline constexpr const char* kImuBiasCsvHeader = "timestamp,bw_x,bw_y,bw_z,ba_x,ba_y,ba_z";

// Parsers that record every problem as (path, "line N", message naming the column): the header,
// 7 finite numbers per line, strictly increasing stamps.
std::vector<ImuSample> ParseImuCsv(const std::string& text, const std::string& path,
                                   std::vector<ValidationIssue>* issues);
std::vector<ImuBiasSample> ParseImuBiasCsv(const std::string& text, const std::string& path,
                                           std::vector<ValidationIssue>* issues);
// Readers: throw std::runtime_error naming the file, line and column.
std::vector<ImuSample> ReadImuCsv(const std::string& path);
std::vector<ImuBiasSample> ReadImuBiasCsv(const std::string& path);
// The three streams of a dataset; throws naming the file when one is missing, malformed, or when
// their lengths or stamps differ.
ImuStreams ReadImuStreams(const std::string& dataset_dir);

// Atomic writes, full double precision.
void WriteImuCsv(const std::string& path, const std::vector<ImuSample>& samples);
void WriteImuBiasCsv(const std::string& path, const std::vector<ImuBiasSample>& samples);
void WriteImuStreams(const std::string& dataset_dir, const ImuStreams& streams);

// dataset.json's "imu" object.
nlohmann::json ImuRecordToJson(const ImuRecord& record);
// Parses /imu, recording every problem in `check`.
ImuRecord ParseImuRecord(JsonChecker& check, const nlohmann::json& j, const std::string& pointer);

}  // namespace rovo
