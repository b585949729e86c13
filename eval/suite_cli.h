#pragma once
// The options `rovo suite` and `rovo batch plan` share, and the `rovo batch` command tree.

#include <string>

#include "eval/suite.h"

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

// `rovo batch plan | submit | status | resume | task` (eval/batch_cli.cc).
void AddBatchCommand(CLI::App& root);

}  // namespace rovo
