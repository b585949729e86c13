// `rovo` subcommands of eval/: eval, suite, demo, gate.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "datasets/cli_groups.h"
#include "datasets/io.h"
#include "eval/gate.h"
#include "eval/report.h"
#include "eval/suite.h"
#include "eval/suite_cli.h"
#include "scenes/city.h"

namespace rovo {

namespace {

struct EvalArgs {
  std::string dataset;
  std::vector<std::string> runs;
  std::string out;
  bool kitti = false;
  bool no_plots = false;
  double tolerance_s = 0.0;
  std::string format = "auto";
};

void AddEvalCommand(CLI::App& root) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = root.add_subcommand(
      "eval",
      "Score VO runs against a dataset's ground truth: translation RMSE after SE(3) Umeyama alignment (primary) "
      "and with origin alignment, KITTI-style drift, inlier ratio, angular reprojection error, extrinsic error of "
      "each camera relative to camera 0, time per frame. Writes metrics.json, summary.csv, table.md, per-run "
      "CSVs, plots and report.html to --out.");
  cmd->add_option("dataset", args->dataset, "Dataset folder (dataset.json, groundtruth.tum)")->required();
  cmd->add_option("runs", args->runs,
                  "One or more run folders (trajectory.tum, frames.csv, extrinsics.csv, run.json), or other systems' "
                  "trajectory files / folders holding one (TUM in s or ns, EuRoC csv, KITTI poses; see --format)")
      ->required();
  cmd->add_option("--format", args->format,
                  "Trajectory format of runs without run.json: auto | tum | euroc | kitti (KITTI poses are matched to "
                  "ground-truth frames by line)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "tum", "euroc", "kitti"}));
  cmd->add_option("--out", args->out, "Report folder to write")->required();
  cmd->add_flag("--kitti", args->kitti, "Also write aligned estimate and ground truth in KITTI format per run");
  cmd->add_flag("--no-plots", args->no_plots, "Skip the matplotlib plots (report.html without figures)");
  cmd->add_option("--time-tolerance", args->tolerance_s,
                  "Timestamp association tolerance in seconds (0 = a quarter of the ground-truth frame interval)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([args] {
    EvalReportOptions options;
    options.kitti = args->kitti;
    options.plots = !args->no_plots;
    options.eval.time_tolerance_s = args->tolerance_s;
    options.trajectory_format = args->format;
    const std::vector<RunEvaluation> evaluations = EvaluateAndReport(args->dataset, args->runs, args->out, options);
    std::vector<RunMetrics> metrics;
    for (const RunEvaluation& e : evaluations) metrics.push_back(e.metrics);
    std::printf("%s\n%s\nReport: %s\n", RunTableMarkdown(metrics).c_str(), MetricsLegendMarkdown().c_str(),
                args->out.c_str());
  });
}

std::vector<std::string> SplitCommaList(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace

SuiteOptions SuiteCliArgs::Options() const {
  SuiteOptions o = options;
  o.presets = SplitCommaList(presets);
  if (robustness) o.presets = RobustnessEntries(o.presets);
  o.plots = !no_plots;
  return o;
}

void AddSuiteOptions(CLI::App* cmd, SuiteCliArgs* args) {
  SuiteOptions* options = &args->options;
  std::string preset_names;
  for (const ScenePreset& p : ScenePresets()) preset_names += (preset_names.empty() ? "" : ",") + p.name;
  std::string variants;
  for (const std::string& v : SuiteVariantNames()) variants += (variants.empty() ? "" : ",") + v;
  cmd->add_option("--presets", args->presets,
                  "Comma-separated presets (default: all: " + preset_names +
                      "); PRESET+VARIANT renders the preset with "
                      "sensor or timing effects (" +
                      variants + "; eval/suite.h)");
  cmd->add_flag("--robustness", args->robustness,
                "Robustness table: each preset (default cloudy_urban) plain and with every variant, then the harder "
                "worlds (indoor_hall, suburban_road, night_street) plain and +realistic");
  cmd->add_flag("--quick", options->quick, "Use the presets' quick forms (fewer frames, smaller images)");
  cmd->add_option("--frames", options->frames,
                  "Only the first N frames of each preset: rendered, run and scored on that span (0: all; e.g. a "
                  "full-size check of the 3000-frame static_urban in minutes)")
      ->default_val(0)
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--seeds", options->noise_sets, "Number K of extrinsic noise sets (noise_set 0..K-1)")
      ->default_val(1)
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--draws", options->draws,
                  "D more OnlineExt runs per preset from fresh perturbation draws (seeds derived from --scene-seed, "
                  "--vo-seed and the draw index, recorded in suite.json); reported as mean +- std and the rate of "
                  "draws whose final extrinsic error is below 0.1 deg")
      ->default_val(0)
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--draw-sigma", options->draw_sigma_deg, "Sigma of the --draws perturbations in degrees")
      ->default_val(5.0)
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--vo-threads", options->vo_threads,
                  "Threads of each VO run (0: cores/jobs, or the task's CPUs in a batch); 1 makes OnlineExt runs "
                  "reproducible, and a batch equal to a local suite byte for byte")
      ->default_val(0)
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--data", options->data_dir, "Dataset cache folder (default: OUT/data)");
  cmd->add_option("--scene-seed", options->scene_seed, "Scene and render seed")->default_val(0);
  cmd->add_option("--vo-seed", options->vo_seed, "RANSAC seed of every run")->default_val(0);
  cmd->add_option("--max-new-features", options->max_new_features,
                  "New detections per view and frame at most, while the view has tracks, in every run (rovo vo "
                  "--max-new-features; 0: no limit; default: rovo vo's). Runs made with another value are redone")
      ->check(CLI::Range(0, 100000));
  cmd->add_flag("--no-plots", args->no_plots, "Skip plots and report.html");
  cmd->add_option("--out", options->out_dir, "Suite output folder")->required();
}

