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
// A gate may name a "system" (default "rovo"): the value is then that system's (docs/systems.md), from
// suite.json's /systems/<system>/presets/...
// "suite" (read by `rovo gate --run`, GateSuiteOptions in eval/orchestration/suite.h) may also hold "vo_seed",
// "vo_threads", "max_new_features" and "systems" (description files, relative to the gates file's
// folder; SuiteOptions); omitted ones take SuiteOptions' defaults.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace rovo {

struct GateCheck {
  std::string preset, mode, metric;
  std::string system = "rovo";  // "system": another system of the suite (suite.json /systems/<system>)
  bool is_max = true;           // bound kind: value <= bound (max) or value >= bound (min)
  double bound = 0.0;
  std::optional<double> value;
  bool pass = false;
  std::string note;
};

// Throws std::runtime_error naming `gates_what` and the gate index/field on a malformed gate file.
std::vector<GateCheck> CheckGates(const nlohmann::json& gates, const std::string& gates_what,
                                  const nlohmann::json& suite);
bool AllGatesPass(const std::vector<GateCheck>& checks);
std::string GateTableMarkdown(const std::vector<GateCheck>& checks);

}  // namespace rovo
