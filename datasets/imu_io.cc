#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "datasets/imu.h"
#include "datasets/io.h"
#include "datasets/json_check.h"

namespace rovo {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// One csv line of the IMU files: a stamp and six numbers. Returns false (and records the problem)
// when the line is malformed.
bool ParseSevenNumbers(const std::string& line, const char* const names[7], double values[7],
                       const std::function<void(const std::string&)>& issue) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) fields.push_back(f);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  if (fields.size() != 7) {
    issue("expected 7 comma-separated fields, found " + std::to_string(fields.size()));
    return false;
  }
  bool ok = true;
  for (int k = 0; k < 7; ++k) {
    char* end = nullptr;
    values[k] = std::strtod(fields[k].c_str(), &end);
    if (fields[k].empty() || *end != '\0' || !std::isfinite(values[k])) {
      issue(std::string("column ") + names[k] + ": `" + fields[k] + "` is not a finite number");
      ok = false;
    }
  }
  return ok;
}

// The lines of an IMU csv with the header checked and stamps strictly increasing; `emit` gets the
// seven numbers of every good line.
void ParseImuText(const std::string& text, const std::string& path, const char* header,
                  std::vector<ValidationIssue>* issues, const std::function<void(const double*)>& emit) {
  const std::string header_text = header;
  const char* names[7];
  std::vector<std::string> name_storage;
  {
    std::stringstream hs(header_text);
    for (std::string f; std::getline(hs, f, ',');) name_storage.push_back(f);
    for (int k = 0; k < 7; ++k) names[k] = name_storage[k].c_str();
  }
  std::stringstream in(text);
  std::string line;
  int line_number = 0;
  double previous = -std::numeric_limits<double>::infinity();
  auto issue = [&](const std::string& message) {
    issues->push_back({path, "line " + std::to_string(line_number), message});
  };
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1) {
      if (line != header_text) issue("expected the header `" + header_text + "`");
      continue;
    }
    if (line.empty()) continue;
    double v[7];
    if (!ParseSevenNumbers(line, names, v, issue)) continue;
    if (!(v[0] > previous))
      issue("column timestamp: " + JsonChecker::Format(v[0]) + " is not after the previous stamp " +
            JsonChecker::Format(previous));
    previous = v[0];
    emit(v);
  }
  if (line_number == 0) issues->push_back({path, "file", "empty file (expected the header `" + header_text + "`)"});
}

std::string FormatSevenNumbers(double t, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", t, a.x(), a.y(), a.z(), b.x(), b.y(),
                b.z());
  return buf;
}

json Vector3Json(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

Eigen::Vector3d ParseVector3(JsonChecker& check, const json& j, const std::string& p, const std::string& key) {
  const std::vector<double> v = check.Numbers(j, p, key, 3);
  return v.size() == 3 ? Eigen::Vector3d(v[0], v[1], v[2]) : Eigen::Vector3d::Zero();
}

json NoiseJson(const ImuNoise& n) {
  return json{{"gyroscope_noise_density", n.gyroscope_noise_density},
              {"gyroscope_random_walk", n.gyroscope_random_walk},
              {"accelerometer_noise_density", n.accelerometer_noise_density},
              {"accelerometer_random_walk", n.accelerometer_random_walk},
              {"gyroscope_initial_bias", Vector3Json(n.gyroscope_initial_bias)},
              {"accelerometer_initial_bias", Vector3Json(n.accelerometer_initial_bias)}};
}

}  // namespace

bool ImuNoise::operator==(const ImuNoise& o) const { return NoiseJson(*this) == NoiseJson(o); }
bool ImuRecord::operator==(const ImuRecord& o) const { return ImuRecordToJson(*this) == ImuRecordToJson(o); }

std::string ImuDataPath(const std::string& dataset_dir) {
  return (fs::path(dataset_dir) / "imu" / "data.csv").string();
}
std::string ImuExactPath(const std::string& dataset_dir) {
  return (fs::path(dataset_dir) / "imu" / "exact.csv").string();
}
std::string ImuBiasPath(const std::string& dataset_dir) {
  return (fs::path(dataset_dir) / "imu" / "bias.csv").string();
}

std::vector<ImuSample> ParseImuCsv(const std::string& text, const std::string& path,
                                   std::vector<ValidationIssue>* issues) {
  std::vector<ImuSample> out;
  ParseImuText(text, path, kImuCsvHeader, issues, [&](const double* v) {
    ImuSample s;
    s.timestamp = v[0];
    s.angular_velocity = Eigen::Vector3d(v[1], v[2], v[3]);
    s.linear_acceleration = Eigen::Vector3d(v[4], v[5], v[6]);
    out.push_back(s);
  });
  return out;
}

std::vector<ImuBiasSample> ParseImuBiasCsv(const std::string& text, const std::string& path,
                                           std::vector<ValidationIssue>* issues) {
  std::vector<ImuBiasSample> out;
  ParseImuText(text, path, kImuBiasCsvHeader, issues, [&](const double* v) {
    ImuBiasSample s;
    s.timestamp = v[0];
    s.gyroscope_bias = Eigen::Vector3d(v[1], v[2], v[3]);
    s.accelerometer_bias = Eigen::Vector3d(v[4], v[5], v[6]);
    out.push_back(s);
  });
  return out;
}

std::vector<ImuSample> ReadImuCsv(const std::string& path) {
  std::vector<ValidationIssue> issues;
  std::vector<ImuSample> out = ParseImuCsv(ReadFile(path), path, &issues);
  if (!issues.empty()) throw std::runtime_error(JoinIssues(issues));
  return out;
}

