// The IMU part of `rovo dataset validate` (datasets/FORMAT.md, section "IMU"): the three streams
// present and well-formed, as many samples as dataset.json says, stamps on the stated rate, the
// noise-free stream equal to the ground truth's motion at spot checks, and the measurements equal
// to exact + bias when the record has no white noise.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "datasets/continuous_trajectory.h"
#include "datasets/dataset.h"
#include "datasets/dataset_internal.h"
#include "datasets/imu_model.h"
#include "datasets/io.h"
#include "datasets/json_check.h"

namespace rovo {
namespace fs = std::filesystem;

namespace {

constexpr int kSpotChecks = 64;

template <typename Sample>
void CheckStamps(const std::vector<Sample>& samples, const std::string& path, const ImuRecord& record,
                 std::vector<ValidationIssue>* issues) {
  if (static_cast<int>(samples.size()) != record.sample_count) {
    issues->push_back({path, "lines",
                       std::to_string(samples.size()) + " samples but dataset.json /imu/sample_count is " +
                           std::to_string(record.sample_count)});
  }
  int reported = 0;
  for (size_t k = 0; k < samples.size() && reported < 5; ++k) {
    const double expected = record.first_timestamp + static_cast<double>(k) / record.rate_hz;
    if (!(std::abs(samples[k].timestamp - expected) <= 1e-9 * (1.0 + std::abs(expected)))) {
      issues->push_back({path, "line " + std::to_string(k + 2),
                         "column timestamp: " + JsonChecker::Format(samples[k].timestamp) + ", expected " +
                             JsonChecker::Format(expected) + " (first_timestamp + k / rate_hz of dataset.json /imu)"});
      ++reported;
    }
  }
}

bool Near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance) {
  return (a - b).norm() <= tolerance * (1.0 + b.norm());
}

// exact.csv against the ground truth's continuous-time motion at evenly spread samples.
void SpotCheckExact(const std::string& dir, const DatasetInfo& info, const std::vector<ImuSample>& exact,
                    std::vector<ValidationIssue>* issues) {
  const std::string path = ImuExactPath(dir);
  if (!info.has_ground_truth || !info.rig.imu_from_rig || exact.empty()) return;
  std::optional<ContinuousTrajectory> motion;
  try {
    motion.emplace(ReadTum(GroundTruthPath(dir)));
  } catch (const std::exception& e) {
    issues->push_back({path, "file", std::string("no continuous-time ground truth to check against: ") + e.what()});
    return;
  }
  const ImuRecord& r = *info.imu;
  const size_t step = std::max<size_t>(1, exact.size() / kSpotChecks);
  for (size_t k = 0; k < exact.size(); k += step) {
    const double stamp = r.first_timestamp + static_cast<double>(k) / r.rate_hz;
    const ImuSample truth =
        ExactImuSample(motion->State(stamp - r.time_offset_s), *info.rig.imu_from_rig, r.gravity_m_s2);
    if (!Near(exact[k].angular_velocity, truth.angular_velocity, 1e-9) ||
        !Near(exact[k].linear_acceleration, truth.linear_acceleration, 1e-9)) {
      issues->push_back(
          {path, "line " + std::to_string(k + 2),
           "differs from the ground truth's motion (groundtruth.tum, rig imu_from_rig) by " +
               JsonChecker::Format((exact[k].angular_velocity - truth.angular_velocity).norm()) + " rad/s, " +
               JsonChecker::Format((exact[k].linear_acceleration - truth.linear_acceleration).norm()) + " m/s^2"});
      return;
    }
  }
}

// measured = exact + bias + white noise; without white noise the sum holds exactly.
void CheckComposition(const std::string& dir, const ImuRecord& r, const ImuStreams& s,
                      std::vector<ValidationIssue>* issues) {
  const size_t n = std::min({s.measured.size(), s.exact.size(), s.bias.size()});
  if (n == 0) return;
  if (!Near(s.bias[0].gyroscope_bias, r.noise.gyroscope_initial_bias, 1e-12) ||
      !Near(s.bias[0].accelerometer_bias, r.noise.accelerometer_initial_bias, 1e-12))
    issues->push_back(
        {ImuBiasPath(dir), "line 2", "the first biases are not dataset.json's /imu/noise initial biases"});
  if (r.noise.gyroscope_noise_density != 0.0 || r.noise.accelerometer_noise_density != 0.0) return;
  for (size_t k = 0; k < n; ++k) {
    if (!Near(s.measured[k].angular_velocity, s.exact[k].angular_velocity + s.bias[k].gyroscope_bias, 1e-12) ||
        !Near(s.measured[k].linear_acceleration, s.exact[k].linear_acceleration + s.bias[k].accelerometer_bias,
              1e-12)) {
      issues->push_back({ImuDataPath(dir), "line " + std::to_string(k + 2),
                         "not exact + bias although dataset.json's /imu/noise has no white noise"});
      return;
    }
  }
}

}  // namespace

void CheckImuStreams(const std::string& dir, const DatasetInfo& info, std::vector<ValidationIssue>* issues) {
  if (!info.imu) {
    if (fs::exists(fs::path(dir) / "imu"))
      issues->push_back({(fs::path(dir) / "imu").string(), "folder", "IMU files but no /imu record in dataset.json"});
    return;
  }
  ImuStreams streams;
  bool complete = true;
  auto read = [&](const std::string& path, auto parse, auto* out) {
    if (!fs::exists(path)) {
      issues->push_back({path, "file", "missing IMU stream (dataset.json has /imu)"});
      complete = false;
      return;
    }
    try {
      *out = parse(ReadFile(path), path, issues);
      CheckStamps(*out, path, *info.imu, issues);
    } catch (const std::exception& e) {
      issues->push_back({path, "file", e.what()});
      complete = false;
    }
  };
  read(ImuDataPath(dir), &ParseImuCsv, &streams.measured);
  read(ImuExactPath(dir), &ParseImuCsv, &streams.exact);
  read(ImuBiasPath(dir), &ParseImuBiasCsv, &streams.bias);
  if (!complete) return;
  SpotCheckExact(dir, info, streams.exact, issues);
  CheckComposition(dir, *info.imu, streams, issues);
}

}  // namespace rovo
