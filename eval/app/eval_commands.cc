// `rovo eval`: score runs against a dataset's ground truth and write the report (eval/report.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "eval/app/commands.h"
#include "eval/report.h"

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
    metrics.reserve(evaluations.size());
    for (const RunEvaluation& e : evaluations) metrics.push_back(e.metrics);
    std::printf("%s\n%s\nReport: %s\n", RunTableMarkdown(metrics).c_str(), MetricsLegendMarkdown().c_str(),
                args->out.c_str());
  });
}

}  // namespace

void AddEvalCommands(CommandTree& tree) { AddEvalCommand(*tree.root); }

}  // namespace rovo
