// The `rovo` command: builds the command tree (one Add<Group>Commands per file of eval/app/) and runs it.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "eval/app/commands.h"
#include "eval/app/progress_printer.h"
#include "rovo/version.h"

// Building the command tree throws only on a programming error (a flag named twice), which should abort.
int main(int argc, char** argv) {  // NOLINT(bugprone-exception-escape)
  CLI::App app{"rovo " ROVO_VERSION
               ": synthetic multi-fisheye datasets with exact ground truth, the ROVO visual odometry pipeline, "
               "and its evaluation suites."};
  app.set_version_flag("--version", "rovo " ROVO_VERSION);
  app.require_subcommand(1);
  rovo::ProgressPrinter progress_printer;  // the libraries' progress, shown on stderr
  rovo::SetProgressSink(&progress_printer);

  rovo::CommandTree tree;
  tree.root = &app;
  tree.dataset = app.add_subcommand("dataset", "Inspect and validate datasets");
  tree.dataset->require_subcommand(1);
  tree.scene = app.add_subcommand("scene", "Generate, convert and preview scenes");
  tree.scene->require_subcommand(1);
  tree.bench = app.add_subcommand("bench", "Speed benchmarks that print a table");
  tree.bench->require_subcommand(1);
  tree.study = app.add_subcommand("study", "Studies that reproduce the paper's analyses");
  tree.study->require_subcommand(1);

  rovo::AddDatasetCommands(tree);
  rovo::AddExchangeCommands(tree);
  rovo::AddSceneCommands(tree);
  rovo::AddRenderCommands(tree);
  rovo::AddBenchCommands(tree);
  rovo::AddVoCommands(tree);
  rovo::AddStudyCommands(tree);
  rovo::AddEvalCommands(tree);
  rovo::AddSuiteCommands(tree);
  rovo::AddBatchCommands(tree);
  rovo::AddDemoCommands(tree);
  rovo::AddGateCommands(tree);

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
