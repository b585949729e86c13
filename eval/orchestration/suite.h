#pragma once
// The paper's comparison suites (Table I): for each preset, render the dataset if missing, run VO
// with ground-truth extrinsics (GTExt) once and with each of K perturbed extrinsic sets held fixed
// (NoisyExt) and calibrated online (OnlineExt), evaluate, aggregate mean +- std over the noise sets;
// optionally D more OnlineExt runs per preset from fresh perturbation draws (--draws), reported as
// mean +- std and a convergence rate.
//
// The suite is a plan of tasks (PlanSuite): per preset one dataset to render (in shards), then VO runs,
// then one merge. `rovo suite` runs them in one process (RunSuite); `rovo batch` (eval/orchestration/batch.h) runs the
// same tasks as Slurm jobs. Both call RenderSuiteDataset, RunSuiteRun and MergeSuite, so their outputs
// agree byte for byte apart from timing fields.
//
// Layout of --out:
//   <out>/runs/<preset>/{gt, noisy_<k>, online_<k>, draw_<d>}/   run folders (datasets/run.h)
//   <out>/reports/<preset>/                            `rovo eval` report of all runs of the preset
//   <out>/suite.json                                   aggregated metrics per preset and mode
//   <out>/table.md, <out>/report.html                  Table I layout with the paper's figures
// Datasets go to <data>/<preset>[_quick]_s<seed>[_imu]/ (default <data> = <out>/data); _imu: rendered with
// an IMU (`rovo render --imu`, default IMU settings), because a selected system needs one (needs_imu).
// Resume: a run folder whose run.json is complete and records the settings asked for (RunSettings)
// is not run again; one made with other settings is; a dataset whose frames (all, or the first --frames) exist is not
// rendered again.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/metrics.h"
#include "eval/orchestration/system_description.h"
#include "eval/suite_summary.h"
#include "eval/suite_table.h"
#include "vo/pipeline.h"

