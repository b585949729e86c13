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
  std::string align = "se3";
  std::string association = "auto";
  double rpe_delta_s = 1.0;
};

void AddEvalCommand(CLI::App& root) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = root.add_subcommand(
      "eval",
      "Score VO runs against a dataset's ground truth: translation RMSE after SE(3) (or --align sim3) Umeyama "
      "alignment (primary) and with origin alignment, KITTI-style drift, relative pose error over 1 s, the same "
      "after removing the system's fixed body offset (hand-eye calibration AX = XB: rovo reports its rig with "
      "camera 0 as the gauge, a VIO its IMU, COLMAP a camera), inlier ratio, angular reprojection error, "
      "extrinsic error of each camera relative to camera 0, time per frame. Estimates at any rate (e.g. VIO at "
      "200 Hz) are scored against the ground truth interpolated at their times. Writes metrics.json, "
      "summary.csv, table.md, per-run CSVs, plots and report.html to --out.");
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
  cmd->add_option("--align", args->align,
                  "se3: rigid alignment (metric systems); sim3: also the scale (Umeyama), for monocular systems, "
                  "whose unit of length is their own: the estimate's positions are scaled by it before every metric")
      ->capture_default_str()
      ->check(CLI::IsMember({"se3", "sim3"}));
  cmd->add_option("--association", args->association,
                  "nearest: each ground-truth frame pairs with the nearest estimate within --time-tolerance; "
                  "interpolate: the ground truth is interpolated at every estimate's time (inside its time range), "
                  "for estimates at any rate; auto: nearest unless more than 10 % of the estimates are not within "
                  "the tolerance of a frame")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "nearest", "interpolate"}));
  cmd->add_option("--rpe-delta", args->rpe_delta_s, "Interval of the relative pose error [s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->callback([args] {
    EvalReportOptions options;
    options.kitti = args->kitti;
    options.plots = !args->no_plots;
    options.eval.time_tolerance_s = args->tolerance_s;
    options.eval.align = args->align;
    options.eval.association = args->association;
    options.eval.rpe_delta_s = args->rpe_delta_s;
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
