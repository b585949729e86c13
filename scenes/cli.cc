// `rovo` subcommands of scenes/.
#include "datasets/cli_groups.h"

#include <CLI/CLI.hpp>

namespace rovo {

void AddSceneCommands(CliGroups& groups) {}

}  // namespace rovo
