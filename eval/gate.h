#pragma once
// CI accuracy gate: thresholds (ci/gates.json) checked against a suite's suite.json.
//
// gates.json:
//   { "suite": {"presets": ["cloudy_urban"], "quick": true, "noise_sets": 1, "scene_seed": 0},
//     "gates": [ {"preset": "cloudy_urban", "mode": "gt", "metric": "relative_rmse_pct",
//                 "max": 0.5, "note": "..."}, ... ] }
// Each gate names a preset, a mode (gt|noisy|online), a metric of AggregatedMetricNames() and a
// bound "max" (value <= max passes) or "min" (value >= min passes). The value is the metric's
// mean over the suite's noise sets. A metric missing from the suite fails its gate.
// "suite" (read by `rovo gate --run`) may also hold "vo_seed", "vo_threads" and "max_new_features"
// (SuiteOptions); omitted ones take SuiteOptions' defaults.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace rovo {

struct GateCheck {
  std::string preset, mode, metric;
  bool is_max = true;  // bound kind: value <= bound (max) or value >= bound (min)
  double bound = 0.0;
  std::optional<double> value;
  bool pass = false;
  std::string note;
};

// Throws std::runtime_error naming `gates_what` and the gate index/field on a malformed gate file.
std::vector<GateCheck> CheckGates(const nlohmann::json& gates, const std::string& gates_what,
                                  const nlohmann::json& suite);
struct SuiteOptions;
// The "suite" object of a gates file (`rovo gate --run`): presets (strings), quick (bool), noise_sets
// (1..1000), scene_seed and vo_seed (non-negative integers), vo_threads (0..1024), max_new_features
// (-1..1000000); omitted fields keep quick true, noise_sets 1, seeds 0, vo_threads 0,
// max_new_features -1. Throws std::runtime_error "<gates_what>: suite.<field>: ..." otherwise.
SuiteOptions GateSuiteOptions(const nlohmann::json& gates, const std::string& gates_what);
bool AllGatesPass(const std::vector<GateCheck>& checks);
std::string GateTableMarkdown(const std::vector<GateCheck>& checks);

}  // namespace rovo
