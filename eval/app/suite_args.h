#pragma once
// The options `rovo suite` and `rovo batch plan` share (defined in suite_commands.cc).

#include <string>
#include <vector>

#include "eval/orchestration/suite.h"

namespace CLI {
class App;
}

namespace rovo {

struct SuiteCliArgs {
  SuiteOptions options;
  std::string presets;  // comma-separated
  bool no_plots = false;
  bool robustness = false;       // --robustness: RobustnessEntries(presets)
  SuiteOptions Options() const;  // with presets and plots filled in
};

// --presets, --quick, --frames, --seeds, --draws, --draw-sigma, --vo-threads, --data, --scene-seed,
// --vo-seed, --max-new-features, --no-plots, --out.
void AddSuiteOptions(CLI::App* cmd, SuiteCliArgs* args);

// The suite's tables and where its outputs went (`rovo suite`, `rovo demo`).
void PrintSuite(const std::vector<PresetSummary>& summaries, const SuiteOptions& options);

}  // namespace rovo