std::vector<ImuBiasSample> ReadImuBiasCsv(const std::string& path) {
  std::vector<ValidationIssue> issues;
  std::vector<ImuBiasSample> out = ParseImuBiasCsv(ReadFile(path), path, &issues);
  if (!issues.empty()) throw std::runtime_error(JoinIssues(issues));
  return out;
}

ImuStreams ReadImuStreams(const std::string& dataset_dir) {
  ImuStreams s;
  s.measured = ReadImuCsv(ImuDataPath(dataset_dir));
  s.exact = ReadImuCsv(ImuExactPath(dataset_dir));
  s.bias = ReadImuBiasCsv(ImuBiasPath(dataset_dir));
  auto check_same = [&](const std::string& path, size_t size, const std::function<double(size_t)>& stamp) {
    if (size != s.measured.size())
      throw std::runtime_error(path + ": lines: " + std::to_string(size) + " samples but " + ImuDataPath(dataset_dir) +
                               " has " + std::to_string(s.measured.size()));
    for (size_t k = 0; k < size; ++k) {
      if (stamp(k) != s.measured[k].timestamp)
        throw std::runtime_error(path + ": sample " + std::to_string(k) + ": stamp " + JsonChecker::Format(stamp(k)) +
                                 " differs from " + ImuDataPath(dataset_dir) + " (" +
                                 JsonChecker::Format(s.measured[k].timestamp) + ")");
    }
  };
  check_same(ImuExactPath(dataset_dir), s.exact.size(), [&](size_t k) { return s.exact[k].timestamp; });
  check_same(ImuBiasPath(dataset_dir), s.bias.size(), [&](size_t k) { return s.bias[k].timestamp; });
  return s;
}

void WriteImuCsv(const std::string& path, const std::vector<ImuSample>& samples) {
  std::string text = std::string(kImuCsvHeader) + "\n";
  text.reserve(samples.size() * 180);
  for (const ImuSample& s : samples) text += FormatSevenNumbers(s.timestamp, s.angular_velocity, s.linear_acceleration);
  WriteFileAtomic(path, text);
}

void WriteImuBiasCsv(const std::string& path, const std::vector<ImuBiasSample>& samples) {
  std::string text = std::string(kImuBiasCsvHeader) + "\n";
  text.reserve(samples.size() * 180);
  for (const ImuBiasSample& s : samples)
    text += FormatSevenNumbers(s.timestamp, s.gyroscope_bias, s.accelerometer_bias);
  WriteFileAtomic(path, text);
}

void WriteImuStreams(const std::string& dataset_dir, const ImuStreams& streams) {
  WriteImuCsv(ImuDataPath(dataset_dir), streams.measured);
  WriteImuCsv(ImuExactPath(dataset_dir), streams.exact);
  WriteImuBiasCsv(ImuBiasPath(dataset_dir), streams.bias);
}

json ImuRecordToJson(const ImuRecord& r) {
  return json{{"rate_hz", r.rate_hz},
              {"noise_profile", r.noise_profile},
              {"noise", NoiseJson(r.noise)},
              {"seed", r.seed},
              {"time_offset_s", r.time_offset_s},
              {"gravity_m_s2", r.gravity_m_s2},
              {"sample_count", r.sample_count},
              {"first_timestamp", r.first_timestamp}};
}

ImuRecord ParseImuRecord(JsonChecker& check, const json& j, const std::string& p) {
  ImuRecord r;
  if (!check.Object(j, p)) return r;
  r.rate_hz = check.Number(j, p, "rate_hz", 200.0, 0.0, 1e6, /*lo_open=*/true);
  r.noise_profile = check.String(j, p, "noise_profile", true);
  if (!r.noise_profile.empty() && r.noise_profile != "none" && r.noise_profile != "adis16448" &&
      r.noise_profile != "custom")
    check.Issue(p + "/noise_profile", "unknown profile `" + r.noise_profile + "` (known: none, adis16448, custom)");
  if (const json* n = check.Member(j, p, "noise"); n && check.Object(*n, p + "/noise")) {
    const std::string np = p + "/noise";
    r.noise.gyroscope_noise_density = check.Number(*n, np, "gyroscope_noise_density", 0.0, 0.0, 1e3);
    r.noise.gyroscope_random_walk = check.Number(*n, np, "gyroscope_random_walk", 0.0, 0.0, 1e3);
    r.noise.accelerometer_noise_density = check.Number(*n, np, "accelerometer_noise_density", 0.0, 0.0, 1e3);
    r.noise.accelerometer_random_walk = check.Number(*n, np, "accelerometer_random_walk", 0.0, 0.0, 1e3);
    r.noise.gyroscope_initial_bias = ParseVector3(check, *n, np, "gyroscope_initial_bias");
    r.noise.accelerometer_initial_bias = ParseVector3(check, *n, np, "accelerometer_initial_bias");
  }
  r.seed = check.Unsigned(j, p, "seed");
  r.time_offset_s = check.Number(j, p, "time_offset_s", 0.0, -1.0, 1.0);
  r.gravity_m_s2 = check.Number(j, p, "gravity_m_s2", 9.81, 0.0, 100.0);
  r.sample_count = static_cast<int>(check.Integer(j, p, "sample_count", 0, 1, 2000000000));
  r.first_timestamp = check.Number(j, p, "first_timestamp", 0.0, -1e12, 1e12);
  return r;
}

}  // namespace rovo
