#pragma once
// A suite's per-run metrics aggregated by preset and mode (mean +- std over the noise sets, draw
// convergence): scoring only, shared by the suite's merge, its tables and the CI gates.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "eval/metrics.h"

namespace rovo {

// Mean and sample standard deviation (n - 1; 0 for n = 1) of one metric over the noise sets.
struct Stat {
  double mean = 0.0;
  double std = 0.0;
  int n = 0;
};
Stat ComputeStat(const std::vector<double>& values);

// Aggregated metrics of one mode of one preset. Metric names as in MetricsToJson.
struct ModeSummary {
  std::string mode;  // gt | noisy | online | draws (OnlineExt runs from fresh perturbation draws)
  std::vector<RunMetrics> runs;
  std::vector<std::pair<std::string, Stat>> stats;  // name -> stat, names in kAggregatedMetrics order
  std::vector<int64_t> draw_seeds;                  // draws: the seed of each run, in runs order
  // Per run, in runs order (filled by the suite's merge; empty elsewhere): its folder and how it
  // ended ("ok", or an external system's failure: crashed, timeout, failed, no trajectory, ...).
  std::vector<std::string> run_dirs, statuses;
  std::optional<Stat> Find(const std::string& name) const;
};

// A draw has converged when its final extrinsic error (largest over cameras i >= 1 of the rotation
// angle of est(cam_i_from_cam0) * true(cam_i_from_cam0)^-1, RunMetrics::max_final_ext_rotation_deg)
// is below this; a run without extrinsics has not.
inline constexpr double kDrawConvergedBelowDeg = 0.1;
struct DrawConvergence {
  int converged = 0;
  int draws = 0;
  std::vector<int64_t> failed_seeds;  // seeds of the draws that did not converge
};
DrawConvergence ComputeDrawConvergence(const ModeSummary& draws);

// What a system's runs cost, mean over the runs that started (those that recorded it): an external
// system's wall and CPU time from wait4 and the peak resident memory of its process group
// (suite_systems.h); rovo's own in-process runs' wall time and getrusage(RUSAGE_SELF) CPU delta, and
// the rovo process's maxrss (process_maxrss: not the runs' own memory).
struct SystemCost {
  int runs = 0;
  double wall_s = 0.0, cpu_s = 0.0, peak_rss_mb = 0.0;
  bool process_maxrss = false;  // peak_rss_mb is the whole rovo process's maxrss
};

struct PresetSummary {
  std::string preset;
  std::string system = "rovo";  // rovo's pipeline, or an external system's name (docs/systems.md)
  std::string align = "se3";    // how its runs are scored: se3, or sim3 (scale fitted first)
  std::optional<SystemCost> cost;
  std::string dataset_dir;
  int frames = 0;                  // frames the runs cover (the first N of the dataset)
  int dataset_frames = 0;          // frames of the preset's trajectory; > frames for a --frames suite
  double path_length_m = 0.0;      // ground-truth length of the frames the runs cover
  std::vector<ModeSummary> modes;  // gt, noisy, online (those that ran)
  const ModeSummary* Find(const std::string& mode) const;
};

// Names of the aggregated metrics (keys of suite.json "presets.<p>.<mode>").
const std::vector<std::string>& AggregatedMetricNames();
// Value of an aggregated metric for one run (nullopt when undefined, e.g. RMSE of a failed run).
std::optional<double> MetricValue(const RunMetrics& metrics, const std::string& name);

// Groups per-run metrics by mode and aggregates them.
std::vector<ModeSummary> SummariseModes(const std::vector<RunMetrics>& runs);
// Aggregates the given runs as one mode.
ModeSummary SummariseRuns(const std::string& mode, const std::vector<RunMetrics>& runs);

}  // namespace rovo
