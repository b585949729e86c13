// `rovo` subcommands of eval/.
#include "datasets/cli_groups.h"

#include <CLI/CLI.hpp>

namespace rovo {

void AddEvalCommands(CliGroups& groups) {}

}  // namespace rovo
