// Merging a suite: evaluation of every run, suite.json, table.md and report.html.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
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

namespace {

// Mean wall and CPU time per run and the peak memory; rovo's own runs name their memory
// process_maxrss_mb (the rovo process's maxrss, not the run's own).
nlohmann::json CostJson(const SystemCost& cost) {
  return {{"runs", cost.runs},
          {"wall_s", cost.wall_s},
          {"cpu_s", cost.cpu_s},
          {cost.process_maxrss ? "process_maxrss_mb" : "peak_rss_mb", cost.peak_rss_mb}};
}

// Each system's cost over all presets: means weighted by the presets' runs, the largest memory.
std::map<std::string, SystemCost> CostPerSystem(const std::vector<PresetSummary>& presets) {
  std::map<std::string, SystemCost> out;
  for (const PresetSummary& p : presets) {
    if (!p.cost) continue;
    SystemCost& c = out[p.system];
    c.wall_s += p.cost->wall_s * p.cost->runs;
    c.cpu_s += p.cost->cpu_s * p.cost->runs;
    c.runs += p.cost->runs;
    c.peak_rss_mb = std::max(c.peak_rss_mb, p.cost->peak_rss_mb);
    c.process_maxrss = p.cost->process_maxrss;
  }
  for (auto& [name, c] : out) {
    c.wall_s /= c.runs;
    c.cpu_s /= c.runs;
  }
  return out;
}

nlohmann::json PresetJson(const PresetSummary& p, const SuiteOptions& options) {
  nlohmann::json pj;
  pj["dataset"] = p.dataset_dir;
  pj["frames"] = p.frames;
  pj["dataset_frames"] = p.dataset_frames;
  pj["path_length_m"] = p.path_length_m;
  pj["align"] = p.align;
  if (p.cost) pj["cost_per_run"] = CostJson(*p.cost);
  for (const ModeSummary& m : p.modes) {
    nlohmann::json mj;
    for (const auto& [name, s] : m.stats) mj[name] = {{"mean", s.mean}, {"std", s.std}, {"n", s.n}};
    mj["runs"] = nlohmann::json::array();
    for (size_t r = 0; r < m.runs.size(); ++r) {
      nlohmann::json rj = MetricsToJson(m.runs[r]);
      if (r < m.run_dirs.size()) rj["run_dir"] = m.run_dirs[r];
      if (r < m.statuses.size()) rj["status"] = m.statuses[r];
      mj["runs"].push_back(rj);
    }
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
  return pj;
}

}  // namespace

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
  // "presets": rovo's pipeline (as before systems existed); "systems": every system, rovo's included.
  j["presets"] = nlohmann::json::object();
  j["systems"] = nlohmann::json::object();
  for (const PresetSummary& p : presets) {
    const nlohmann::json pj = PresetJson(p, options);
    if (p.system == kBuiltInSystem) j["presets"][p.preset] = pj;
    j["systems"][p.system]["presets"][p.preset] = pj;
  }
  for (const auto& [name, cost] : CostPerSystem(presets)) j["systems"][name]["cost_per_run"] = CostJson(cost);
  for (const std::string& file : options.systems) {
    const SystemDescription d = ReadSystemDescription(file);
    j["systems"][d.name]["description"] = fs::absolute(file).lexically_normal().string();
    j["systems"][d.name]["input"] = d.input;
    j["systems"][d.name]["online_calibration"] = d.online_calibration;
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

double GtPathLengthOfSpan(const Trajectory& gt, int frames) {
  return GtPathLength(Trajectory(gt.begin(), gt.begin() + std::min<long>(frames, static_cast<long>(gt.size()))));
}

// A run that left no trajectory to score: its metrics say only which frames it lacks.
RunMetrics UnscoredRun(const std::string& label, const RunSettings& settings, int frames,
                       const ExternalRunRecord& record) {
  RunMetrics m;
  m.label = label;
  m.mode = settings.mode == ExtrinsicsMode::kGroundTruth ? "gt"
           : settings.mode == ExtrinsicsMode::kNoisy     ? "noisy"
                                                         : "online";
  m.noise_set = settings.mode == ExtrinsicsMode::kGroundTruth ? -1 : settings.noise_set;
  m.gt_frames = frames;
  m.missing_frames = frames;
  m.alignment_note = record.status + (record.detail.empty() ? "" : ": " + record.detail);
  return m;
}

// One system's runs of a preset, aggregated by mode (their evaluations in `scored`, by run).
PresetSummary SummariseSystem(const SuitePlan& plan, size_t preset_index, int system,
                              const std::vector<const SuiteRun*>& runs,
                              const std::vector<std::optional<RunMetrics>>& scored) {
  PresetSummary summary;
  summary.preset = plan.options.presets[preset_index];
  summary.system = system < 0 ? kBuiltInSystem : plan.systems[static_cast<size_t>(system)].name;
  summary.align = system < 0 ? "se3" : plan.systems[static_cast<size_t>(system)].align;
  summary.dataset_dir = fs::absolute(plan.dataset_dirs[preset_index]).lexically_normal().string();
  summary.frames = plan.frame_ends[preset_index];
  const DatasetInfo info = ReadDatasetInfo(plan.dataset_dirs[preset_index]);
  summary.dataset_frames = info.frame_count;
  summary.path_length_m = GtPathLengthOfSpan(ReadTum(GroundTruthPath(plan.dataset_dirs[preset_index])), summary.frames);
  std::vector<RunMetrics> metrics, draws;
  std::vector<std::string> dirs, statuses, draw_dirs, draw_statuses;
  std::vector<int64_t> draw_seeds;
  SystemCost cost;
  for (size_t r = 0; r < runs.size(); ++r) {
    const SuiteRun& run = *runs[r];
    if (run.system != system) continue;
    ExternalRunRecord record;
    record.status = "ok";  // rovo's own runs end ok or stop the suite
    if (system >= 0) record = ReadExternalRunRecord(run.run_dir);
    if (system >= 0 && record.status != "not run" && record.status != "not started") {
      ++cost.runs;
      cost.wall_s += record.wall_s;
      cost.cpu_s += record.cpu_s;
      cost.peak_rss_mb = std::max(cost.peak_rss_mb, record.peak_rss_mb);
    }
    if (const std::optional<RovoRunCost> own = system < 0 ? ReadRovoRunCost(run.run_dir) : std::nullopt) {
      ++cost.runs;
      cost.wall_s += own->wall_s;
      cost.cpu_s += own->cpu_s;
      cost.peak_rss_mb = std::max(cost.peak_rss_mb, own->memory_mb);
      cost.process_maxrss = true;
    }
    const std::string label = summary.preset + "/" + (system >= 0 ? summary.system + "/" : "") + run.name;
    RunMetrics m = scored[r] ? *scored[r] : UnscoredRun(label, run.settings, summary.frames, record);
    if (run.settings.draw_seed >= 0) m.noise_set = -1;
    if (m.noise_set < 0 && run.settings.mode != ExtrinsicsMode::kGroundTruth && run.settings.draw_seed < 0) {
      m.noise_set = run.settings.noise_set;
    }
    if (system >= 0) m.mode = UnscoredRun("", run.settings, 0, record).mode;
    m.label = label;
    const bool draw = run.settings.draw_seed >= 0;
    (draw ? draws : metrics).push_back(m);
    (draw ? draw_dirs : dirs).push_back(fs::absolute(run.run_dir).lexically_normal().string());
    (draw ? draw_statuses : statuses).push_back(record.status + (record.Ok() ? "" : " (" + record.detail + ")"));
    if (draw) draw_seeds.push_back(run.settings.draw_seed);
  }
  summary.modes = SummariseModes(metrics);
  for (ModeSummary& mode : summary.modes) {
    for (size_t i = 0; i < metrics.size(); ++i) {
      if (metrics[i].mode != mode.mode) continue;
      mode.run_dirs.push_back(dirs[i]);
      mode.statuses.push_back(statuses[i]);
    }
  }
  if (!draws.empty()) {
    summary.modes.push_back(SummariseRuns("draws", draws));
    summary.modes.back().draw_seeds = draw_seeds;
    summary.modes.back().run_dirs = draw_dirs;
    summary.modes.back().statuses = draw_statuses;
  }
  if (cost.runs > 0) {
    cost.wall_s /= cost.runs;
    cost.cpu_s /= cost.runs;
    summary.cost = cost;
  }
  return summary;
}

// Evaluates the runs of one preset, every system's (writes reports/<preset>/: one report, so the
// plots show every system's trajectories), and aggregates them per system.
std::vector<PresetSummary> MergePreset(const SuitePlan& plan, size_t preset_index) {
  const SuiteOptions& options = plan.options;
  const std::string& preset = options.presets[preset_index];
  std::vector<const SuiteRun*> runs;
  for (const SuiteRun& run : plan.runs) {
    if (run.preset_index == preset_index) runs.push_back(&run);
  }
  EvalReportOptions report;
  report.plots = options.plots;
  report.quiet = options.quiet;
  report.frame_end = plan.frame_ends[preset_index];
  std::vector<std::string> run_dirs;
  std::vector<size_t> scored_index;  // run index of each evaluated folder
  for (size_t r = 0; r < runs.size(); ++r) {
    const SuiteRun& run = *runs[r];
    if (run.system >= 0 && !ReadExternalRunRecord(run.run_dir).Ok()) continue;
    run_dirs.push_back(run.run_dir);
    scored_index.push_back(r);
    const SystemDescription* system = run.system >= 0 ? &plan.systems[static_cast<size_t>(run.system)] : nullptr;
    report.labels.push_back(system ? system->name + "_" + run.name : run.name);
    report.sim3.push_back(system && system->align == "sim3");
  }
  const std::string report_dir = (fs::path(options.out_dir) / "reports" / preset).string();
  const std::vector<RunEvaluation> evaluations =
      EvaluateAndReport(plan.dataset_dirs[preset_index], run_dirs, report_dir, report);
  std::vector<std::optional<RunMetrics>> scored(runs.size());
  for (size_t i = 0; i < evaluations.size(); ++i) scored[scored_index[i]] = evaluations[i].metrics;
  std::vector<PresetSummary> out;
  for (int s = -1; s < static_cast<int>(plan.systems.size()); ++s) {
    out.push_back(SummariseSystem(plan, preset_index, s, runs, scored));
  }
  return out;
}

// table.md, suite.json and report.html of the merged presets.
void WriteSuiteOutputs(const SuitePlan& plan, const std::vector<PresetSummary>& summaries) {
  const SuiteOptions& options = plan.options;
  std::string table = SuiteTableMarkdown(summaries, options.quick);
  const std::string draw_table = DrawTableMarkdown(summaries, options.draw_sigma_deg);
  if (!draw_table.empty()) table += "\n" + draw_table;
  const std::string cost_table = SystemCostMarkdown(summaries);
  if (!cost_table.empty()) table += "\n" + cost_table;
  WriteFileAtomic((fs::path(options.out_dir) / "table.md").string(), "# rovo suite (Table I layout)\n\n" + table);
  WriteJsonFileAtomic((fs::path(options.out_dir) / "suite.json").string(), SuiteToJson(summaries, options));
  if (!options.plots) return;
  std::vector<RunMetrics> all_runs;
  std::vector<std::string> all_pngs;
  for (const PresetSummary& p : summaries) {
    for (const ModeSummary& m : p.modes) all_runs.insert(all_runs.end(), m.runs.begin(), m.runs.end());
    if (p.system != kBuiltInSystem) continue;  // one report per preset, with every system's runs
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
  for (size_t i = 0; i < plan.options.presets.size(); ++i) {
    for (PresetSummary& s : MergePreset(plan, i)) summaries.push_back(std::move(s));
  }
  WriteSuiteOutputs(plan, summaries);
  return summaries;
}

}  // namespace rovo
