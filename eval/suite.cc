#include "eval/suite.h"

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

namespace {

// The options of a suite run (RunSettings recorded by RunVo).
VoOptions VoOptionsFor(const RunSettings& settings) {
  VoOptions vo;
  vo.start.mode = settings.mode;
  vo.start.noise_set = settings.noise_set;
  vo.start.draw_seed = settings.draw_seed;
  vo.start.draw_sigma_deg = settings.draw_sigma_deg;
  vo.frontend.max_new_features_per_view = settings.max_new_features;
  vo.backend.ransac.seed = settings.seed;
  vo.io.frames.end = settings.frame_end;
  return vo;
}

}  // namespace

bool RunReusable(const std::string& run_dir, const RunSettings& want, std::string* mismatch) {
  mismatch->clear();
  std::error_code ec;
  if (!fs::is_regular_file(RunInfoPath(run_dir), ec)) return false;
  nlohmann::json info;
  try {
    info = ReadJsonFile(RunInfoPath(run_dir));
  } catch (const std::exception&) {
    return false;
  }
  if (!info.is_object() || !info.contains("dataset") || !info.contains("frames") ||
      info["frames"] != nlohmann::json::array({0, want.frame_end}) ||
      !fs::is_regular_file(RunTrajectoryPath(run_dir), ec) || !fs::is_regular_file(RunFramesPath(run_dir), ec) ||
      !fs::is_regular_file(RunExtrinsicsPath(run_dir), ec)) {
    return false;  // incomplete (a run writes run.json last)
  }
  return VoRunSettingsMatch(info, VoOptionsFor(want), mismatch);
}

