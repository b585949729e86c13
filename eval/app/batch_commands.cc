// `rovo batch`: a suite as Slurm job arrays (eval/orchestration/batch.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>

#include "eval/app/commands.h"
#include "eval/app/suite_args.h"
#include "eval/orchestration/batch.h"

namespace rovo {

namespace {

struct BatchPlanArgs {
  SuiteCliArgs suite;
  BatchOptions batch;
};

void AddResourceOptions(CLI::App* cmd, const std::string& stage, BatchResources* r) {
  cmd->add_option("--" + stage + "-cpus", r->cpus, "CPUs of each " + stage + " task (default: measured, docs/batch.md)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--" + stage + "-mem", r->mem, "Memory of each " + stage + " task, e.g. 4G (default: measured)");
  cmd->add_option("--" + stage + "-time", r->time,
                  "Time limit of each " + stage + " task, minutes or [D-]HH:MM:SS (default: from measured speed)");
}

void AddPlanCommand(CLI::App* batch) {
  auto args = std::make_shared<BatchPlanArgs>();
  args->batch.render.cpus = args->batch.vo.cpus = args->batch.merge.cpus = 0;
  CLI::App* cmd = batch->add_subcommand(
      "plan",
      "Write a Slurm batch folder for the suite these options describe (the same options as `rovo suite`): one sbatch "
      "job array per stage (render: scene generation and rendering per preset and shard; vo: one task per VO run; "
      "merge: evaluation, reports, suite.json, table.md), chained with --dependency=afterok, per-task logs and "
      "markers, and submit.sh.");
  AddSuiteOptions(cmd, &args->suite);
  cmd->add_option("--batch", args->batch.dir, "Batch folder to write (default: OUT/batch)");
  cmd->add_option("--shards", args->batch.shards, "Render shards per preset (default: about 200 frames each)")
      ->check(CLI::NonNegativeNumber);
  AddResourceOptions(cmd, "render", &args->batch.render);
  AddResourceOptions(cmd, "vo", &args->batch.vo);
  AddResourceOptions(cmd, "merge", &args->batch.merge);
  cmd->add_option("--partition", args->batch.partition, "sbatch --partition of every job");
  cmd->add_option("--sbatch-arg", args->batch.sbatch_args, "More #SBATCH lines, e.g. --sbatch-arg=--account=proj");
  cmd->add_option("--rovo", args->batch.rovo, "rovo executable the tasks run (default: this one)");
  cmd->callback([args] {
    const BatchLayout layout = PlanBatch(args->suite.Options(), args->batch);
    WriteBatchFolder(layout);
    std::printf("Batch folder %s:\n", layout.options.dir.c_str());
    for (const std::string& stage : BatchStages()) {
      const BatchResources& r = layout.Resources(stage);
      std::printf("  %-6s %4d task(s), each --cpus-per-task=%d --mem=%s --time=%s\n", stage.c_str(),
                  layout.Tasks(stage), r.cpus, r.mem.c_str(), r.time.c_str());
    }
    std::printf("Submit with `rovo batch submit %s` (or %s/submit.sh)\n", layout.options.dir.c_str(),
                layout.options.dir.c_str());
  });
}

}  // namespace

void AddBatchCommands(CommandTree& tree) {
  CLI::App* batch = tree.root->add_subcommand(
      "batch", "Run a suite on a Slurm cluster: plan a batch folder, submit it, follow it, resume what did not finish");
  batch->require_subcommand(1);
  AddPlanCommand(batch);

  auto dir = std::make_shared<std::string>();
  auto dry_run = std::make_shared<bool>(false);
  CLI::App* submit = batch->add_subcommand("submit", "Submit a batch folder's stages through sbatch (afterok chain)");
  submit->add_option("dir", *dir, "Batch folder")->required();
  submit->add_flag("--dry-run", *dry_run, "Print the sbatch commands instead of running them");
  submit->callback([dir, dry_run] {
    const BatchLayout layout = LoadBatchFolder(*dir);
    SubmitBatch(layout, PlanSubmission(layout, nullptr), *dry_run);
  });

  CLI::App* status = batch->add_subcommand(
      "status", "Print which tasks are done, running, pending, failed or lost (squeue and the folder's markers)");
  status->add_option("dir", *dir, "Batch folder")->required();
  status->callback([dir] {
    const BatchLayout layout = LoadBatchFolder(*dir);
    std::printf("%s", FormatBatchStatus(layout, ReadBatchStatus(*dir)).c_str());
  });

  CLI::App* resume = batch->add_subcommand(
      "resume",
      "Resubmit only the tasks that are not done (failed, lost or never submitted) and the stages after them");
  resume->add_option("dir", *dir, "Batch folder")->required();
  resume->add_flag("--dry-run", *dry_run, "Print the sbatch commands instead of running them");
  resume->callback([dir, dry_run] {
    const BatchLayout layout = LoadBatchFolder(*dir);
    const BatchStatus state = ReadBatchStatus(*dir);
    const std::vector<SubmitCall> calls = PlanSubmission(layout, &state);
    if (calls.empty()) {
      std::printf("rovo batch resume: every task is done; results in %s\n", layout.suite.options.out_dir.c_str());
      return;
    }
    SubmitBatch(layout, calls, *dry_run);
  });

  auto stage = std::make_shared<std::string>();
  auto index = std::make_shared<int>(0);
  CLI::App* task = batch->add_subcommand("task", "Run one task of a batch folder (what the sbatch scripts call)");
  task->add_option("dir", *dir, "Batch folder")->required();
  task->add_option("stage", *stage, "render, vo or merge")->required()->check(CLI::IsMember({"render", "vo", "merge"}));
  task->add_option("index", *index, "Task index (SLURM_ARRAY_TASK_ID)")->required();
  task->callback([dir, stage, index] { RunBatchTask(*dir, *stage, *index); });
}

}  // namespace rovo
