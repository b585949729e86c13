#pragma once
// `rovo eval`: scores runs against a dataset's ground truth and writes a report folder:
//   <out>/metrics.json            dataset, seeds, metric definitions, one object per run
//   <out>/summary.csv             one row per run (same numbers as the table)
//   <out>/table.md                Markdown table (states which metrics)
//   <out>/groundtruth.csv         full gt path: timestamp,x,y,z (world)
//   <out>/<label>/errors.csv      per associated frame: gt and aligned estimated position, error
//   <out>/<label>/frames.csv      the run's per-frame records (inlier ratio, reprojection error)
//   <out>/<label>/extrinsic_errors.csv  per frame and camera i >= 1: errors and roll/pitch/yaw of
//                                       camera i relative to camera 0 in rig axes (metrics.h),
//                                       estimated and ground truth
//   with --kitti: <out>/<label>/kitti_estimate.txt (aligned) and kitti_groundtruth.txt, line by line
//   associated.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/metrics.h"

namespace rovo {

struct EvalReportOptions {
  bool kitti = false;
  bool plots = true;  // run eval/plots/plot_report.py and write report.html
  bool quiet = false;
  EvalOptions eval;
  std::string trajectory_format = "auto";  // of runs from other systems (eval/foreign_run.h)
  // Per run (in run_dirs order; shorter or empty: the defaults): its label instead of the folder's
  // name, and whether it is scored after Sim(3) scaling (EvalOptions::align sim3).
  std::vector<std::string> labels;
  std::vector<bool> sim3;
  int frame_end = 0;  // > 0: runs that do not say which frames they cover cover [0, frame_end)
};

nlohmann::json MetricsToJson(const RunMetrics& metrics);
// Inverse of MetricsToJson; throws std::runtime_error naming `what` and the field.
RunMetrics MetricsFromJson(const nlohmann::json& json, const std::string& what);

// Definitions of the reported metrics, printed under every table.
std::string MetricsLegendMarkdown();
// One row per run.
std::string RunTableMarkdown(const std::vector<RunMetrics>& runs);

// Reads the dataset and runs, scores each run, writes the report folder. Run labels are the run
// folders' names (made unique with a suffix). Returns the evaluations in input order.
std::vector<RunEvaluation> EvaluateAndReport(const std::string& dataset_dir, const std::vector<std::string>& run_dirs,
                                             const std::string& out_dir, const EvalReportOptions& options);

}  // namespace rovo
