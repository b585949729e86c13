#pragma once
// The `rovo` command tree. main() creates the root and the command groups; each file
// eval/app/<group>_commands.cc adds its commands with Add<Group>Commands(CommandTree&), called from
// main() in the order of `rovo --help`. Commands report bad input by throwing std::exception (main
// prints "rovo: error: <what>" and exits 1) or CLI::RuntimeError(code) for a specific exit code.

#include <string>

namespace CLI {
class App;
}

namespace rovo {

struct CommandTree {
  CLI::App* root = nullptr;
  CLI::App* dataset = nullptr;  // rovo dataset ...
  CLI::App* scene = nullptr;    // rovo scene ...
  CLI::App* bench = nullptr;    // rovo bench ...
  CLI::App* study = nullptr;    // rovo study ...
};

void AddDatasetCommands(CommandTree& tree);   // dataset validate | info | rig | import-omnimvs
void AddExchangeCommands(CommandTree& tree);  // dataset export | import | lens-fit
void AddSceneCommands(CommandTree& tree);     // scene generate | info | list | preview
void AddRenderCommands(CommandTree& tree);    // render
void AddBenchCommands(CommandTree& tree);     // bench render | vo
void AddVoCommands(CommandTree& tree);        // vo
void AddStudyCommands(CommandTree& tree);     // study projection | calibration
void AddEvalCommands(CommandTree& tree);      // eval
void AddSuiteCommands(CommandTree& tree);     // suite
void AddBatchCommands(CommandTree& tree);     // batch plan | submit | status | resume | task
void AddDemoCommands(CommandTree& tree);      // demo
void AddGateCommands(CommandTree& tree);      // gate

// `--frames A:B`: "A:B", "A:" or ":B" -> [begin, end), end = -1 for "to the end". An empty text
// leaves begin and end unchanged. Throws std::invalid_argument naming the option.
void ParseFrameRange(const std::string& text, int* begin, int* end);

}  // namespace rovo