namespace rovo {

// A suite entry is a scene preset, optionally with a variant of its render: "cloudy_urban+blur". The
// dataset, the runs and the table row carry the whole entry. Variants (values in docs/results.md):
//   ideal      --sensor ideal (HDR sun, auto-exposure and gain, no noise)
//   sensor     --sensor realistic (noise, 12-bit ADC, BT.709 response, per-camera sensitivity spread)
//   gray       the realistic sensor, grayscale
//   optics     the realistic sensor behind the realistic lens (render/optics.h: blur widening towards
//              the rim, vignetting, lateral colour, veiling glare)
//   blur       motion blur over a fixed 10 ms shutter (8 samples per pixel)
//   rolling    rolling shutter, 30 ms readout
//   trigger    per-camera trigger offsets, standard deviation 1 ms
//   realistic  the realistic profile, `rovo render --realistic`: the realistic sensor and lens, motion
//              blur over its exposure, 20 ms rolling shutter, trigger offsets of 0.5 ms standard deviation
struct SuiteEntry {
  std::string preset;   // a scene preset (scenes/city.h)
  std::string variant;  // "" or one of SuiteVariantNames()
};
// Throws std::invalid_argument naming the entry and the valid variants.
SuiteEntry ParseSuiteEntry(const std::string& entry);
const std::vector<std::string>& SuiteVariantNames();
// `rovo suite --robustness`: every preset of `presets` (default cloudy_urban) plain and with each
// variant, then the harder worlds (HarderScenePresets) plain and with the realistic profile.
std::vector<std::string> RobustnessEntries(const std::vector<std::string>& presets);

struct SuiteOptions {
  std::vector<std::string> presets;  // empty = all presets (ScenePresets order)
  bool quick = false;                // the presets' quick forms
  int frames = 0;                    // > 0: only the first N frames of each preset (rendered and run)
  int noise_sets = 1;                // K: NoisyExt/OnlineExt runs per preset (noise_set 0..K-1)
  int draws = 0;                     // D: OnlineExt runs per preset from fresh draws (SuiteDrawSeed)
  double draw_sigma_deg = 5.0;       // sigma of those draws (roll, pitch, yaw of every camera)
  int jobs = 1;                      // VO runs in parallel; each gets cores / jobs threads
  int threads = 0;                   // cores to use; 0 = all
  int vo_threads = 0;                // threads of each VO run; 0 = cores / jobs. 1 makes OnlineExt
                                     // runs reproducible (OnlineExt depends on the thread count)
  std::string data_dir;              // "" = <out>/data
  std::string out_dir;
  uint64_t scene_seed = 0;    // scene / render seed
  uint64_t vo_seed = 0;       // RANSAC seed of every run
  int max_new_features = -1;  // FrontendOptions::max_new_features_per_view of every run; < 0: its default
  int MaxNewFeatures() const {
    return max_new_features >= 0 ? max_new_features : VoOptions{}.frontend.max_new_features_per_view;
  }
  bool plots = true;
  bool quiet = false;
  // Description files of other systems (--system, docs/systems.md) run beside rovo's own pipeline.
  std::vector<std::string> systems;
};

// What a suite run must have been made with to be reused: its frames, mode, noise set or draw seed,
// RANSAC seed and front-end detection limit, as recorded in its run.json.
struct RunSettings {
  ExtrinsicsMode mode = ExtrinsicsMode::kGroundTruth;
  int noise_set = 0;
  int64_t draw_seed = -1;  // >= 0: started from PerturbExtrinsics(gt rig, draw_sigma_deg, 0, draw_seed)
  double draw_sigma_deg = 5.0;
  int frame_end = 0;  // the run covers frames [0, frame_end)
  uint64_t seed = 0;
  int max_new_features = 0;
};

// Whether the run in `run_dir` is complete (run.json, trajectory, frames and extrinsics files) and
// was made with `want`. A complete run made with other settings sets `*mismatch` to
// "field: recorded vs wanted" (e.g. "seed: 1 vs 0") and must be redone; it stays empty otherwise.
bool RunReusable(const std::string& run_dir, const RunSettings& want, std::string* mismatch);

// Seed of perturbation draw `draw` (0-based) of a suite: derived from the scene and VO seeds and the
// draw index, in [0, 2^63), and never equal to the seed of a noise set stored in dataset.json.
int64_t SuiteDrawSeed(uint64_t scene_seed, uint64_t vo_seed, int draw);
// The seed render/ uses for stored noise set k of a dataset rendered with `scene_seed`.
uint64_t StoredNoiseSetSeed(uint64_t scene_seed, int k);

// The "suite" object of a gates file (`rovo gate --run`, eval/gate.h): presets (strings), quick (bool),
// noise_sets (1..1000), scene_seed and vo_seed (non-negative integers), vo_threads (0..1024),
// max_new_features (-1..1000000), systems (description files, relative to the gates file's folder);
// omitted fields keep quick true, noise_sets 1, seeds 0, vo_threads 0,
// max_new_features -1. Throws std::runtime_error "<gates_what>: suite.<field>: ..." otherwise.
SuiteOptions GateSuiteOptions(const nlohmann::json& gates, const std::string& gates_what);

nlohmann::json SuiteToJson(const std::vector<PresetSummary>& presets, const SuiteOptions& options);

// The suite's arguments as JSON and back (the batch folder's plan.json); FromJson names `source` and
// the field on bad input.
nlohmann::json SuiteOptionsToJson(const SuiteOptions& options);
SuiteOptions SuiteOptionsFromJson(const nlohmann::json& j, const std::string& source);

// One VO run of a suite.
struct SuiteRun {
  size_t preset_index = 0;
  std::string name;  // gt | noisy_<k> | online_<k> | draw_<d>: the run folder's name
  std::string run_dir;
  int system = -1;  // -1: rovo's pipeline; else an index into SuitePlan::systems (suite_systems.h)
  RunSettings settings;
};

// Everything a suite does, decided from its options alone (no file is read).
struct SuitePlan {
  SuiteOptions options;                    // presets filled in (all when none were named)
  std::string data_dir;                    // options.data_dir or <out>/data
  std::vector<std::string> dataset_dirs;   // per preset
  std::vector<int> frame_ends;             // per preset: runs cover frames [0, end)
  std::vector<SuiteRun> runs;              // per preset: gt, noisy_k / online_k, draw_d; then each system's
  std::vector<SystemDescription> systems;  // options.systems, read
  bool imu = false;                        // a system needs the IMU: datasets are rendered with one
};
// Validates the options (throws std::invalid_argument naming the option) and reads the system
// descriptions (throws std::runtime_error naming the file and field).
SuitePlan PlanSuite(const SuiteOptions& options);

// Renders shard `shard` of `shards` of preset `preset_index`'s dataset with `threads` threads
// (render/render.h: chunks of 8 frames); a complete dataset is not touched. Resumable.
void RenderSuiteDataset(const SuitePlan& plan, size_t preset_index, int shard, int shards, int threads);
// Runs one VO run with `threads` threads unless a reusable one exists (RunReusable); returns whether it
// ran. `quiet` silences the run's progress. An external system's run goes to RunSystemRun
// (suite_systems.h): a failure of the system is recorded, not thrown.
bool RunSuiteRun(const SuitePlan& plan, const SuiteRun& run, int threads, bool quiet);
// Evaluates every run of the plan, writes reports/, suite.json, table.md and report.html.
std::vector<PresetSummary> MergeSuite(const SuitePlan& plan);

// The whole suite in this process: PlanSuite, the systems' checks (before any rendering),
// RenderSuiteDataset, RunSuiteRun (--jobs at a time), MergeSuite.
std::vector<PresetSummary> RunSuite(const SuiteOptions& options);

}  // namespace rovo