namespace {

// " (k of K runs)" when only k of the mode's K runs have the metric, else empty.
std::string ShortCount(const std::optional<Stat>& stat, int runs) {
  if (!stat || stat->n >= runs) return "";
  return " (" + std::to_string(stat->n) + " of " + std::to_string(runs) + " runs)";
}

// "mean +- std" (std omitted for a single run), with ShortCount.
std::string FmtStat(const std::optional<Stat>& stat, int runs, const char* format, double factor = 1.0) {
  if (!stat || stat->n == 0) return "n/a";
  std::string s = Fmt(format, stat->mean * factor);
  if (stat->n > 1) s += " ± " + Fmt(format, stat->std * factor);
  return s + ShortCount(stat, runs);
}

// Whether the dataset's sensor and timing records are the ones `render` would write (a variant's
// dataset rendered with other effects is not reused).
bool EffectsMatch(const DatasetInfo& info, const RenderOptions& render) {
  const int n = info.rig.NumCameras();
  if (render.sensor.enabled != info.sensor.has_value() || render.timing.Enabled() != info.timing.has_value())
    return false;
  if (info.sensor &&
      *info.sensor != MakeSensorRecord(render.sensor, CameraSensitivities(render.sensor, n, render.seed)))
    return false;
  return !info.timing ||
         *info.timing == MakeTimingRecord(render.timing, TriggerOffsetsMs(render.timing, n, render.seed));
}

// Complete: the first `max_frames` frames (all when <= 0) have every camera's image, and the effects
// match `render`'s.
bool DatasetComplete(const std::string& dataset_dir, int max_frames, const RenderOptions& render) {
  std::error_code ec;
  if (!fs::is_regular_file(DatasetJsonPath(dataset_dir), ec) ||
      !fs::is_regular_file(GroundTruthPath(dataset_dir), ec)) {
    return false;
  }
  try {
    const DatasetInfo info = ReadDatasetInfo(dataset_dir);
    if (!EffectsMatch(info, render)) return false;
    const int frames = max_frames > 0 ? std::min(max_frames, info.frame_count) : info.frame_count;
    for (int f = 0; f < frames; ++f) {
      for (const RigCamera& cam : info.rig.cameras) {
        if (!fs::is_regular_file(ImagePath(dataset_dir, cam.name, f), ec)) return false;
      }
    }
    return info.frame_count > 0 && info.frame_count >= max_frames;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

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
                                                 "missing_frames"};
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

std::optional<PaperRow> PaperRowForPreset(const std::string& preset) {
  static const std::vector<std::pair<std::string, PaperRow>> rows = {
      {"canyon_multifov", {"4view-MultiFOV", 440, 30.01, 0.60, 0.23, 47.8, 51.0, 0.19, 0.13}},
      {"static_urban", {"Static Urban", 2000, 83.17, 5.11, 5.0, 50.2, 53.2, 0.37, 0.25}},
      {"dynamic_urban", {"Dynamic Urban", 1320, 65.65, 5.68, 1.62, 56.9, 57.5, 0.29, 0.18}},
      {"cloudy_urban", {"Cloudy Urban", 350, 42.28, 1.43, 0.42, 59.1, 60.7, 0.31, 0.22}},
      {"sunset_urban", {"Sunset Urban", 350, 25.86, 1.92, 0.37, 51.8, 59.8, 0.23, 0.21}},
  };
  for (const auto& [name, row] : rows) {
    if (name == preset) return row;
  }
  return std::nullopt;
}

std::string SuiteTableMarkdown(const std::vector<PresetSummary>& presets, bool quick) {
  std::string md =
      "| sequence | frames | length [m] | RMSE NoisyExt [m] | RMSE OnlineExt [m] | RMSE GTExt [m] | rel. "
      "Noisy/Online/GT "
      "[%] | paper rel. Noisy/Online/GT [%] | inliers Online/GT [%] | paper | reproj Online/GT [deg] | paper | "
      "ext rot Online [deg] |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const PresetSummary& p : presets) {
    auto stat = [&](const char* mode, const char* name) -> std::optional<Stat> {
      const ModeSummary* m = p.Find(mode);
      return m ? m->Find(name) : std::nullopt;
    };
    auto runs = [&](const char* mode) {
      const ModeSummary* m = p.Find(mode);
      return m ? static_cast<int>(m->runs.size()) : 0;
    };
    auto mean = [&](const char* mode, const char* name, const char* format, double factor = 1.0) {
      const auto s = stat(mode, name);
      return (s && s->n > 0) ? Fmt(format, s->mean * factor) + ShortCount(s, runs(mode)) : std::string("n/a");
    };
    auto mean_std = [&](const char* mode, const char* name, const char* format) {
      return FmtStat(stat(mode, name), runs(mode), format);
    };
    const std::optional<PaperRow> paper = PaperRowForPreset(p.preset);
    std::string paper_rel = "-", paper_inl = "-", paper_rep = "-";
    if (paper) {
      paper_rel = Fmt("%.2f", 100.0 * paper->rmse_noisy / paper->length_m) + " / " +
                  Fmt("%.3f", 100.0 * paper->rmse_online / paper->length_m) + " / " +
                  Fmt("%.3f", 100.0 * paper->rmse_gt / paper->length_m);
      paper_inl = Fmt("%.1f", paper->inlier_online) + " / " + Fmt("%.1f", paper->inlier_gt);
      paper_rep = Fmt("%.2f", paper->reproj_online) + " / " + Fmt("%.2f", paper->reproj_gt);
    }
    const std::string name =
        (paper ? paper->sequence + " (`" + p.preset + "`)" : "`" + p.preset + "`") + (quick ? " quick" : "");
    const std::string frames =
        std::to_string(p.frames) +
        (p.dataset_frames > p.frames ? " of " + std::to_string(p.dataset_frames) : std::string());
    md += "| " + name + " | " + frames + " | " + Fmt("%.1f", p.path_length_m) + " | " +
          mean_std("noisy", "rmse_se3_m", "%.3f") + " | " + mean_std("online", "rmse_se3_m", "%.3f") + " | " +
          mean_std("gt", "rmse_se3_m", "%.3f") + " | " + mean("noisy", "relative_rmse_pct", "%.2f") + " / " +
          mean("online", "relative_rmse_pct", "%.3f") + " / " + mean("gt", "relative_rmse_pct", "%.3f") + " | " +
          paper_rel + " | " + mean("online", "mean_inlier_ratio", "%.1f", 100.0) + " / " +
          mean("gt", "mean_inlier_ratio", "%.1f", 100.0) + " | " + paper_inl + " | " +
          mean("online", "mean_reproj_error_deg", "%.3f") + " / " + mean("gt", "mean_reproj_error_deg", "%.3f") +
          " | " + paper_rep + " | " + mean_std("online", "max_final_ext_rotation_deg", "%.3f") + " |\n";
  }
  md +=
      "\nRMSE = translation RMSE after SE(3) Umeyama alignment (mean ± std over the noise sets; GTExt runs once; "
      "\"k of K runs\": only k runs have the value, e.g. a run lost on every frame has no trajectory to align); "
      "rel. = RMSE / ground-truth path length; the paper's relative errors use its Table I RMSEs and sequence "
      "lengths (4view-MultiFOV 440 m, Static 2000 m, Dynamic 1320 m, Cloudy 350 m, Sunset 350 m); our scenes "
      "differ from the paper's, so compare relative errors. inliers = mean inlier ratio of the multi-view P3P "
      "RANSAC; reproj = mean angular reprojection error of inliers; ext rot = largest error over cameras of "
      "cam_i_from_cam0 at the last frame.\n";
  return md;
}

nlohmann::json SuiteToJson(const std::vector<PresetSummary>& presets, const SuiteOptions& options) {
  nlohmann::json j;
  j["generator"] = "rovo suite";
  j["generator_version"] = ROVO_VERSION;
  j["quick"] = options.quick;
  j["frames"] = options.frames;
  j["noise_sets"] = options.noise_sets;
  if (options.draws > 0) {
    j["draws"] = options.draws;
    j["draw_sigma_deg"] = options.draw_sigma_deg;
  }
  j["scene_seed"] = options.scene_seed;
  j["vo_seed"] = options.vo_seed;
  j["max_new_features"] = options.MaxNewFeatures();
  j["presets"] = nlohmann::json::object();
  for (const PresetSummary& p : presets) {
    nlohmann::json pj;
    pj["dataset"] = p.dataset_dir;
    pj["frames"] = p.frames;
    pj["dataset_frames"] = p.dataset_frames;
    pj["path_length_m"] = p.path_length_m;
    for (const ModeSummary& m : p.modes) {
      nlohmann::json mj;
      for (const auto& [name, s] : m.stats) mj[name] = {{"mean", s.mean}, {"std", s.std}, {"n", s.n}};
      mj["runs"] = nlohmann::json::array();
      for (const RunMetrics& r : m.runs) mj["runs"].push_back(MetricsToJson(r));
      pj["modes"][m.mode] = mj;
    }
    if (const ModeSummary* draws = p.Find("draws")) {
      const DrawConvergence c = ComputeDrawConvergence(*draws);
      nlohmann::json& dj = pj["modes"]["draws"];
      dj["draw_seeds"] = draws->draw_seeds;
      dj["draw_sigma_deg"] = options.draw_sigma_deg;
      dj["converged"] = {{"below_deg", kDrawConvergedBelowDeg},
                         {"count", c.converged},
                         {"draws", c.draws},
                         {"rate", c.draws > 0 ? static_cast<double>(c.converged) / c.draws : 0.0},
                         {"failed_seeds", c.failed_seeds}};
    }
    j["presets"][p.preset] = pj;
  }
  return j;
}

std::string DrawTableMarkdown(const std::vector<PresetSummary>& presets, double draw_sigma_deg) {
  std::string md;
  for (const PresetSummary& p : presets) {
    const ModeSummary* draws = p.Find("draws");
    if (!draws) continue;
    const int n = static_cast<int>(draws->runs.size());
    const DrawConvergence c = ComputeDrawConvergence(*draws);
    std::string failed;
    for (int64_t seed : c.failed_seeds) failed += (failed.empty() ? "" : ", ") + std::to_string(seed);
    md += "| `" + p.preset + "` | " + std::to_string(n) + " | " + FmtStat(draws->Find("rmse_se3_m"), n, "%.3f") +
          " | " + FmtStat(draws->Find("max_final_ext_rotation_deg"), n, "%.3f") + " | " +
          Fmt("%.0f", 100.0 * c.converged / std::max(1, c.draws)) + " % (" + std::to_string(c.converged) + " of " +
          std::to_string(c.draws) + ") | " + (failed.empty() ? "-" : failed) + " |\n";
  }
  if (md.empty()) return "";
  return "## OnlineExt from fresh perturbation draws (σ = " + Fmt("%.1f", draw_sigma_deg) +
         "°)\n\n| sequence | draws | RMSE [m] | ext rot final [deg] | converged (< " +
         Fmt("%.1f", kDrawConvergedBelowDeg) + "°) | seeds not converged |\n|---|---|---|---|---|---|\n" + md +
         "\nmean ± std over the draws; ext rot = largest over cameras i ≥ 1 of the rotation angle of "
         "est(cam_i_from_cam0) · true(cam_i_from_cam0)⁻¹ at the last frame; a draw has converged when it is below "
         "the threshold. Draw seeds (suite.json \"draw_seeds\") are derived from the scene and VO seeds and never "
         "equal a stored noise set's.\n";
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
          {"quiet", o.quiet}};
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
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(source + ": field \"" + field + "\": " + e.what());
  }
  return o;
}

