// The `rovo` command: parses the command line and hands off to the parts' commands.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "datasets/cli_groups.h"
#include "eval/calibration_study.h"
#include "rovo/version.h"

int main(int argc, char** argv) {
  CLI::App app{"rovo " ROVO_VERSION
               ": synthetic multi-fisheye datasets with exact ground truth, the ROVO visual odometry pipeline, "
               "and its evaluation suites."};
  app.set_version_flag("--version", "rovo " ROVO_VERSION);
  app.require_subcommand(1);

  rovo::CliGroups groups;
  groups.root = &app;
  groups.dataset = app.add_subcommand("dataset", "Inspect and validate datasets");
  groups.dataset->require_subcommand(1);
  groups.scene = app.add_subcommand("scene", "Generate, convert and preview scenes");
  groups.scene->require_subcommand(1);
  groups.bench = app.add_subcommand("bench", "Speed benchmarks that print a table");
  groups.bench->require_subcommand(1);
  groups.study = app.add_subcommand("study", "Studies that reproduce the paper's analyses");
  groups.study->require_subcommand(1);

  rovo::AddDatasetCommands(groups);
  rovo::AddSceneCommands(groups);
  rovo::AddRenderCommands(groups);
  rovo::AddVoCommands(groups);
  rovo::AddEvalCommands(groups);
  rovo::AddCalibrationStudyCommand(groups.study);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rovo: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
