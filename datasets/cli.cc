// `rovo` subcommands of datasets/.
#include "datasets/cli_groups.h"

#include <CLI/CLI.hpp>

namespace rovo {

void AddDatasetCommands(CliGroups& groups) {}

}  // namespace rovo
