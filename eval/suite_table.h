#pragma once
// The suite's Markdown tables: Table I beside the paper's figures, and the perturbation draws.

#include <optional>
#include <string>
#include <vector>

#include "eval/suite_summary.h"

namespace rovo {

// The paper's Table I row for a preset, if it has one (path length in metres, RMSEs in metres,
// inlier ratios in %, reprojection errors in degrees).
struct PaperRow {
  std::string sequence;
  double length_m, rmse_noisy, rmse_online, rmse_gt, inlier_online, inlier_gt, reproj_online, reproj_gt;
};
std::optional<PaperRow> PaperRowForPreset(const std::string& preset);

// Table I layout (one row per preset and system; with other systems than rovo, a system column and
// how its runs ended): per preset, RMSE SE(3) of NoisyExt / OnlineExt / GTExt (mean +- std over noise
// sets) with our relative error and the paper's (RMSE / path length), inlier ratio and
// reprojection error Online/GT beside the paper's, final extrinsic error of OnlineExt.
std::string SuiteTableMarkdown(const std::vector<PresetSummary>& presets, bool quick);

// Per preset and system (rovo's own included): wall and CPU time per run, peak memory; "" when there is none.
std::string SystemCostMarkdown(const std::vector<PresetSummary>& presets);

// Per preset with draws: RMSE, final extrinsic error (mean +- std) and the convergence rate; "" when
// no preset has draws.
std::string DrawTableMarkdown(const std::vector<PresetSummary>& presets, double draw_sigma_deg);

}  // namespace rovo
