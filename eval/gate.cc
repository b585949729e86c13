#include "eval/gate.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "eval/suite.h"

namespace rovo {

namespace {

std::string Fmt(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

// The suite's mean of a metric (suite.json /presets/<preset>/modes/<mode>/<metric>, with n > 0 runs),
// or none when any part is missing or not of the expected type.
std::optional<double> SuiteMean(const nlohmann::json& suite, const std::string& preset, const std::string& mode,
                                const std::string& metric) {
  const nlohmann::json* node = &suite;
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
    if (g.contains("note")) {
      if (!g["note"].is_string()) throw std::runtime_error(where + ": field \"note\" must be a string");
      c.note = g["note"].get<std::string>();
    }
    c.value = SuiteMean(suite, c.preset, c.mode, c.metric);
    c.pass = c.value && (c.is_max ? *c.value <= c.bound : *c.value >= c.bound);
    checks.push_back(c);
  }
  return checks;
}

SuiteOptions GateSuiteOptions(const nlohmann::json& gates, const std::string& gates_what) {
  if (!gates.is_object() || !gates.contains("suite") || !gates["suite"].is_object()) {
    throw std::runtime_error(gates_what + ": missing object field \"suite\" (needed by --run)");
  }
  const nlohmann::json& s = gates["suite"];
  auto fail = [&](const std::string& key, const std::string& what) {
    throw std::runtime_error(gates_what + ": suite." + key + ": " + what);
  };
  // An integer field in [lo, hi], or `fallback` when absent.
  auto integer = [&](const char* key, int64_t fallback, int64_t lo, int64_t hi) {
    if (!s.contains(key)) return fallback;
    const nlohmann::json& v = s[key];
    if (!v.is_number_integer() || (v.is_number_unsigned() && v.get<uint64_t>() > static_cast<uint64_t>(hi)) ||
        v.get<int64_t>() < lo || v.get<int64_t>() > hi) {
      fail(key, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return v.get<int64_t>();
  };
  auto seed = [&](const char* key) {
    if (!s.contains(key)) return uint64_t{0};
    if (!s[key].is_number_unsigned()) fail(key, "expected a non-negative integer");
    return s[key].get<uint64_t>();
  };
  SuiteOptions options;
  if (!s.contains("presets") || !s["presets"].is_array()) fail("presets", "expected an array of preset names");
  for (const nlohmann::json& name : s["presets"]) {
    if (!name.is_string()) fail("presets", "expected an array of preset names");
    options.presets.push_back(name.get<std::string>());
  }
  options.quick = true;
  if (s.contains("quick")) {
    if (!s["quick"].is_boolean()) fail("quick", "expected true or false");
    options.quick = s["quick"].get<bool>();
  }
  options.noise_sets = static_cast<int>(integer("noise_sets", 1, 1, 1000));
  options.scene_seed = seed("scene_seed");
  options.vo_seed = seed("vo_seed");
  options.vo_threads = static_cast<int>(integer("vo_threads", 0, 0, 1024));
  options.max_new_features = static_cast<int>(integer("max_new_features", -1, -1, 1000000));
  return options;
}

bool AllGatesPass(const std::vector<GateCheck>& checks) {
  return std::all_of(checks.begin(), checks.end(), [](const GateCheck& c) { return c.pass; });
}

std::string GateTableMarkdown(const std::vector<GateCheck>& checks) {
  std::string md = "| preset | mode | metric | value (mean) | bound | result |\n|---|---|---|---|---|---|\n";
  for (const GateCheck& c : checks) {
    md += "| " + c.preset + " | " + c.mode + " | " + c.metric + " | " + (c.value ? Fmt(*c.value) : "missing") + " | " +
          (c.is_max ? "<= " : ">= ") + Fmt(c.bound) + " | " + (c.pass ? "pass" : "**FAIL**") + " |\n";
  }
  return md;
}

}  // namespace rovo
