#include "datasets/trajectory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "datasets/io.h"

namespace rovo {
namespace {

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

}  // namespace

std::vector<TumLine> ParseTumText(const std::string& text, const std::string& path, std::vector<std::string>* errors) {
  std::vector<TumLine> lines;
  std::istringstream in(text);
  std::string raw;
  int line_number = 0;
  auto fail = [&](const std::string& message) {
    const std::string error = path + ": line " + std::to_string(line_number) + ": " + message;
    if (!errors) throw std::runtime_error(error);
    errors->push_back(error);
  };
  while (std::getline(in, raw)) {
    ++line_number;
    const std::string line = Trim(raw);
    if (line.empty() || line[0] == '#') continue;
    TumLine parsed;
    parsed.line_number = line_number;
    const char* p = line.c_str();
    int count = 0;
    bool bad_token = false;
    while (*p) {
      while (*p == ' ' || *p == '\t') ++p;
      if (!*p) break;
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      if (end == p || (*end && *end != ' ' && *end != '\t')) {
        bad_token = true;
        break;
      }
      if (count < 8) parsed.values[count] = v;
      ++count;
      p = end;
    }
    if (bad_token) {
      fail("not a number in `" + line + "` (expected `timestamp tx ty tz qx qy qz qw`)");
      continue;
    }
    if (count != 8) {
      fail("expected 8 numbers `timestamp tx ty tz qx qy qz qw`, found " + std::to_string(count));
      continue;
    }
    bool finite = true;
    for (double v : parsed.values) finite = finite && std::isfinite(v);
    if (!finite) {
      fail("NaN or Inf value");
      continue;
    }
    lines.push_back(parsed);
  }
  return lines;
}

Trajectory ReadTum(const std::string& path) {
  const std::vector<TumLine> lines = ParseTumText(ReadFile(path), path, nullptr);
  Trajectory trajectory;
  trajectory.reserve(lines.size());
  for (const TumLine& line : lines) {
    const std::string where = path + ": line " + std::to_string(line.line_number) + ": ";
    const Eigen::Quaterniond q(line.values[7], line.values[4], line.values[5], line.values[6]);
    const double norm = q.norm();
    // Text files carry a few digits only; a norm this far from 1 is not rounding but a wrong column.
    if (!(std::abs(norm - 1.0) < 1e-3)) {
      throw std::runtime_error(where + "quaternion (qx qy qz qw) has norm " + std::to_string(norm) + ", expected 1");
    }
    if (!trajectory.empty() && !(line.values[0] > trajectory.back().timestamp)) {
      throw std::runtime_error(where + "timestamp " + std::to_string(line.values[0]) +
                               " is not after the previous one");
    }
    StampedPose pose;
    pose.timestamp = line.values[0];
    pose.world_from_rig = Rigid3(q, Eigen::Vector3d(line.values[1], line.values[2], line.values[3]));
    // Keep a quaternion that is already unit to rounding as written, so that read -> write -> read
    // is exact (normalising again would change the last bits).
    if (std::abs(norm - 1.0) <= 1e-15) pose.world_from_rig.rotation = q;
    trajectory.push_back(pose);
  }
  return trajectory;
}

std::string FormatTum(const Trajectory& trajectory) {
  std::string out;
  out.reserve(trajectory.size() * 200);
  out += "# timestamp tx ty tz qx qy qz qw (world_from_rig)\n";
  char buf[512];
  for (const StampedPose& pose : trajectory) {
    const Eigen::Vector3d& t = pose.world_from_rig.translation;
    const Eigen::Quaterniond& q = pose.world_from_rig.rotation;
    std::snprintf(buf, sizeof(buf), "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", pose.timestamp, t.x(), t.y(),
                  t.z(), q.x(), q.y(), q.z(), q.w());
    out += buf;
  }
  return out;
}

void WriteTum(const std::string& path, const Trajectory& trajectory) { WriteFileAtomic(path, FormatTum(trajectory)); }

void WriteKitti(const std::string& path, const Trajectory& trajectory) {
  std::string out;
  char buf[64];
  for (const StampedPose& pose : trajectory) {
    const Eigen::Matrix<double, 3, 4> m = pose.world_from_rig.Matrix3x4();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        std::snprintf(buf, sizeof(buf), "%.17g", m(r, c));
        if (r || c) out += ' ';
        out += buf;
      }
    }
    out += '\n';
  }
  WriteFileAtomic(path, out);
}

