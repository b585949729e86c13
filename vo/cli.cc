// `rovo` subcommands of vo/.
#include "datasets/cli_groups.h"

#include <CLI/CLI.hpp>

namespace rovo {

void AddVoCommands(CliGroups& groups) {}

}  // namespace rovo
