// `rovo demo`: the end-to-end demo, a quick one-preset suite.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "eval/app/commands.h"
#include "eval/app/suite_args.h"

namespace rovo {
namespace {

void AddDemoCommand(CLI::App& root) {
  auto out = std::make_shared<std::string>("rovo-demo");
  auto no_plots = std::make_shared<bool>(false);
  CLI::App* cmd = root.add_subcommand(
      "demo",
      "End-to-end demo: renders the small default dataset (cloudy_urban, quick), runs GTExt, NoisyExt and OnlineExt "
      "(one noise set), prints the Table I row and writes the report (a few minutes on 2 cores).");
  cmd->add_option("--out", *out, "Output folder")->default_val("rovo-demo");
  cmd->add_flag("--no-plots", *no_plots, "Skip plots and report.html");
  cmd->callback([out, no_plots] {
    SuiteOptions options;
    options.presets = {"cloudy_urban"};
    options.quick = true;
    options.noise_sets = 1;
    options.out_dir = *out;
    options.plots = !*no_plots;
    PrintSuite(RunSuite(options), options);
    if (options.plots) {
      std::printf("Open %s\n", (std::filesystem::absolute(*out) / "report.html").lexically_normal().c_str());
    }
  });
}

}  // namespace

void AddDemoCommands(CommandTree& tree) { AddDemoCommand(*tree.root); }

}  // namespace rovo
