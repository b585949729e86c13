// What a suite does, from its options alone: entries and variants, seeds, the options as JSON, the plan.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <type_traits>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "datasets/run.h"
#include "eval/format.h"
#include "eval/orchestration/suite.h"
#include "eval/orchestration/suite_systems.h"
#include "eval/plots.h"
#include "eval/report.h"
#include "render/render.h"
#include "render/timing.h"
#include "rovo/version.h"
#include "scenes/city.h"
#include "scenes/rng.h"
#include "vo/pipeline.h"

namespace rovo {
namespace fs = std::filesystem;

uint64_t StoredNoiseSetSeed(uint64_t scene_seed, int k) {
  return MixSeed(scene_seed * 1000003ull + 17 + static_cast<uint64_t>(k));  // as render/render.cc
}

int64_t SuiteDrawSeed(uint64_t scene_seed, uint64_t vo_seed, int draw) {
  constexpr uint64_t kDrawDomain = 0x6472617773ull;  // "draws": a stream apart from the stored sets
  uint64_t x = MixSeed(MixSeed(MixSeed(scene_seed ^ kDrawDomain) + vo_seed) + static_cast<uint64_t>(draw));
  const auto stored = [&](uint64_t seed) {
    for (int k = 0; k < kNumPerturbedSets; ++k) {
      if (StoredNoiseSetSeed(scene_seed, k) == seed) return true;
    }
    return false;
  };
  // VoOptions::draw_seed is signed (-1 = no draw): keep 63 bits; step on in the rare clash.
  while (stored(x >> 1)) x = MixSeed(x);
  return static_cast<int64_t>(x >> 1);
}

nlohmann::json SuiteOptionsToJson(const SuiteOptions& o) {
  return {{"presets", o.presets},
          {"quick", o.quick},
          {"frames", o.frames},
          {"noise_sets", o.noise_sets},
          {"draws", o.draws},
          {"draw_sigma_deg", o.draw_sigma_deg},
          {"jobs", o.jobs},
          {"threads", o.threads},
          {"vo_threads", o.vo_threads},
          {"data_dir", o.data_dir},
          {"out_dir", o.out_dir},
          {"scene_seed", o.scene_seed},
          {"vo_seed", o.vo_seed},
          {"max_new_features", o.max_new_features},
          {"plots", o.plots},
          {"quiet", o.quiet},
          {"systems", o.systems}};
}

SuiteOptions SuiteOptionsFromJson(const nlohmann::json& j, const std::string& source) {
  SuiteOptions o;
  const char* field = "";
  try {
    auto get = [&](const char* name, auto* value) {
      field = name;
      *value = j.at(name).get<std::remove_pointer_t<decltype(value)>>();
    };
    get("presets", &o.presets);
    get("quick", &o.quick);
    get("frames", &o.frames);
    get("noise_sets", &o.noise_sets);
    get("draws", &o.draws);
    get("draw_sigma_deg", &o.draw_sigma_deg);
    get("jobs", &o.jobs);
    get("threads", &o.threads);
    get("vo_threads", &o.vo_threads);
    get("data_dir", &o.data_dir);
    get("out_dir", &o.out_dir);
    get("scene_seed", &o.scene_seed);
    get("vo_seed", &o.vo_seed);
    get("max_new_features", &o.max_new_features);
    get("plots", &o.plots);
    get("quiet", &o.quiet);
    field = "systems";
    if (j.contains("systems")) o.systems = j.at("systems").get<std::vector<std::string>>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(source + ": field \"" + field + "\": " + e.what());
  }
  return o;
}

const std::vector<std::string>& SuiteVariantNames() {
  static const std::vector<std::string> names = {"ideal", "sensor",  "gray",    "optics",
                                                 "blur",  "rolling", "trigger", "realistic"};
  return names;
}

SuiteEntry ParseSuiteEntry(const std::string& entry) {
  const size_t plus = entry.find('+');
  if (plus == std::string::npos) return {entry, ""};
  SuiteEntry e{entry.substr(0, plus), entry.substr(plus + 1)};
  const auto& names = SuiteVariantNames();
  if (std::find(names.begin(), names.end(), e.variant) == names.end()) {
    std::string valid;
    for (const std::string& n : names) valid += (valid.empty() ? "" : ", ") + n;
    throw std::invalid_argument("rovo suite: preset entry \"" + entry + "\": unknown variant \"" + e.variant +
                                "\" (valid: " + valid + ")");
  }
  return e;
}

std::vector<std::string> RobustnessEntries(const std::vector<std::string>& presets) {
  std::vector<std::string> base = presets.empty() ? std::vector<std::string>{"cloudy_urban"} : presets;
  std::vector<std::string> out;
  for (const std::string& p : base) {
    out.push_back(p);
    for (const std::string& v : SuiteVariantNames()) out.push_back(p + "+" + v);
  }
  for (const ScenePreset& p : HarderScenePresets()) {
    for (const std::string& entry : {p.name, p.name + "+realistic"})
      if (std::find(out.begin(), out.end(), entry) == out.end()) out.push_back(entry);
  }
  return out;
}

namespace {

// The dataset's folder is its reuse key: preset, quick, scene seed, and whether it carries an IMU (an IMU-less
// dataset is never reused for a system that needs the IMU).
std::string DatasetDirFor(const std::string& data_dir, const std::string& preset, const SuiteOptions& options,
                          bool imu) {
  return (fs::path(data_dir) /
          (preset + (options.quick ? "_quick" : "") + "_s" + std::to_string(options.scene_seed) + (imu ? "_imu" : "")))
      .string();
}

// The runs of one preset, in the order of the table and suite.json.
void PlanPresetRuns(const SuiteOptions& options, size_t preset_index, const std::string& runs_dir, int frame_end,
                    std::vector<SuiteRun>* runs) {
  const auto add = [&](const std::string& name, ExtrinsicsMode mode, int noise_set, int64_t draw_seed) {
    SuiteRun run;
    run.preset_index = preset_index;
    run.name = name;
    run.run_dir = (fs::path(runs_dir) / name).string();
    run.settings = RunSettings{
        mode, noise_set, draw_seed, options.draw_sigma_deg, frame_end, options.vo_seed, options.MaxNewFeatures()};
    runs->push_back(run);
  };
  add("gt", ExtrinsicsMode::kGroundTruth, 0, -1);
  for (int k = 0; k < options.noise_sets; ++k) {
    add("noisy_" + std::to_string(k), ExtrinsicsMode::kNoisy, k, -1);
    add("online_" + std::to_string(k), ExtrinsicsMode::kOnline, k, -1);
  }
  for (int d = 0; d < options.draws; ++d) {
    add("draw_" + std::to_string(d), ExtrinsicsMode::kOnline, 0, SuiteDrawSeed(options.scene_seed, options.vo_seed, d));
  }
}

}  // namespace

SuitePlan PlanSuite(const SuiteOptions& options) {
  if (options.out_dir.empty()) throw std::invalid_argument("rovo suite: --out is required");
  if (options.noise_sets < 1) throw std::invalid_argument("rovo suite: --seeds must be >= 1");
  if (options.draws < 0) throw std::invalid_argument("rovo suite: --draws must be >= 0");
  if (!(options.draw_sigma_deg >= 0.0)) throw std::invalid_argument("rovo suite: --draw-sigma must be >= 0");
  if (options.jobs < 1) throw std::invalid_argument("rovo suite: --jobs must be >= 1");
  if (options.frames < 0) throw std::invalid_argument("rovo suite: --frames must be >= 0");
  SuitePlan plan;
  plan.options = options;
  if (plan.options.presets.empty()) {
    for (const ScenePreset& p : ScenePresets()) plan.options.presets.push_back(p.name);
  }
  for (const std::string& file : options.systems) {
    plan.systems.push_back(ReadSystemDescription(file));
    plan.imu = plan.imu || plan.systems.back().needs_imu;
  }
  plan.data_dir = options.data_dir.empty() ? (fs::path(options.out_dir) / "data").string() : options.data_dir;
  for (size_t i = 0; i < plan.options.presets.size(); ++i) {
    const std::string& preset = plan.options.presets[i];
    const ScenePreset& p = FindScenePreset(ParseSuiteEntry(preset).preset);  // throws listing the valid names
    const int trajectory_frames = options.quick ? p.quick_frames : p.frames;
    const int frame_end = options.frames > 0 ? std::min(options.frames, trajectory_frames) : trajectory_frames;
    plan.dataset_dirs.push_back(DatasetDirFor(plan.data_dir, preset, options, plan.imu));
    plan.frame_ends.push_back(frame_end);
    PlanPresetRuns(options, i, (fs::path(options.out_dir) / "runs" / preset).string(), frame_end, &plan.runs);
  }
  for (size_t i = 0; i < plan.options.presets.size(); ++i) {
    PlanSystemRuns(plan, i, (fs::path(options.out_dir) / "runs" / plan.options.presets[i]).string(), plan.frame_ends[i],
                   &plan.runs);
  }
  return plan;
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
  if (s.contains("systems")) {
    if (!s["systems"].is_array()) fail("systems", "expected an array of system description files");
    for (const nlohmann::json& file : s["systems"]) {
      if (!file.is_string() || file.get<std::string>().empty()) {
        fail("systems", "expected an array of system description files");
      }
      const fs::path path(file.get<std::string>());
      options.systems.push_back(
          (path.is_relative() ? fs::absolute(gates_what).parent_path() / path : path).lexically_normal().string());
    }
  }
  return options;
}

}  // namespace rovo
