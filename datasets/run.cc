// Run folders (datasets/run.h): CSV writers and strict readers.
//
// CSV dialect: comma separated, one header line naming the columns (checked on read), no quoting
// (no field contains a comma), '\n' line ends ('\r\n' accepted on read). Doubles are written in the
// shortest form that reads back to the same value (std::to_chars), so a write/read round trip is
// exact. Booleans are 0/1.

#include "datasets/run.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "datasets/io.h"

namespace rovo {
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kFramesColumns = {
    "frame",  "timestamp", "num_correspondences", "num_inliers", "inlier_ratio", "mean_reproj_error_deg", "keyframe",
    "status", "time_ms",   "missing_cameras"};
// frames.csv as written before missing_cameras existed: still read (no camera missing).
const std::vector<std::string> kFramesColumnsWithoutMissing(kFramesColumns.begin(), kFramesColumns.end() - 1);
const std::vector<std::string> kExtrinsicsColumns = {"frame", "timestamp", "camera", "qx", "qy",
                                                     "qz",    "qw",        "tx",     "ty", "tz"};

std::string FormatDouble(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string Join(const std::vector<std::string>& fields) {
  std::string line;
  for (size_t i = 0; i < fields.size(); ++i) {
    if (i) line += ',';
    line += fields[i];
  }
  return line;
}

// One parsed CSV file: rows of fields with the line number of each row, header checked.
class CsvReader {
 public:
  CsvReader(std::string path, const std::vector<std::string>& columns) : path_(std::move(path)), columns_(columns) {
    const std::string text = ReadFile(path_);
    std::istringstream in(text);
    std::string line;
    int line_number = 0;
    bool have_header = false;
    while (std::getline(in, line)) {
      ++line_number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.empty()) continue;
      std::vector<std::string> fields = Split(line);
      if (!have_header) {
        if (fields != columns_) {
          throw std::runtime_error(path_ + ":" + std::to_string(line_number) + ": bad header line, expected \"" +
                                   Join(columns_) + "\", got \"" + line + "\"");
        }
        have_header = true;
        continue;
      }
      if (fields.size() != columns_.size()) {
        throw std::runtime_error(path_ + ":" + std::to_string(line_number) + ": expected " +
                                 std::to_string(columns_.size()) + " columns, got " + std::to_string(fields.size()));
      }
      rows_.push_back(std::move(fields));
      lines_.push_back(line_number);
    }
    if (!have_header) throw std::runtime_error(path_ + ": empty file, expected header \"" + Join(columns_) + "\"");
  }

  size_t NumRows() const { return rows_.size(); }

  [[noreturn]] void Fail(size_t row, size_t column, const std::string& message) const {
    throw std::runtime_error(path_ + ":" + std::to_string(lines_[row]) + ": column " + std::to_string(column + 1) +
                             " (" + columns_[column] + "): " + message);
  }

  const std::string& Text(size_t row, size_t column) const { return rows_[row][column]; }

  double Double(size_t row, size_t column) const {
    const std::string& s = rows_[row][column];
    double value = 0.0;
    const auto result = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || result.ec != std::errc() || result.ptr != s.data() + s.size()) {
      Fail(row, column, "not a number: \"" + s + "\"");
    }
    if (!std::isfinite(value)) Fail(row, column, "not finite: \"" + s + "\"");
    return value;
  }

  int Int(size_t row, size_t column) const {
    const std::string& s = rows_[row][column];
    int value = 0;
    const auto result = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || result.ec != std::errc() || result.ptr != s.data() + s.size()) {
      Fail(row, column, "not an integer: \"" + s + "\"");
    }
    return value;
  }

  bool Bool(size_t row, size_t column) const {
    const std::string& s = rows_[row][column];
    if (s == "0") return false;
    if (s == "1") return true;
    Fail(row, column, "expected 0 or 1, got \"" + s + "\"");
  }

 private:
  static std::vector<std::string> Split(const std::string& line) {
    std::vector<std::string> fields;
    size_t start = 0;
    while (true) {
      const size_t comma = line.find(',', start);
      std::string field = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      // Tolerate spaces around fields.
      const size_t b = field.find_first_not_of(" \t");
      const size_t e = field.find_last_not_of(" \t");
      fields.push_back(b == std::string::npos ? std::string() : field.substr(b, e - b + 1));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    return fields;
  }

  std::string path_;
  std::vector<std::string> columns_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<int> lines_;
};

