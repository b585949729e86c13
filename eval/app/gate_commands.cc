// `rovo gate`: the CI accuracy gate (eval/gate.h); with --run, the suite its gates file describes first.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "datasets/io.h"
#include "eval/app/commands.h"
#include "eval/gate.h"
#include "eval/orchestration/suite.h"

namespace rovo {
namespace {

struct GateArgs {
  std::string gates = "ci/gates.json";
  std::string suite;
  bool run = false;
  std::string data;
  int jobs = 1;
};

void AddGateCommand(CLI::App& root) {
  auto args = std::make_shared<GateArgs>();
  CLI::App* cmd = root.add_subcommand(
      "gate",
      "CI accuracy gate: checks a suite's suite.json against the thresholds of a gates file; prints the table and "
      "exits with status 1 when any metric crosses its threshold. With --run, first runs (or resumes) the suite the "
      "gates file describes into --suite.");
  cmd->add_option("--gates", args->gates, "Gates file (JSON)")->default_val("ci/gates.json");
  cmd->add_option("--suite", args->suite, "Suite folder (holds suite.json)")->required();
  cmd->add_flag("--run", args->run, "Run the suite described in the gates file first (resumes)");
  cmd->add_option("--data", args->data, "With --run: dataset cache folder (default: SUITE/data)");
  cmd->add_option("--jobs", args->jobs, "With --run: VO runs in parallel")->default_val(1)->check(CLI::Range(1, 256));
  cmd->callback([args] {
    const nlohmann::json gates = ReadJsonFile(args->gates);
    if (args->run) {
      SuiteOptions options = GateSuiteOptions(gates, args->gates);
      options.out_dir = args->suite;
      options.data_dir = args->data;
      options.jobs = args->jobs;
      options.plots = false;
      RunSuite(options);
    }
    const std::string suite_path = (std::filesystem::path(args->suite) / "suite.json").string();
    const std::vector<GateCheck> checks = CheckGates(gates, args->gates, ReadJsonFile(suite_path));
    std::printf("%s\n", GateTableMarkdown(checks).c_str());
    if (!AllGatesPass(checks)) {
      std::fprintf(stderr, "rovo gate: FAILED: a metric crossed its threshold (%s vs %s)\n", suite_path.c_str(),
                   args->gates.c_str());
      throw CLI::RuntimeError(1);
    }
    std::printf("rovo gate: all %zu gates pass\n", checks.size());
  });
}

}  // namespace

void AddGateCommands(CommandTree& tree) { AddGateCommand(*tree.root); }

}  // namespace rovo
