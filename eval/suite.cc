#include "eval/suite.h"
#include "eval/format.h"

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "datasets/run.h"
#include "eval/plots.h"
#include "eval/report.h"
#include "render/render.h"
#include "rovo/version.h"
#include "scenes/city.h"
#include "vo/pipeline.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace rovo {
namespace fs = std::filesystem;

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
      info["frames"] != nlohmann::json::array({0, want.frame_end}) || !fs::is_regular_file(RunTrajectoryPath(run_dir), ec) ||
      !fs::is_regular_file(RunFramesPath(run_dir), ec) || !fs::is_regular_file(RunExtrinsicsPath(run_dir), ec)) {
    return false;  // incomplete (a run writes run.json last)
  }
  // Runs from before max_new_features was recorded had no limit.
  const nlohmann::json recorded_limit = info.value("max_new_features", nlohmann::json(0));
  const std::pair<const char*, std::pair<nlohmann::json, nlohmann::json>> checks[] = {
      {"mode", {info.value("mode", nlohmann::json()), ExtrinsicsModeName(want.mode)}},
      {"noise_set", {info.value("noise_set", nlohmann::json()), want.noise_set}},
      {"seed", {info.value("seed", nlohmann::json()), want.seed}},
      {"max_new_features", {recorded_limit, want.max_new_features}},
  };
  for (const auto& [field, values] : checks) {
    if (values.first != values.second) {
      *mismatch = std::string(field) + ": " + values.first.dump() + " vs " + values.second.dump();
      return false;
    }
  }
  return true;
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

// Complete: the first `max_frames` frames (all when <= 0) have every camera's image.
bool DatasetComplete(const std::string& dataset_dir, int max_frames) {
  std::error_code ec;
  if (!fs::is_regular_file(DatasetJsonPath(dataset_dir), ec) || !fs::is_regular_file(GroundTruthPath(dataset_dir), ec)) {
    return false;
  }
  try {
    const DatasetInfo info = ReadDatasetInfo(dataset_dir);
    const int frames = max_frames > 0 ? std::min(max_frames, info.frame_count) : info.frame_count;
    for (int f = 0; f < frames; ++f) {
      for (const RigCamera& cam : info.rig.cameras) {
        if (!fs::is_regular_file(ImagePath(dataset_dir, cam.name, f), ec)) return false;
      }
    }
    return info.frame_count > 0;
  } catch (const std::exception&) {
    return false;
  }
}

struct VoJob {
  std::string preset;
  std::string dataset_dir;
  std::string run_dir;
  RunSettings settings;
};

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
  static const std::vector<std::string> names = {
      "rmse_se3_m",          "relative_rmse_pct",          "rmse_origin_m",          "drift_translation_pct",
      "drift_rotation_deg_per_100m", "mean_inlier_ratio",  "mean_reproj_error_deg",  "max_final_ext_rotation_deg",
      "max_final_ext_translation_m", "mean_time_ms",       "lost_frames",            "missing_frames"};
  return names;
}

std::optional<double> MetricValue(const RunMetrics& m, const std::string& name) {
  if (name == "rmse_se3_m") return m.rmse_se3_m;
  if (name == "relative_rmse_pct") return m.relative_rmse_pct;
  if (name == "rmse_origin_m") return m.rmse_origin_m;
  if (name == "drift_translation_pct") return m.drift.num_segments > 0 ? std::optional<double>(m.drift.translation_pct) : std::nullopt;
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

std::vector<ModeSummary> SummariseModes(const std::vector<RunMetrics>& runs) {
  std::vector<ModeSummary> out;
  for (const char* mode : {"gt", "noisy", "online"}) {
    ModeSummary summary;
    summary.mode = mode;
    for (const RunMetrics& m : runs) {
      if (m.mode == mode) summary.runs.push_back(m);
    }
    if (summary.runs.empty()) continue;
    for (const std::string& name : AggregatedMetricNames()) {
      std::vector<double> values;
      for (const RunMetrics& m : summary.runs) {
        if (const auto v = MetricValue(m, name)) values.push_back(*v);
      }
      // A run without a value (e.g. no trajectory) makes the whole statistic undefined: n counts
      // the runs that have it, and the table shows n when it is short.
      summary.stats.emplace_back(name, ComputeStat(values));
    }
    out.push_back(std::move(summary));
  }
  return out;
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
      "| sequence | frames | length [m] | RMSE NoisyExt [m] | RMSE OnlineExt [m] | RMSE GTExt [m] | rel. Noisy/Online/GT "
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
    const std::string name = (paper ? paper->sequence + " (`" + p.preset + "`)" : "`" + p.preset + "`") +
                             (quick ? " quick" : "");
    const std::string frames = std::to_string(p.frames) + (p.dataset_frames > p.frames
                                                               ? " of " + std::to_string(p.dataset_frames)
                                                               : std::string());
    md += "| " + name + " | " + frames + " | " + Fmt("%.1f", p.path_length_m) + " | " +
          mean_std("noisy", "rmse_se3_m", "%.3f") + " | " + mean_std("online", "rmse_se3_m", "%.3f") + " | " +
          mean_std("gt", "rmse_se3_m", "%.3f") + " | " + mean("noisy", "relative_rmse_pct", "%.2f") + " / " +
          mean("online", "relative_rmse_pct", "%.3f") + " / " + mean("gt", "relative_rmse_pct", "%.3f") + " | " +
          paper_rel + " | " + mean("online", "mean_inlier_ratio", "%.1f", 100.0) + " / " +
          mean("gt", "mean_inlier_ratio", "%.1f", 100.0) + " | " + paper_inl + " | " +
          mean("online", "mean_reproj_error_deg", "%.3f") + " / " + mean("gt", "mean_reproj_error_deg", "%.3f") +
          " | " + paper_rep + " | " + mean_std("online", "max_final_ext_rotation_deg", "%.3f") + " |\n";
  }
  md += "\nRMSE = translation RMSE after SE(3) Umeyama alignment (mean ± std over the noise sets; GTExt runs once; "
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
    j["presets"][p.preset] = pj;
  }
  return j;
}