std::vector<FrameRecord> ReadFramesCsv(const std::string& path) {
  const std::string text = ReadFile(path);
  const bool old_layout = text.rfind(Join(kFramesColumnsWithoutMissing) + "\n", 0) == 0 ||
                          text.rfind(Join(kFramesColumnsWithoutMissing) + "\r\n", 0) == 0;
  const CsvReader csv(path, old_layout ? kFramesColumnsWithoutMissing : kFramesColumns);
  std::vector<FrameRecord> frames(csv.NumRows());
  for (size_t r = 0; r < csv.NumRows(); ++r) {
    FrameRecord& f = frames[r];
    f.frame = csv.Int(r, 0);
    if (f.frame < 0) csv.Fail(r, 0, "negative frame index");
    f.timestamp = csv.Double(r, 1);
    f.num_correspondences = csv.Int(r, 2);
    if (f.num_correspondences < 0) csv.Fail(r, 2, "negative count");
    f.num_inliers = csv.Int(r, 3);
    if (f.num_inliers < 0 || f.num_inliers > std::max(f.num_correspondences, 0)) {
      csv.Fail(r, 3, "must be in [0, num_correspondences]");
    }
    f.inlier_ratio = csv.Double(r, 4);
    if (f.inlier_ratio < 0.0 || f.inlier_ratio > 1.0) csv.Fail(r, 4, "must be in [0, 1]");
    f.mean_reproj_error_deg = csv.Double(r, 5);
    if (f.mean_reproj_error_deg < 0.0) csv.Fail(r, 5, "negative error");
    f.keyframe = csv.Bool(r, 6);
    const std::string& status = csv.Text(r, 7);
    try {
      f.status = FrameStatusFromName(status);
    } catch (const std::invalid_argument&) {
      csv.Fail(r, 7, "unknown status \"" + status + "\" (ok|init|lost)");
    }
    f.time_ms = csv.Double(r, 8);
    if (f.time_ms < 0.0) csv.Fail(r, 8, "negative time");
    if (!old_layout) {
      f.missing_cameras = csv.Text(r, 9);
      if (f.missing_cameras.find_first_not_of("0123456789;") != std::string::npos) {
        csv.Fail(r, 9, "expected camera indices separated by ';'");
      }
    }
    if (r > 0 && f.frame <= frames[r - 1].frame) csv.Fail(r, 0, "frame indices must increase");
  }
  return frames;
}

std::vector<ExtrinsicsRecord> ReadExtrinsicsCsv(const std::string& path) {
  const CsvReader csv(path, kExtrinsicsColumns);
  std::vector<ExtrinsicsRecord> records(csv.NumRows());
  for (size_t r = 0; r < csv.NumRows(); ++r) {
    ExtrinsicsRecord& e = records[r];
    e.frame = csv.Int(r, 0);
    if (e.frame < 0) csv.Fail(r, 0, "negative frame index");
    e.timestamp = csv.Double(r, 1);
    e.camera = csv.Int(r, 2);
    if (e.camera < 0) csv.Fail(r, 2, "negative camera index");
    const Eigen::Quaterniond q(csv.Double(r, 6), csv.Double(r, 3), csv.Double(r, 4), csv.Double(r, 5));
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > 1e-3) {
      csv.Fail(r, 3, "quaternion (qx,qy,qz,qw) is not unit length (norm " + FormatDouble(norm) + ")");
    }
    e.cam_from_rig = Rigid3(q, Eigen::Vector3d(csv.Double(r, 7), csv.Double(r, 8), csv.Double(r, 9)));
  }
  return records;
}

void RequireKey(const nlohmann::json& info, const std::string& path, const std::string& key) {
  if (!info.contains(key)) throw std::runtime_error(path + ": missing required field \"" + key + "\"");
}

