#pragma once
// External systems in a suite (docs/systems.md): their runs in the plan, the exports and per-run
// calibrations they read, running them, and what their run folders say afterwards.
//
// Layout (beside rovo's runs):
//   <out>/runs/<preset>/systems/<name>/<run>/   system_run.json, stdout.log, stderr.log,
//                                               out/ ({out}), the calibration given ({calibration}),
//                                               input/ (input: euroc, the per-run EuRoC view; input: ros2,
//                                               the run's own bag, its /tf_static the given extrinsics),
//                                               trajectory.tum (the trajectory read back, TUM seconds)
//   <dataset>.exports/<input>[_<lens>][_frames_<N>]/  the export the system reads (shared by its runs
//                                               and by systems of the same input and lens; --frames N:
//                                               of the first N frames, from the view frames_<N>/)

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/orchestration/suite.h"
#include "eval/orchestration/system_description.h"

namespace rovo {

// The runs of every external system of the plan for one preset: gt, noisy_<k>, online_<k> (systems
// that calibrate online), draw_<d> (online when the system calibrates online, else noisy).
void PlanSystemRuns(const SuitePlan& plan, size_t preset_index, const std::string& runs_dir, int frame_end,
                    std::vector<SuiteRun>* runs);

// What can be checked before rendering: names are unique, programs exist.
void CheckSuiteSystems(const SuitePlan& plan);

// Runs one external run unless a finished one with the same command and calibration exists; returns
// whether it ran. A failure of the system is recorded in its folder, never thrown.
bool RunSystemRun(const SuitePlan& plan, const SuiteRun& run, int threads, bool quiet);

// gt | noisy | online: a run's mode in system_run.json.
const char* SuiteModeName(ExtrinsicsMode mode);

// The fields every system_run.json starts with (rovo's runs and external ones): generator, system, run,
// mode, noise set, draw seed, seed and threads.
nlohmann::json SystemRunRecordHead(const SuitePlan& plan, const SuiteRun& run, const std::string& system, int threads);

// What a finished external run's system_run.json says.
struct ExternalRunRecord {
  std::string status = "not run";  // ok | crashed | timeout | failed | no trajectory | unparsable trajectory |
                                   // not started | not run
  std::string detail;              // e.g. "signal 11 (Segmentation fault)", the parse error
  double wall_s = 0.0, cpu_s = 0.0, peak_rss_mb = 0.0;
  bool Ok() const { return status == "ok"; }
};
ExternalRunRecord ReadExternalRunRecord(const std::string& run_dir);

// The file name of a run's system record: an external run's, and (in-process, suite.h RunSuiteRun) one
// of rovo's own runs, with its wall and CPU time and the process's maxrss.
inline constexpr const char* kSystemRunFile = "system_run.json";

// The cost a rovo run's system_run.json records; nullopt when it has none (a run made before runs
// recorded it). memory_mb is the rovo process's maxrss (process_maxrss_mb), not the run's own.
struct RovoRunCost {
  double wall_s = 0.0, cpu_s = 0.0, memory_mb = 0.0;
};
std::optional<RovoRunCost> ReadRovoRunCost(const std::string& run_dir);

}  // namespace rovo
