#pragma once
// The `rovo` command tree. main() creates the groups; each part adds its subcommands with
// Add<Part>Commands(CliGroups&). Commands report bad input by throwing std::exception (main prints
// "rovo: error: <what>" and exits 1) or CLI::RuntimeError(code) for a specific exit code.

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

void AddDatasetCommands(CliGroups& groups);  // datasets/cli.cc
void AddSceneCommands(CliGroups& groups);    // scenes/cli.cc
void AddRenderCommands(CliGroups& groups);   // render/cli.cc
void AddVoCommands(CliGroups& groups);       // vo/cli.cc
void AddEvalCommands(CliGroups& groups);     // eval/cli.cc

}  // namespace rovo