const std::vector<std::string>& SuiteVariantNames() {
  static const std::vector<std::string> names = {"ideal", "sensor", "gray", "blur", "rolling", "trigger", "realistic"};
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

// The render settings of a variant (ParseSuiteEntry), on top of the preset's.
void ApplySuiteVariant(const std::string& variant, RenderOptions* render) {
  if (variant.empty()) return;
  const bool sensor = variant == "sensor" || variant == "gray" || variant == "realistic";
  if (variant == "ideal") render->sensor = MakeSensorSettings("ideal", {});
  if (sensor) {
    SensorOverrides overrides;
    if (variant == "gray") overrides.grayscale = true;
    render->sensor = MakeSensorSettings("realistic", overrides);
  }
  if (variant == "realistic") render->timing = RealisticTiming();
  if (variant == "blur") render->timing.shutter_ms = 10.0;
  if (variant == "rolling") render->timing.rolling_shutter_ms = 30.0;
  if (variant == "trigger") render->timing.trigger_offset_std_ms = 1.0;
}

std::string DatasetDirFor(const std::string& data_dir, const std::string& preset, const SuiteOptions& options) {
  return (fs::path(data_dir) / (preset + (options.quick ? "_quick" : "") + "_s" + std::to_string(options.scene_seed)))
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

// The dataset must cover the runs' frames and hold the noise sets they use.
void CheckSuiteDataset(const SuitePlan& plan, size_t preset_index) {
  const std::string& dir = plan.dataset_dirs[preset_index];
  const DatasetInfo info = ReadDatasetInfo(dir);
  if (info.frame_count < plan.frame_ends[preset_index]) {
    throw std::runtime_error(DatasetJsonPath(dir) + ": field \"frame_count\" is " + std::to_string(info.frame_count) +
                             ", the suite runs frames [0, " + std::to_string(plan.frame_ends[preset_index]) + ")");
  }
  if (static_cast<int>(info.perturbed.size()) < plan.options.noise_sets) {
    throw std::runtime_error(DatasetJsonPath(dir) + ": field \"perturbed\" holds " +
                             std::to_string(info.perturbed.size()) + " noise sets, --seeds asks for " +
                             std::to_string(plan.options.noise_sets));
  }
}

// The PNGs of a report folder's plots/, sorted.
std::vector<std::string> ReportPngs(const std::string& report_dir) {
  std::vector<std::string> pngs;
  std::error_code ec;
  const fs::path plots = fs::path(report_dir) / "plots";
  if (!fs::is_directory(plots, ec)) return pngs;
  for (const auto& entry : fs::directory_iterator(plots, ec)) {
    if (entry.path().extension() == ".png") pngs.push_back(entry.path().string());
  }
  std::sort(pngs.begin(), pngs.end());
  return pngs;
}

// Evaluates the runs of one preset (writes reports/<preset>/) and aggregates them.
PresetSummary MergePreset(const SuitePlan& plan, size_t preset_index) {
  const SuiteOptions& options = plan.options;
  const std::string& preset = options.presets[preset_index];
  std::vector<const SuiteRun*> runs;
  std::vector<std::string> run_dirs;
  for (const SuiteRun& run : plan.runs) {
    if (run.preset_index != preset_index) continue;
    runs.push_back(&run);
    run_dirs.push_back(run.run_dir);
  }
  EvalReportOptions report;
  report.plots = options.plots;
  report.quiet = options.quiet;
  const std::string report_dir = (fs::path(options.out_dir) / "reports" / preset).string();
  const std::vector<RunEvaluation> evaluations =
      EvaluateAndReport(plan.dataset_dirs[preset_index], run_dirs, report_dir, report);
  PresetSummary summary;
  summary.preset = preset;
  summary.dataset_dir = fs::absolute(plan.dataset_dirs[preset_index]).lexically_normal().string();
  summary.frames = plan.frame_ends[preset_index];
  summary.dataset_frames = ReadDatasetInfo(plan.dataset_dirs[preset_index]).frame_count;
  std::vector<RunMetrics> metrics, draws;
  std::vector<int64_t> draw_seeds;
  for (size_t r = 0; r < evaluations.size(); ++r) {
    RunMetrics m = evaluations[r].metrics;
    const RunSettings& settings = runs[r]->settings;
    if (settings.draw_seed >= 0) m.noise_set = -1;
    if (m.noise_set < 0 && settings.mode != ExtrinsicsMode::kGroundTruth && settings.draw_seed < 0) {
      m.noise_set = settings.noise_set;
    }
    m.label = preset + "/" + m.label;
    summary.path_length_m = m.path_length_m;
    if (settings.draw_seed >= 0) {
      draws.push_back(m);
      draw_seeds.push_back(settings.draw_seed);
    } else {
      metrics.push_back(m);
    }
  }
  summary.modes = SummariseModes(metrics);
  if (!draws.empty()) {
    summary.modes.push_back(SummariseRuns("draws", draws));
    summary.modes.back().draw_seeds = draw_seeds;
  }
  return summary;
}

// table.md, suite.json and report.html of the merged presets.
void WriteSuiteOutputs(const SuitePlan& plan, const std::vector<PresetSummary>& summaries) {
  const SuiteOptions& options = plan.options;
  std::string table = SuiteTableMarkdown(summaries, options.quick);
  const std::string draw_table = DrawTableMarkdown(summaries, options.draw_sigma_deg);
  if (!draw_table.empty()) table += "\n" + draw_table;
  WriteFileAtomic((fs::path(options.out_dir) / "table.md").string(), "# rovo suite (Table I layout)\n\n" + table);
  WriteJsonFileAtomic((fs::path(options.out_dir) / "suite.json").string(), SuiteToJson(summaries, options));
  if (!options.plots) return;
  std::vector<RunMetrics> all_runs;
  std::vector<std::string> all_pngs;
  for (const PresetSummary& p : summaries) {
    for (const ModeSummary& m : p.modes) all_runs.insert(all_runs.end(), m.runs.begin(), m.runs.end());
    const std::vector<std::string> pngs = ReportPngs((fs::path(options.out_dir) / "reports" / p.preset).string());
    all_pngs.insert(all_pngs.end(), pngs.begin(), pngs.end());
  }
  // Captions name the preset through the report folder (reports/<preset>/plots/<plot>.png).
  WriteHtmlReport((fs::path(options.out_dir) / "report.html").string(), "rovo suite (Table I layout)",
                  table + "\n## All runs\n\n" + RunTableMarkdown(all_runs) + "\n" + MetricsLegendMarkdown(), all_pngs);
}

// Runs `todo` with `parallel` runs at a time; rethrows the first error after the running ones end.
void RunSuiteRunsInParallel(const SuitePlan& plan, const std::vector<const SuiteRun*>& todo, int parallel,
                            int threads_per_run) {
  Progress progress("suite VO runs", static_cast<int64_t>(todo.size()), "runs", plan.options.quiet);
  std::atomic<size_t> next{0};
  std::mutex error_mutex;
  std::exception_ptr first_error;
  auto worker = [&] {
    while (true) {
      const size_t index = next.fetch_add(1);
      if (index >= todo.size()) return;
      {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (first_error) return;
      }
      try {
        RunSuiteRun(plan, *todo[index], threads_per_run, plan.options.quiet || parallel > 1);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
      }
      progress.Add(1);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < parallel; ++i) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  progress.Finish();
  if (first_error) std::rethrow_exception(first_error);
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
  plan.data_dir = options.data_dir.empty() ? (fs::path(options.out_dir) / "data").string() : options.data_dir;
  for (size_t i = 0; i < plan.options.presets.size(); ++i) {
    const std::string& preset = plan.options.presets[i];
    const ScenePreset& p = FindScenePreset(ParseSuiteEntry(preset).preset);  // throws listing the valid names
    const int trajectory_frames = options.quick ? p.quick_frames : p.frames;
    const int frame_end = options.frames > 0 ? std::min(options.frames, trajectory_frames) : trajectory_frames;
    plan.dataset_dirs.push_back(DatasetDirFor(plan.data_dir, preset, options));
    plan.frame_ends.push_back(frame_end);
    PlanPresetRuns(options, i, (fs::path(options.out_dir) / "runs" / preset).string(), frame_end, &plan.runs);
  }
  return plan;
}

void RenderSuiteDataset(const SuitePlan& plan, size_t preset_index, int shard, int shards, int threads) {
  const SuiteOptions& options = plan.options;
  const std::string& dir = plan.dataset_dirs.at(preset_index);
  const std::string& preset = options.presets[preset_index];
  RenderOptions render;
  const SuiteEntry entry = ParseSuiteEntry(preset);
  render.preset = entry.preset;
  ApplySuiteVariant(entry.variant, &render);
  render.seed = options.scene_seed;
  if (DatasetComplete(dir, plan.frame_ends[preset_index], render)) {
    if (!options.quiet) std::fprintf(stderr, "rovo suite: dataset %s is complete, not rendering\n", dir.c_str());
    return;
  }
  if (!options.quiet) {
    std::fprintf(stderr, "rovo suite: rendering %s%s -> %s%s\n", preset.c_str(), options.quick ? " (quick)" : "",
                 dir.c_str(),
                 shards > 1 ? (" (shard " + std::to_string(shard) + "/" + std::to_string(shards) + ")").c_str() : "");
  }
  EnsureWritableDir(plan.data_dir);
  render.quick = options.quick;
  render.out_dir = dir;
  if (options.frames > 0) render.frame_end = plan.frame_ends[preset_index];
  render.shard_index = shard;
  render.shard_count = shards;
  render.threads = threads;
  render.depth = false;
  render.quiet = options.quiet;
  RenderDataset(render);
}

bool RunSuiteRun(const SuitePlan& plan, const SuiteRun& run, int threads, bool quiet) {
  std::string mismatch;
  if (RunReusable(run.run_dir, run.settings, &mismatch)) {
    if (!plan.options.quiet) std::fprintf(stderr, "rovo suite: run %s is complete, skipping\n", run.run_dir.c_str());
    return false;
  }
  if (!mismatch.empty()) {
    std::fprintf(stderr, "rovo suite: run %s was made with other settings (%s), running it again\n",
                 run.run_dir.c_str(), mismatch.c_str());
  }
  CheckSuiteDataset(plan, run.preset_index);
  VoOptions vo = VoOptionsFor(run.settings);
  vo.io.dataset_dir = plan.dataset_dirs[run.preset_index];
  vo.io.out_dir = run.run_dir;
  vo.io.threads = threads;
  vo.io.quiet = quiet;
  RunVo(vo);
  return true;
}

std::vector<PresetSummary> MergeSuite(const SuitePlan& plan) {
  std::vector<PresetSummary> summaries;
  for (size_t i = 0; i < plan.options.presets.size(); ++i) summaries.push_back(MergePreset(plan, i));
  WriteSuiteOutputs(plan, summaries);
  return summaries;
}

std::vector<PresetSummary> RunSuite(const SuiteOptions& options) {
  const SuitePlan plan = PlanSuite(options);
  EnsureWritableDir(options.out_dir);
  EnsureWritableDir(plan.data_dir);
  const int cores = options.threads > 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  // Datasets: rendering uses all cores, one dataset at a time.
  for (size_t i = 0; i < plan.dataset_dirs.size(); ++i) {
    RenderSuiteDataset(plan, i, 0, 1, cores);
    CheckSuiteDataset(plan, i);
  }
  // VO runs, --jobs at a time.
  std::vector<const SuiteRun*> todo;
  for (const SuiteRun& run : plan.runs) {
    std::string mismatch;
    if (!RunReusable(run.run_dir, run.settings, &mismatch)) todo.push_back(&run);
  }
  const int parallel = std::min<int>(options.jobs, std::max<int>(1, static_cast<int>(todo.size())));
  const int threads_per_run = options.vo_threads > 0 ? options.vo_threads : std::max(1, cores / parallel);
  RunSuiteRunsInParallel(plan, todo, parallel, threads_per_run);
  return MergeSuite(plan);
}

}  // namespace rovo