std::vector<PresetSummary> RunSuite(const SuiteOptions& options) {
  if (options.out_dir.empty()) throw std::invalid_argument("rovo suite: --out is required");
  if (options.noise_sets < 1) throw std::invalid_argument("rovo suite: --seeds must be >= 1");
  if (options.jobs < 1) throw std::invalid_argument("rovo suite: --jobs must be >= 1");
  std::vector<std::string> presets = options.presets;
  if (presets.empty()) {
    for (const ScenePreset& p : ScenePresets()) presets.push_back(p.name);
  }
  for (const std::string& p : presets) FindScenePreset(p);  // throws listing the valid names
  const std::string data_dir = options.data_dir.empty() ? (fs::path(options.out_dir) / "data").string() : options.data_dir;
  EnsureWritableDir(options.out_dir);
  EnsureWritableDir(data_dir);
  const int cores = options.threads > 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());

  // 1. Datasets (rendering uses all cores, one dataset at a time).
  std::vector<std::string> dataset_dirs;
  for (const std::string& preset : presets) {
    const std::string dir = (fs::path(data_dir) / (preset + (options.quick ? "_quick" : "") + "_s" +
                                                   std::to_string(options.scene_seed)))
                                .string();
    dataset_dirs.push_back(dir);
    if (DatasetComplete(dir, options.frames)) {
      if (!options.quiet) std::fprintf(stderr, "rovo suite: dataset %s is complete, not rendering\n", dir.c_str());
      continue;
    }
    if (!options.quiet) std::fprintf(stderr, "rovo suite: rendering %s%s -> %s\n", preset.c_str(),
                                     options.quick ? " (quick)" : "", dir.c_str());
    RenderOptions render;
    render.preset = preset;
    render.quick = options.quick;
    render.out_dir = dir;
    render.seed = options.scene_seed;
    if (options.frames > 0) {
      const ScenePreset& p = FindScenePreset(preset);
      render.frame_end = std::min(options.frames, options.quick ? p.quick_frames : p.frames);
    }
    render.threads = cores;
    render.depth = false;
    render.quiet = options.quiet;
    RenderDataset(render);
  }

  // 2. VO runs.
  std::vector<VoJob> jobs;
  std::vector<int> frame_ends;      // per preset: runs cover frames [0, end)
  std::vector<int> dataset_frames;  // per preset: frames of the dataset
  for (size_t i = 0; i < presets.size(); ++i) {
    const DatasetInfo info = ReadDatasetInfo(dataset_dirs[i]);
    frame_ends.push_back(options.frames > 0 ? std::min(options.frames, info.frame_count) : info.frame_count);
    dataset_frames.push_back(info.frame_count);
    if (static_cast<int>(info.perturbed.size()) < options.noise_sets) {
      throw std::runtime_error(DatasetJsonPath(dataset_dirs[i]) + ": field \"perturbed\" holds " +
                               std::to_string(info.perturbed.size()) + " noise sets, --seeds asks for " +
                               std::to_string(options.noise_sets));
    }
    const fs::path runs = fs::path(options.out_dir) / "runs" / presets[i];
    const int end = frame_ends[i];
    const auto settings = [&](ExtrinsicsMode mode, int noise_set) {
      return RunSettings{mode, noise_set, end, options.vo_seed, options.MaxNewFeatures()};
    };
    jobs.push_back({presets[i], dataset_dirs[i], (runs / "gt").string(), settings(ExtrinsicsMode::kGroundTruth, 0)});
    for (int k = 0; k < options.noise_sets; ++k) {
      jobs.push_back({presets[i], dataset_dirs[i], (runs / ("noisy_" + std::to_string(k))).string(),
                      settings(ExtrinsicsMode::kNoisy, k)});
      jobs.push_back({presets[i], dataset_dirs[i], (runs / ("online_" + std::to_string(k))).string(),
                      settings(ExtrinsicsMode::kOnline, k)});
    }
  }
  std::vector<const VoJob*> todo;
  for (const VoJob& job : jobs) {
    std::string mismatch;
    if (RunReusable(job.run_dir, job.settings, &mismatch)) {
      if (!options.quiet) std::fprintf(stderr, "rovo suite: run %s is complete, skipping\n", job.run_dir.c_str());
    } else {
      if (!mismatch.empty()) {
        std::fprintf(stderr, "rovo suite: run %s was made with other settings (%s), running it again\n",
                     job.run_dir.c_str(), mismatch.c_str());
      }
      todo.push_back(&job);
    }
  }
  const int parallel = std::min<int>(options.jobs, std::max<int>(1, static_cast<int>(todo.size())));
  const int threads_per_job = options.vo_threads > 0 ? options.vo_threads : std::max(1, cores / parallel);
  {
    Progress progress("suite VO runs", static_cast<int64_t>(todo.size()), "runs", options.quiet);
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
        const VoJob& job = *todo[index];
        try {
          VoOptions vo;
          vo.dataset_dir = job.dataset_dir;
          vo.out_dir = job.run_dir;
          vo.mode = job.settings.mode;
          vo.noise_set = job.settings.noise_set;
          vo.max_new_features = job.settings.max_new_features;
          vo.seed = options.vo_seed;
          vo.threads = threads_per_job;
          vo.quiet = options.quiet || parallel > 1;
          vo.frame_end = job.settings.frame_end;
          RunVo(vo);
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

  // 3. Evaluation per preset, aggregation, table, report.
  std::vector<PresetSummary> summaries;
  std::vector<std::string> all_pngs;
  for (size_t i = 0; i < presets.size(); ++i) {
    std::vector<std::string> run_dirs;
    std::vector<int> noise_sets;
    for (const VoJob& job : jobs) {
      if (job.preset == presets[i]) {
        run_dirs.push_back(job.run_dir);
        noise_sets.push_back(job.settings.mode == ExtrinsicsMode::kGroundTruth ? -1 : job.settings.noise_set);
      }
    }
    EvalReportOptions report;
    report.plots = options.plots;
    report.quiet = options.quiet;
    const std::string report_dir = (fs::path(options.out_dir) / "reports" / presets[i]).string();
    const std::vector<RunEvaluation> evaluations = EvaluateAndReport(dataset_dirs[i], run_dirs, report_dir, report);
    PresetSummary summary;
    summary.preset = presets[i];
    summary.dataset_dir = fs::absolute(dataset_dirs[i]).lexically_normal().string();
    summary.frames = frame_ends[i];
    summary.dataset_frames = dataset_frames[i];
    std::vector<RunMetrics> metrics;
    for (size_t r = 0; r < evaluations.size(); ++r) {
      RunMetrics m = evaluations[r].metrics;
      if (m.noise_set < 0) m.noise_set = noise_sets[r];
      m.label = presets[i] + "/" + m.label;
      summary.path_length_m = m.path_length_m;
      metrics.push_back(m);
    }
    summary.modes = SummariseModes(metrics);
    summaries.push_back(std::move(summary));
    std::error_code ec;
    const fs::path plots = fs::path(report_dir) / "plots";
    if (options.plots && fs::is_directory(plots, ec)) {
      std::vector<std::string> pngs;
      for (const auto& entry : fs::directory_iterator(plots, ec)) {
        if (entry.path().extension() == ".png") pngs.push_back(entry.path().string());
      }
      std::sort(pngs.begin(), pngs.end());
      all_pngs.insert(all_pngs.end(), pngs.begin(), pngs.end());
    }
  }
  const std::string table = SuiteTableMarkdown(summaries, options.quick);
  WriteFileAtomic((fs::path(options.out_dir) / "table.md").string(), "# rovo suite (Table I layout)\n\n" + table);
  WriteJsonFileAtomic((fs::path(options.out_dir) / "suite.json").string(), SuiteToJson(summaries, options));
  if (options.plots) {
    std::vector<RunMetrics> all_runs;
    for (const PresetSummary& p : summaries) {
      for (const ModeSummary& m : p.modes) all_runs.insert(all_runs.end(), m.runs.begin(), m.runs.end());
    }
    // Captions name the preset through the report folder (reports/<preset>/plots/<plot>.png).
    WriteHtmlReport((fs::path(options.out_dir) / "report.html").string(), "rovo suite (Table I layout)",
                    table + "\n## All runs\n\n" + RunTableMarkdown(all_runs) + "\n" + MetricsLegendMarkdown(),
                    all_pngs);
  }
  return summaries;
}

}  // namespace rovo
