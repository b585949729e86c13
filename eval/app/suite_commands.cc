// `rovo suite`: the paper's Table I suites (eval/orchestration/suite.h); the suite options `rovo batch plan`
// shares (suite_args.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "eval/app/commands.h"
#include "eval/app/suite_args.h"
#include "scenes/city.h"

namespace rovo {
namespace {

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
  cmd->add_option("--system", options->systems,
                  "Description file of another odometry system to run through the same plan beside rovo's pipeline "
                  "(repeatable; docs/systems.md): GTExt with the true calibration, NoisyExt with each noise set or "
                  "draw written into the calibration it reads, OnlineExt when it calibrates online. A system with "
                  "needs_imu makes the suite render its datasets with an IMU (as rovo render --imu, in "
                  "<preset>..._imu folders). Every run records its wall and CPU time (system_run.json); the table's "
                  "\"Cost per system\" gives their means per system")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--no-plots", args->no_plots, "Skip plots and report.html");
  cmd->add_option("--out", options->out_dir, "Suite output folder")->required();
}

void PrintSuite(const std::vector<PresetSummary>& summaries, const SuiteOptions& options) {
  std::printf("%s\n", SuiteTableMarkdown(summaries, options.quick).c_str());
  const std::string draws = DrawTableMarkdown(summaries, options.draw_sigma_deg);
  if (!draws.empty()) std::printf("%s\n", draws.c_str());
  const std::string cost = SystemCostMarkdown(summaries);
  if (!cost.empty()) std::printf("%s\n", cost.c_str());
  std::printf("Suite: %s (suite.json, table.md%s)\n", options.out_dir.c_str(), options.plots ? ", report.html" : "");
}

namespace {

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

}  // namespace

void AddSuiteCommands(CommandTree& tree) { AddSuiteCommand(*tree.root); }

}  // namespace rovo