void CheckRunInfo(const nlohmann::json& info, const std::string& path) {
  if (!info.is_object()) throw std::runtime_error(path + ": expected a JSON object");
  RequireKey(info, path, "mode");
  RequireKey(info, path, "dataset");
  RequireKey(info, path, "seed");
  const nlohmann::json& mode = info["mode"];
  if (!mode.is_string() || (mode != "gt" && mode != "noisy" && mode != "online")) {
    throw std::runtime_error(path + ": field \"mode\" must be \"gt\", \"noisy\" or \"online\", got " + mode.dump());
  }
  if (!info["dataset"].is_string()) throw std::runtime_error(path + ": field \"dataset\" must be a string");
  if (!info["seed"].is_number_integer()) throw std::runtime_error(path + ": field \"seed\" must be an integer");
}

}  // namespace

std::string RunTrajectoryPath(const std::string& run_dir) { return (fs::path(run_dir) / "trajectory.tum").string(); }
std::string RunFramesPath(const std::string& run_dir) { return (fs::path(run_dir) / "frames.csv").string(); }
std::string RunExtrinsicsPath(const std::string& run_dir) { return (fs::path(run_dir) / "extrinsics.csv").string(); }
const char* FrameStatusName(FrameStatus status) {
  switch (status) {
    case FrameStatus::kOk:
      return "ok";
    case FrameStatus::kInit:
      return "init";
    case FrameStatus::kLost:
      return "lost";
  }
  return "ok";
}

FrameStatus FrameStatusFromName(const std::string& name) {
  if (name == "ok") return FrameStatus::kOk;
  if (name == "init") return FrameStatus::kInit;
  if (name == "lost") return FrameStatus::kLost;
  throw std::invalid_argument("frame status: expected ok, init or lost, got \"" + name + "\"");
}

std::string RunInfoPath(const std::string& run_dir) { return (fs::path(run_dir) / "run.json").string(); }

void WriteFramesCsv(const std::string& path, const std::vector<FrameRecord>& frames) {
  std::string text = Join(kFramesColumns) + "\n";
  for (const FrameRecord& f : frames) {
    text += Join({std::to_string(f.frame), FormatDouble(f.timestamp), std::to_string(f.num_correspondences),
                  std::to_string(f.num_inliers), FormatDouble(f.inlier_ratio), FormatDouble(f.mean_reproj_error_deg),
                  f.keyframe ? "1" : "0", FrameStatusName(f.status), FormatDouble(f.time_ms), f.missing_cameras});
    text += '\n';
  }
  WriteFileAtomic(path, text);
}

void WriteExtrinsicsCsv(const std::string& path, const std::vector<ExtrinsicsRecord>& extrinsics) {
  std::string text = Join(kExtrinsicsColumns) + "\n";
  for (const ExtrinsicsRecord& e : extrinsics) {
    const Eigen::Quaterniond& q = e.cam_from_rig.rotation;
    const Eigen::Vector3d& t = e.cam_from_rig.translation;
    text += Join({std::to_string(e.frame), FormatDouble(e.timestamp), std::to_string(e.camera), FormatDouble(q.x()),
                  FormatDouble(q.y()), FormatDouble(q.z()), FormatDouble(q.w()), FormatDouble(t.x()),
                  FormatDouble(t.y()), FormatDouble(t.z())});
    text += '\n';
  }
  WriteFileAtomic(path, text);
}

void WriteRun(const std::string& run_dir, const RunData& run) {
  CheckRunInfo(run.info, RunInfoPath(run_dir));
  EnsureWritableDir(run_dir);
  WriteTum(RunTrajectoryPath(run_dir), run.trajectory);
  WriteFramesCsv(RunFramesPath(run_dir), run.frames);
  WriteExtrinsicsCsv(RunExtrinsicsPath(run_dir), run.extrinsics);
  // run.json last: its presence marks a complete run (suites resume on it).
  WriteJsonFileAtomic(RunInfoPath(run_dir), run.info);
}

RunData ReadRun(const std::string& run_dir) {
  if (!fs::is_directory(run_dir)) throw std::runtime_error(run_dir + ": run folder does not exist");
  RunData run;
  const std::string info_path = RunInfoPath(run_dir);
  run.info = ReadJsonFile(info_path);
  CheckRunInfo(run.info, info_path);
  run.trajectory = ReadTum(RunTrajectoryPath(run_dir));
  run.frames = ReadFramesCsv(RunFramesPath(run_dir));
  run.extrinsics = ReadExtrinsicsCsv(RunExtrinsicsPath(run_dir));
  return run;
}

}  // namespace rovo
