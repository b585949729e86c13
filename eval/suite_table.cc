// The suite's Markdown tables (suite_table.h).
#include "eval/suite_table.h"

#include <algorithm>
#include <cstdio>

#include "eval/format.h"

namespace rovo {

namespace {

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

}  // namespace

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

std::string RunStatusCounts(const PresetSummary& p) {
  std::vector<std::pair<std::string, int>> counts;
  for (const ModeSummary& m : p.modes) {
    for (const std::string& status : m.statuses) {
      const std::string word = status.substr(0, status.find(" ("));
      auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == word; });
      if (it == counts.end()) {
        counts.emplace_back(word, 1);
      } else {
        ++it->second;
      }
    }
  }
  std::string out;
  for (const auto& [word, n] : counts) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + word;
  return out.empty() ? "-" : out;
}

// The header of Table I (with the system and runs columns when other systems are in it).
static std::string SuiteTableHeader(bool systems) {
  return std::string("| sequence | ") + (systems ? "system | runs | " : "") +
         "frames | length [m] | RMSE NoisyExt [m] | RMSE OnlineExt [m] | RMSE GTExt [m] | rel. "
         "Noisy/Online/GT "
         "[%] | paper rel. Noisy/Online/GT [%] | inliers Online/GT [%] | paper | reproj Online/GT [deg] | "
         "paper | ext rot Online [deg] | drift Online / GT [%] raw → body-aligned |\n|---|" +
         (systems ? "---|---|" : "") + "---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

std::string SuiteTableMarkdown(const std::vector<PresetSummary>& presets, bool quick) {
  const bool systems =
      std::any_of(presets.begin(), presets.end(), [](const PresetSummary& p) { return p.system != "rovo"; });
  std::string md = SuiteTableHeader(systems);
  for (const PresetSummary& p : presets) {
    const bool own = p.system == "rovo";  // external systems report no inliers, reprojection or extrinsics
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
    const std::string system_cells =
        systems ? p.system + (p.align == "sim3" ? " (Sim(3))" : "") + " | " + RunStatusCounts(p) + " | " : "";
    const std::string inliers = own ? mean("online", "mean_inlier_ratio", "%.1f", 100.0) + " / " +
                                          mean("gt", "mean_inlier_ratio", "%.1f", 100.0)
                                    : "-";
    const std::string reproj =
        own ? mean("online", "mean_reproj_error_deg", "%.3f") + " / " + mean("gt", "mean_reproj_error_deg", "%.3f")
            : "-";
    const std::string ext_rot = own ? mean_std("online", "max_final_ext_rotation_deg", "%.3f") : "-";
    md += "| " + name + " | " + system_cells + frames + " | " + Fmt("%.1f", p.path_length_m) + " | " +
          mean_std("noisy", "rmse_se3_m", "%.3f") + " | " + mean_std("online", "rmse_se3_m", "%.3f") + " | " +
          mean_std("gt", "rmse_se3_m", "%.3f") + " | " + mean("noisy", "relative_rmse_pct", "%.2f") + " / " +
          mean("online", "relative_rmse_pct", "%.3f") + " / " + mean("gt", "relative_rmse_pct", "%.3f") + " | " +
          paper_rel + " | " + inliers + " | " + paper_inl + " | " + reproj + " | " + paper_rep + " | " + ext_rot +
          " | " + mean("online", "drift_translation_pct", "%.2f") + " → " +
          mean("online", "body_aligned_drift_translation_pct", "%.2f") + " / " +
          mean("gt", "drift_translation_pct", "%.2f") + " → " +
          mean("gt", "body_aligned_drift_translation_pct", "%.2f") + " |\n";
  }
  if (systems) {
    md +=
        "\nsystem: rovo = this pipeline; others run from their description (docs/systems.md), scored on the "
        "trajectory they wrote; Sim(3): the estimate is scaled by the Sim(3) alignment's scale first (monocular "
        "systems). runs: how the system's runs ended (ok, crashed, timeout, failed = non-zero exit, no "
        "trajectory, unparsable trajectory); a run that did not end ok has no RMSE, so the mean is over fewer "
        "runs (\"k of K runs\"). Other systems report no inlier ratio, reprojection error or extrinsics (-). "
        "NoisyExt gives a system the perturbed extrinsics in its own calibration file; OnlineExt runs only "
        "for systems that calibrate online.\n";
  }
  md +=
      "\nRMSE = translation RMSE after SE(3) Umeyama alignment (mean ± std over the noise sets; GTExt runs once; "
      "\"k of K runs\": only k runs have the value, e.g. a run lost on every frame has no trajectory to align); "
      "rel. = RMSE / ground-truth path length; the paper's relative errors use its Table I RMSEs and sequence "
      "lengths (4view-MultiFOV 440 m, Static 2000 m, Dynamic 1320 m, Cloudy 350 m, Sunset 350 m); our scenes "
      "differ from the paper's, so compare relative errors. inliers = mean inlier ratio of the multi-view P3P "
      "RANSAC; reproj = mean angular reprojection error of inliers; ext rot = largest error over cameras of "
      "cam_i_from_cam0 at the last frame; drift = KITTI-style relative translation error over 10..80 % of the path, "
      "raw (the reported rig against the ground truth's: with a perturbed calibration the reported rig is turned "
      "by camera 0's error, which the raw figure counts) → body-aligned (after removing the fixed body offset "
      "that hand-eye calibration finds, eval/body_offset.h).\n";
  return md;
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
    md += "| `" + p.preset + "`" + (p.system != "rovo" ? " " + p.system : std::string()) + " | " + std::to_string(n) +
          " | " + FmtStat(draws->Find("rmse_se3_m"), n, "%.3f") + " | " +
          FmtStat(draws->Find("max_final_ext_rotation_deg"), n, "%.3f") + " | " +
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

}  // namespace rovo

namespace rovo {

std::string SystemCostMarkdown(const std::vector<PresetSummary>& presets) {
  std::string md;
  bool process_maxrss = false;
  for (const PresetSummary& p : presets) {
    if (!p.cost) continue;
    process_maxrss = process_maxrss || p.cost->process_maxrss;
    md += "| `" + p.preset + "` | " + p.system + " | " + std::to_string(p.cost->runs) + " | " +
          Fmt("%.1f", p.cost->wall_s) + " | " + Fmt("%.1f", p.cost->cpu_s) + " | " + Fmt("%.0f", p.cost->peak_rss_mb) +
          (p.cost->process_maxrss ? " (process maxrss)" : "") + " |\n";
  }
  if (md.empty()) return "";
  return "## Cost per system\n\n| sequence | system | runs | wall per run [s] | CPU per run [s] | "
         "peak memory [MB] |\n|---|---|---|---|---|---|\n" +
         md +
         "\nmean over the system's runs (system_run.json of each run). Another system: wall and CPU (user + system) "
         "time of its process and the children it waited for (wait4); peak memory = the largest resident set of its "
         "process group over the runs." +
         (process_maxrss
              ? " rovo: its pipeline runs inside the suite's process, so CPU = the getrusage(RUSAGE_SELF) delta over "
                "the run (exact with --jobs 1; system_run.json \"cpu_overlapped\" marks a run that shared the "
                "process with another), and memory = the rovo process's maxrss (its peak since it started, rendering "
                "included), not the run's own."
              : "") +
         "\n";
}

}  // namespace rovo
