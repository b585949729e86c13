// Aggregation of a suite's per-run metrics by mode (suite_summary.h).
#include "eval/suite_summary.h"

#include <algorithm>
#include <cmath>

namespace rovo {

Stat ComputeStat(const std::vector<double>& values) {
  Stat s;
  s.n = static_cast<int>(values.size());
  if (values.empty()) return s;
  for (double v : values) s.mean += v;
  s.mean /= s.n;
  if (s.n > 1) {
    double sum = 0.0;
    for (double v : values) sum += (v - s.mean) * (v - s.mean);
    s.std = std::sqrt(sum / (s.n - 1));
  }
  return s;
}

namespace {

// The RPE and body-aligned metrics (eval/body_offset.h): outer empty when `name` is not one of them,
// inner empty when the run has no value.
std::optional<std::optional<double>> BodyFrameMetricValue(const RunMetrics& m, const std::string& name) {
  using Value = std::optional<double>;
  const BodyAlignedMetrics& b = m.body;
  const Value rpe = m.rpe.num_pairs > 0 ? Value(0.0) : std::nullopt;
  const Value body_drift = b.available && b.drift.num_segments > 0 ? Value(0.0) : std::nullopt;
  const Value body_rpe = b.available && b.rpe.num_pairs > 0 ? Value(0.0) : std::nullopt;
  if (name == "rpe_translation_pct") return rpe ? Value(m.rpe.translation_pct) : std::nullopt;
  if (name == "rpe_rotation_deg") return rpe ? Value(m.rpe.rotation_rmse_deg) : std::nullopt;
  if (name == "body_aligned_rmse_origin_m") return b.available ? b.rmse_origin_m : std::nullopt;
  if (name == "body_aligned_drift_translation_pct") return body_drift ? Value(b.drift.translation_pct) : std::nullopt;
  if (name == "body_aligned_drift_rotation_deg_per_100m") {
    return body_drift ? Value(b.drift.rotation_deg_per_100m) : std::nullopt;
  }
  if (name == "body_aligned_rpe_translation_pct") return body_rpe ? Value(b.rpe.translation_pct) : std::nullopt;
  if (name == "body_aligned_rpe_rotation_deg") return body_rpe ? Value(b.rpe.rotation_rmse_deg) : std::nullopt;
  if (name == "body_offset_rotation_deg") return b.available ? Value(b.offset_rotation_deg) : std::nullopt;
  return std::nullopt;
}

}  // namespace

const std::vector<std::string>& AggregatedMetricNames() {
  static const std::vector<std::string> names = {"rmse_se3_m",
                                                 "relative_rmse_pct",
                                                 "rmse_origin_m",
                                                 "drift_translation_pct",
                                                 "drift_rotation_deg_per_100m",
                                                 "mean_inlier_ratio",
                                                 "mean_reproj_error_deg",
                                                 "max_final_ext_rotation_deg",
                                                 "max_final_ext_translation_m",
                                                 "mean_time_ms",
                                                 "lost_frames",
                                                 "missing_frames",
                                                 "rpe_translation_pct",
                                                 "rpe_rotation_deg",
                                                 "body_aligned_rmse_origin_m",
                                                 "body_aligned_drift_translation_pct",
                                                 "body_aligned_drift_rotation_deg_per_100m",
                                                 "body_aligned_rpe_translation_pct",
                                                 "body_aligned_rpe_rotation_deg",
                                                 "body_offset_rotation_deg"};
  return names;
}

std::optional<double> MetricValue(const RunMetrics& m, const std::string& name) {
  if (name == "rmse_se3_m") return m.rmse_se3_m;
  if (name == "relative_rmse_pct") return m.relative_rmse_pct;
  if (name == "rmse_origin_m") return m.rmse_origin_m;
  if (name == "drift_translation_pct")
    return m.drift.num_segments > 0 ? std::optional<double>(m.drift.translation_pct) : std::nullopt;
  if (name == "drift_rotation_deg_per_100m") {
    return m.drift.num_segments > 0 ? std::optional<double>(m.drift.rotation_deg_per_100m) : std::nullopt;
  }
  if (name == "mean_inlier_ratio") return m.mean_inlier_ratio;
  if (name == "mean_reproj_error_deg") return m.mean_reproj_error_deg;
  if (name == "max_final_ext_rotation_deg") return m.max_final_ext_rotation_deg;
  if (name == "max_final_ext_translation_m") return m.max_final_ext_translation_m;
  if (name == "mean_time_ms") return m.mean_time_ms;
  if (name == "lost_frames") return static_cast<double>(m.lost_frames);
  if (name == "missing_frames") return static_cast<double>(m.missing_frames);
  if (const auto v = BodyFrameMetricValue(m, name)) return *v;
  throw std::invalid_argument("unknown metric \"" + name + "\"");
}

std::optional<Stat> ModeSummary::Find(const std::string& name) const {
  for (const auto& [n, s] : stats) {
    if (n == name) return s;
  }
  return std::nullopt;
}

const ModeSummary* PresetSummary::Find(const std::string& mode) const {
  for (const ModeSummary& m : modes) {
    if (m.mode == mode) return &m;
  }
  return nullptr;
}

ModeSummary SummariseRuns(const std::string& mode, const std::vector<RunMetrics>& runs) {
  ModeSummary summary;
  summary.mode = mode;
  summary.runs = runs;
  for (const std::string& name : AggregatedMetricNames()) {
    std::vector<double> values;
    for (const RunMetrics& m : summary.runs) {
      if (const auto v = MetricValue(m, name)) values.push_back(*v);
    }
    // A run without a value (e.g. no trajectory) makes the whole statistic undefined: n counts
    // the runs that have it, and the table shows n when it is short.
    summary.stats.emplace_back(name, ComputeStat(values));
  }
  return summary;
}

std::vector<ModeSummary> SummariseModes(const std::vector<RunMetrics>& runs) {
  std::vector<ModeSummary> out;
  for (const char* mode : {"gt", "noisy", "online"}) {
    std::vector<RunMetrics> of_mode;
    for (const RunMetrics& m : runs) {
      if (m.mode == mode) of_mode.push_back(m);
    }
    if (!of_mode.empty()) out.push_back(SummariseRuns(mode, of_mode));
  }
  return out;
}

DrawConvergence ComputeDrawConvergence(const ModeSummary& draws) {
  DrawConvergence c;
  c.draws = static_cast<int>(draws.runs.size());
  for (size_t i = 0; i < draws.runs.size(); ++i) {
    const RunMetrics& m = draws.runs[i];
    if (!m.final_ext_rotation_deg.empty() && m.max_final_ext_rotation_deg < kDrawConvergedBelowDeg) {
      ++c.converged;
    } else if (i < draws.draw_seeds.size()) {
      c.failed_seeds.push_back(draws.draw_seeds[i]);
    }
  }
  return c;
}
}  // namespace rovo
