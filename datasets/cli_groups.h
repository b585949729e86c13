#pragma once
// The `rovo` command tree. main() creates the groups; each part adds its subcommands with
// Add<Part>Commands(CliGroups&). Commands report bad input by throwing std::exception (main prints
// "rovo: error: <what>" and exits 1) or CLI::RuntimeError(code) for a specific exit code.

#include <string>

namespace CLI {
class App;
}

namespace rovo {

struct CliGroups {
  CLI::App* root = nullptr;
  CLI::App* dataset = nullptr;  // rovo dataset ...
  CLI::App* scene = nullptr;    // rovo scene ...
  CLI::App* bench = nullptr;    // rovo bench ...
  CLI::App* study = nullptr;    // rovo study ...
};

// `--frames A:B`: "A:B", "A:" or ":B" -> [begin, end), end = -1 for "to the end". An empty text
// leaves begin and end unchanged. Throws std::invalid_argument naming the option.
void ParseFrameRange(const std::string& text, int* begin, int* end);

void AddDatasetCommands(CliGroups& groups);  // datasets/cli.cc
void AddSceneCommands(CliGroups& groups);    // scenes/cli.cc
void AddRenderCommands(CliGroups& groups);   // render/cli.cc
void AddVoCommands(CliGroups& groups);       // vo/cli.cc
void AddEvalCommands(CliGroups& groups);     // eval/cli.cc

}  // namespace rovo
