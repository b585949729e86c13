// Merging a suite: evaluation of every run, suite.json, table.md and report.html.
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

namespace {

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

}  // namespace

std::vector<PresetSummary> MergeSuite(const SuitePlan& plan) {
  std::vector<PresetSummary> summaries;
  for (size_t i = 0; i < plan.options.presets.size(); ++i) summaries.push_back(MergePreset(plan, i));
  WriteSuiteOutputs(plan, summaries);
  return summaries;
}

}  // namespace rovo