namespace {

void PrintSuite(const std::vector<PresetSummary>& summaries, const SuiteOptions& options) {
  std::printf("%s\n", SuiteTableMarkdown(summaries, options.quick).c_str());
  const std::string draws = DrawTableMarkdown(summaries, options.draw_sigma_deg);
  if (!draws.empty()) std::printf("%s\n", draws.c_str());
  std::printf("Suite: %s (suite.json, table.md%s)\n", options.out_dir.c_str(), options.plots ? ", report.html" : "");
}

void AddSuiteCommand(CLI::App& root) {
  auto args = std::make_shared<SuiteCliArgs>();
  CLI::App* cmd = root.add_subcommand(
      "suite",
      "The paper's Table I suites: renders missing datasets, runs VO with ground-truth extrinsics (GTExt) once and "
      "with each of K perturbed extrinsic sets fixed (NoisyExt) and calibrated online (OnlineExt), evaluates, and "
      "writes suite.json, table.md (mean +- std over noise sets, the paper's figures beside ours) and report.html. "
      "Resumes: complete runs made with the same settings (frames, seed, noise set, --max-new-features) and complete "
      "datasets are not redone. `rovo batch plan` takes the same options and runs the suite as Slurm jobs.");
  AddSuiteOptions(cmd, args.get());
  cmd->add_option("--jobs", args->options.jobs, "VO runs in parallel; each gets cores/jobs threads")
      ->default_val(1)
      ->check(CLI::Range(1, 256));
  cmd->add_option("--threads", args->options.threads, "Cores to use (0 = all)")->default_val(0);
  cmd->callback([args] {
    const SuiteOptions options = args->Options();
    PrintSuite(RunSuite(options), options);
  });
}

void AddDemoCommand(CLI::App& root) {
  auto out = std::make_shared<std::string>("rovo-demo");
  auto no_plots = std::make_shared<bool>(false);
  CLI::App* cmd = root.add_subcommand(
      "demo",
      "End-to-end demo: renders the small default dataset (cloudy_urban, quick), runs GTExt, NoisyExt and OnlineExt "
      "(one noise set), prints the Table I row and writes the report (a few minutes on 2 cores).");
  cmd->add_option("--out", *out, "Output folder")->default_val("rovo-demo");
  cmd->add_flag("--no-plots", *no_plots, "Skip plots and report.html");
  cmd->callback([out, no_plots] {
    SuiteOptions options;
    options.presets = {"cloudy_urban"};
    options.quick = true;
    options.noise_sets = 1;
    options.out_dir = *out;
    options.plots = !*no_plots;
    PrintSuite(RunSuite(options), options);
    if (options.plots) {
      std::printf("Open %s\n", (std::filesystem::absolute(*out) / "report.html").lexically_normal().c_str());
    }
  });
}

struct GateArgs {
  std::string gates = "ci/gates.json";
  std::string suite;
  bool run = false;
  std::string data;
  int jobs = 1;
};

void AddGateCommand(CLI::App& root) {
  auto args = std::make_shared<GateArgs>();
  CLI::App* cmd = root.add_subcommand(
      "gate",
      "CI accuracy gate: checks a suite's suite.json against the thresholds of a gates file; prints the table and "
      "exits with status 1 when any metric crosses its threshold. With --run, first runs (or resumes) the suite the "
      "gates file describes into --suite.");
  cmd->add_option("--gates", args->gates, "Gates file (JSON)")->default_val("ci/gates.json");
  cmd->add_option("--suite", args->suite, "Suite folder (holds suite.json)")->required();
  cmd->add_flag("--run", args->run, "Run the suite described in the gates file first (resumes)");
  cmd->add_option("--data", args->data, "With --run: dataset cache folder (default: SUITE/data)");
  cmd->add_option("--jobs", args->jobs, "With --run: VO runs in parallel")->default_val(1)->check(CLI::Range(1, 256));
  cmd->callback([args] {
    const nlohmann::json gates = ReadJsonFile(args->gates);
    if (args->run) {
      SuiteOptions options = GateSuiteOptions(gates, args->gates);
      options.out_dir = args->suite;
      options.data_dir = args->data;
      options.jobs = args->jobs;
      options.plots = false;
      RunSuite(options);
    }
    const std::string suite_path = (std::filesystem::path(args->suite) / "suite.json").string();
    const std::vector<GateCheck> checks = CheckGates(gates, args->gates, ReadJsonFile(suite_path));
    std::printf("%s\n", GateTableMarkdown(checks).c_str());
    if (!AllGatesPass(checks)) {
      std::fprintf(stderr, "rovo gate: FAILED: a metric crossed its threshold (%s vs %s)\n", suite_path.c_str(),
                   args->gates.c_str());
      throw CLI::RuntimeError(1);
    }
    std::printf("rovo gate: all %zu gates pass\n", checks.size());
  });
}

}  // namespace

void AddEvalCommands(CliGroups& groups) {
  AddEvalCommand(*groups.root);
  AddSuiteCommand(*groups.root);
  AddBatchCommand(*groups.root);
  AddDemoCommand(*groups.root);
  AddGateCommand(*groups.root);
}

}  // namespace rovo
