#include "datasets/exposure_csv.h"

#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "datasets/io.h"
#include "datasets/json_check.h"

namespace rovo {

namespace {

constexpr const char* kExposureHeader = "frame,camera,exposure_ms,gain,meter_luminance,dn_per_radiance,dark_dn";

}  // namespace

std::vector<ExposureRow> ParseExposureCsv(const std::string& text, const std::string& path, int frame_count,
                                          const Rig& rig, std::vector<ValidationIssue>* issues) {
  std::vector<ExposureRow> rows;
  const int num_cameras = rig.NumCameras();
  std::stringstream in(text);
  std::string line;
  int line_number = 0;
  auto issue = [&](const std::string& message) {
    issues->push_back({path, "line " + std::to_string(line_number), message});
  };
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1) {
      if (line != kExposureHeader) issue(std::string("expected the header `") + kExposureHeader + "`");
      continue;
    }
    if (line.empty()) continue;
    std::vector<std::string> fields;
    std::stringstream fs_line(line);
    for (std::string f; std::getline(fs_line, f, ',');) fields.push_back(f);
    if (fields.size() != 7) {
      issue("expected 7 comma-separated fields, found " + std::to_string(fields.size()));
      continue;
    }
    const int index = static_cast<int>(rows.size());
    ExposureRow row;
    const int expected_frame = num_cameras > 0 ? index / num_cameras : 0;
    const std::string expected_camera = num_cameras > 0 ? rig.cameras[index % num_cameras].name : "";
    char* end = nullptr;
    const long frame = std::strtol(fields[0].c_str(), &end, 10);
    if (fields[0].empty() || *end != '\0' || frame != expected_frame)
      issue("column frame: `" + fields[0] + "`, expected " + std::to_string(expected_frame) +
            " (rows are frame-major, cameras in rig order)");
    row.frame = static_cast<int>(frame);
    row.camera = fields[1];
    if (row.camera != expected_camera) issue("column camera: `" + row.camera + "`, expected `" + expected_camera + "`");
    const char* names[5] = {"exposure_ms", "gain", "meter_luminance", "dn_per_radiance", "dark_dn"};
    const double lower[5] = {0.0, 1.0, 0.0, 0.0, 0.0};
    const bool lower_open[5] = {true, false, false, true, false};
    double* values[5] = {&row.exposure_ms, &row.gain, &row.meter_luminance, &row.dn_per_radiance, &row.dark_dn};
    for (int k = 0; k < 5; ++k) {
      const std::string& f = fields[2 + k];
      const double v = std::strtod(f.c_str(), &end);
      if (f.empty() || *end != '\0' || !std::isfinite(v)) {
        issue(std::string("column ") + names[k] + ": `" + f + "` is not a finite number");
      } else if (v < lower[k] || (lower_open[k] && v == lower[k])) {
        issue(std::string("column ") + names[k] + ": " + JsonChecker::Format(v) + " must be " +
              (lower_open[k] ? "> " : ">= ") + JsonChecker::Format(lower[k]));
      }
      *values[k] = v;
    }
    rows.push_back(row);
  }
  const size_t expected_rows = static_cast<size_t>(frame_count) * num_cameras;
  if (line_number == 0) {
    issues->push_back({path, "file", "empty file (expected the header and one row per frame and camera)"});
  } else if (rows.size() != expected_rows) {
    issues->push_back({path, "lines",
                       std::to_string(rows.size()) + " rows but dataset.json has " + std::to_string(frame_count) +
                           " frames x " + std::to_string(num_cameras) + " cameras = " + std::to_string(expected_rows)});
  }
  return rows;
}

void WriteExposureCsv(const std::string& path, const std::vector<ExposureRow>& rows) {
  std::string text = std::string(kExposureHeader) + "\n";
  char buf[512];
  for (const ExposureRow& r : rows) {
    std::snprintf(buf, sizeof(buf), "%d,%s,%.17g,%.17g,%.17g,%.17g,%.17g\n", r.frame, r.camera.c_str(), r.exposure_ms,
                  r.gain, r.meter_luminance, r.dn_per_radiance, r.dark_dn);
    text += buf;
  }
  WriteFileAtomic(path, text);
}

std::vector<ExposureRow> ReadExposureCsv(const std::string& path, int frame_count, const Rig& rig) {
  std::vector<ValidationIssue> issues;
  std::vector<ExposureRow> rows = ParseExposureCsv(ReadFile(path), path, frame_count, rig, &issues);
  if (!issues.empty()) throw std::runtime_error(JoinIssues(issues));
  return rows;
}

}  // namespace rovo
