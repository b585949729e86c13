// `rovo` subcommands of render/.
#include "datasets/cli_groups.h"

#include <CLI/CLI.hpp>

namespace rovo {

void AddRenderCommands(CliGroups& groups) {}

}  // namespace rovo