Rigid3 InterpolatePose(const Trajectory& trajectory, double t) {
  if (trajectory.empty()) throw std::invalid_argument("InterpolatePose: empty trajectory");
  if (t <= trajectory.front().timestamp) return trajectory.front().world_from_rig;
  if (t >= trajectory.back().timestamp) return trajectory.back().world_from_rig;
  // First pose with timestamp > t; its predecessor has timestamp <= t.
  const auto upper = std::upper_bound(trajectory.begin(), trajectory.end(), t,
                                      [](double value, const StampedPose& p) { return value < p.timestamp; });
  const StampedPose& b = *upper;
  const StampedPose& a = *(upper - 1);
  const double span = b.timestamp - a.timestamp;
  const double alpha = span > 0.0 ? (t - a.timestamp) / span : 0.0;
  return Interpolate(a.world_from_rig, b.world_from_rig, alpha);
}

double PathLength(const Trajectory& trajectory) {
  double length = 0.0;
  for (size_t i = 1; i < trajectory.size(); ++i) {
    length += (trajectory[i].world_from_rig.translation - trajectory[i - 1].world_from_rig.translation).norm();
  }
  return length;
}

Trajectory ReadTumAnyUnit(const std::string& path, bool* nanoseconds) {
  Trajectory trajectory = ReadTum(path);
  std::vector<double> dt;
  bool huge = false;
  for (size_t i = 0; i < trajectory.size(); ++i) {
    if (i > 0) dt.push_back(trajectory[i].timestamp - trajectory[i - 1].timestamp);
    huge = huge || trajectory[i].timestamp > 1e12;
  }
  double median = 0.0;
  if (!dt.empty()) {
    std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
    median = dt[dt.size() / 2];
  }
  const bool ns = huge || median > 1000.0;
  if (ns) {
    for (StampedPose& pose : trajectory) pose.timestamp *= 1e-9;
  }
  if (nanoseconds) *nanoseconds = ns;
  return trajectory;
}

namespace {

// Numbers of a data line split at commas or white space; false on a non-number.
bool SplitNumbers(const std::string& line, std::vector<double>* values) {
  values->clear();
  const char* p = line.c_str();
  while (*p) {
    while (*p == ' ' || *p == '\t' || *p == ',') ++p;
    if (!*p) break;
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || !std::isfinite(v)) return false;
    values->push_back(v);
    p = end;
  }
  return true;
}

template <typename F>
void ForEachDataLine(const std::string& path, F&& f) {
  std::istringstream in(ReadFile(path));
  std::string raw;
  int line_number = 0;
  std::vector<double> values;
  while (std::getline(in, raw)) {
    ++line_number;
    const std::string line = Trim(raw);
    if (line.empty() || line[0] == '#') continue;
    if (!SplitNumbers(line, &values)) {
      throw std::runtime_error(path + ": line " + std::to_string(line_number) + ": not a number in `" + line + "`");
    }
    f(line_number, values);
  }
}

}  // namespace

Trajectory ReadEurocCsv(const std::string& path) {
  Trajectory trajectory;
  ForEachDataLine(path, [&](int line_number, const std::vector<double>& v) {
    const std::string where = path + ": line " + std::to_string(line_number) + ": ";
    if (v.size() < 8) throw std::runtime_error(where + "expected timestamp [ns], p x y z, q w x y z");
    const Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    if (std::abs(q.norm() - 1.0) > 1e-3) throw std::runtime_error(where + "quaternion norm is not 1");
    const double t = v[0] * 1e-9;
    if (!trajectory.empty() && !(t > trajectory.back().timestamp)) {
      throw std::runtime_error(where + "timestamps not increasing");
    }
    trajectory.push_back({t, Rigid3(q, Eigen::Vector3d(v[1], v[2], v[3]))});
  });
  return trajectory;
}

Trajectory ReadKittiPoses(const std::string& path, const std::vector<double>& timestamps) {
  Trajectory trajectory;
  ForEachDataLine(path, [&](int line_number, const std::vector<double>& v) {
    const std::string where = path + ": line " + std::to_string(line_number) + ": ";
    if (v.size() != 12) throw std::runtime_error(where + "expected 12 numbers (row-major 3x4 pose)");
    if (trajectory.size() >= timestamps.size()) {
      throw std::runtime_error(where + "more poses than ground-truth frames (KITTI poses are matched by line)");
    }
    Eigen::Matrix3d rotation;
    rotation << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    if ((rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-3) {
      throw std::runtime_error(where + "the 3x3 block is not a rotation");
    }
    trajectory.push_back({timestamps[trajectory.size()], Rigid3(rotation, Eigen::Vector3d(v[3], v[7], v[11]))});
  });
  return trajectory;
}

}  // namespace rovo
