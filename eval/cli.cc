// `rovo` subcommands of eval/: eval, suite, demo, gate.
#include "datasets/cli_groups.h"
#include "eval/report.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

namespace rovo {

namespace {

struct EvalArgs {
  std::string dataset;
  std::vector<std::string> runs;
  std::string out;
  bool kitti = false;
  bool no_plots = false;
  double tolerance_s = 0.0;
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
  cmd->add_option("runs", args->runs, "One or more run folders (trajectory.tum, frames.csv, extrinsics.csv, run.json)")
      ->required();
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
    const std::vector<RunEvaluation> evaluations = EvaluateAndReport(args->dataset, args->runs, args->out, options);
    std::vector<RunMetrics> metrics;
    for (const RunEvaluation& e : evaluations) metrics.push_back(e.metrics);
    std::printf("%s\n%s\nReport: %s\n", RunTableMarkdown(metrics).c_str(), MetricsLegendMarkdown().c_str(),
                args->out.c_str());
  });
}

}  // namespace

void AddEvalCommands(CliGroups& groups) { AddEvalCommand(*groups.root); }

}  // namespace rovo
