#include "eval/gate.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "eval/format.h"
#include "eval/suite_summary.h"

namespace rovo {

namespace {

// The suite's mean of a metric (suite.json /presets/<preset>/modes/<mode>/<metric>, with n > 0 runs),
// or none when any part is missing or not of the expected type.
// Another system's figures are under /systems/<system>/presets/...
std::optional<double> SuiteMean(const nlohmann::json& suite, const std::string& system, const std::string& preset,
                                const std::string& mode, const std::string& metric) {
  const nlohmann::json* node = &suite;
  if (system != "rovo") {
    if (!suite.is_object() || !suite.contains("systems") || !suite["systems"].is_object() ||
        !suite["systems"].contains(system)) {
      return std::nullopt;
    }
    node = &suite["systems"][system];
  }
  for (const std::string& key : {std::string("presets"), preset, std::string("modes"), mode, metric}) {
    if (!node->is_object()) return std::nullopt;
    const auto it = node->find(key);
    if (it == node->end()) return std::nullopt;
    node = &*it;
  }
  if (!node->is_object()) return std::nullopt;
  const auto n = node->find("n"), mean = node->find("mean");
  if (n == node->end() || !n->is_number() || !(n->get<double>() > 0)) return std::nullopt;
  if (mean == node->end() || !mean->is_number()) return std::nullopt;
  return mean->get<double>();
}

}  // namespace

std::vector<GateCheck> CheckGates(const nlohmann::json& gates, const std::string& gates_what,
                                  const nlohmann::json& suite) {
  if (!gates.is_object() || !gates.contains("gates") || !gates["gates"].is_array()) {
    throw std::runtime_error(gates_what + ": missing array field \"gates\"");
  }
  const std::vector<std::string>& names = AggregatedMetricNames();
  std::vector<GateCheck> checks;
  int index = 0;
  for (const nlohmann::json& g : gates["gates"]) {
    const std::string where = gates_what + ": gates[" + std::to_string(index++) + "]";
    auto text = [&](const char* key) {
      if (!g.contains(key) || !g[key].is_string())
        throw std::runtime_error(where + ": missing string field \"" + key + "\"");
      return g[key].get<std::string>();
    };
    GateCheck c;
    c.preset = text("preset");
    c.mode = text("mode");
    c.metric = text("metric");
    if (c.mode != "gt" && c.mode != "noisy" && c.mode != "online") {
      throw std::runtime_error(where + ": field \"mode\" must be gt, noisy or online");
    }
    if (std::find(names.begin(), names.end(), c.metric) == names.end()) {
      throw std::runtime_error(where + ": field \"metric\": unknown metric \"" + c.metric + "\"");
    }
    const bool has_max = g.contains("max"), has_min = g.contains("min");
    if (has_max == has_min) throw std::runtime_error(where + ": exactly one of \"max\" and \"min\" is required");
    const nlohmann::json& bound = has_max ? g["max"] : g["min"];
    if (!bound.is_number())
      throw std::runtime_error(where + ": field \"" + (has_max ? "max" : "min") + "\" must be a number");
    c.is_max = has_max;
    c.bound = bound.get<double>();
    if (g.contains("system")) c.system = text("system");
    if (g.contains("note")) {
      if (!g["note"].is_string()) throw std::runtime_error(where + ": field \"note\" must be a string");
      c.note = g["note"].get<std::string>();
    }
    c.value = SuiteMean(suite, c.system, c.preset, c.mode, c.metric);
    c.pass = c.value && (c.is_max ? *c.value <= c.bound : *c.value >= c.bound);
    checks.push_back(c);
  }
  return checks;
}

bool AllGatesPass(const std::vector<GateCheck>& checks) {
  return std::all_of(checks.begin(), checks.end(), [](const GateCheck& c) { return c.pass; });
}

std::string GateTableMarkdown(const std::vector<GateCheck>& checks) {
  std::string md = "| preset | mode | metric | value (mean) | bound | result |\n|---|---|---|---|---|---|\n";
  for (const GateCheck& c : checks) {
    md += "| " + c.preset + (c.system != "rovo" ? " (" + c.system + ")" : "") + " | " + c.mode + " | " + c.metric +
          " | " + (c.value ? Fmt("%.4g", *c.value) : "missing") + " | " + (c.is_max ? "<= " : ">= ") +
          Fmt("%.4g", c.bound) + " | " + (c.pass ? "pass" : "**FAIL**") + " |\n";
  }
  return md;
}

}  // namespace rovo
