#pragma once
// `rovo batch`: a suite (eval/suite.h) as Slurm jobs. `plan` writes a self-contained batch folder,
// `submit` hands it to sbatch, `status` reads squeue and the folder's markers, `resume` resubmits only
// the tasks that are not done. Every task calls the function `rovo suite` calls for the same work
// (RenderSuiteDataset, RunSuiteRun, MergeSuite), so the merged outputs equal a local run's.
//
// Batch folder (default <out>/batch):
//   plan.json                      the suite's options and the batch's (tasks re-plan from it)
//   render.sbatch                  job array, one task per (preset, shard): scene generation and render
//   vo.sbatch                      job array, one task per VO run (SuitePlan::runs order)
//   merge.sbatch                   one task: evaluation, reports, suite.json, table.md, report.html
//   submit.sh                      the three sbatch calls chained with --dependency=afterok
//   jobs.tsv                       one line per submission: stage, job id, array indices
//   logs/<stage>_<index>.log       each task's output (appended across attempts)
//   state/<stage>_<index>.done     written when a task succeeds; .failed holds the error of a failure
// sacct needs Slurm's accounting storage, which many clusters (and a bare slurmctld) do not run, so
// status uses squeue for queued and running tasks and the markers for finished ones.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/orchestration/suite.h"

namespace rovo {

// Resource request of one task of a stage (sbatch --cpus-per-task, --mem, --time).
struct BatchResources {
  int cpus = 0;      // 0 = the measured default
  std::string mem;   // e.g. "2G"
  std::string time;  // minutes, or Slurm's [D-]HH:MM:SS
};

struct BatchOptions {
  std::string dir;                       // batch folder; "" = <out>/batch
  int shards = 0;                        // render shards per preset; 0 = about kBatchFramesPerShard frames each
  BatchResources render, vo, merge;      // empty mem/time and cpus 0 = the measured defaults
  std::string partition;                 // sbatch --partition ("" = the cluster's default)
  std::vector<std::string> sbatch_args;  // more #SBATCH lines, e.g. "--account=proj"
  std::string rovo;                      // rovo executable the tasks run; "" = this one
};

// Default frames per render shard.
inline constexpr int kBatchFramesPerShard = 200;

// The stages in submission order, and their task counts for a plan.
const std::vector<std::string>& BatchStages();
struct BatchLayout {
  SuitePlan suite;
  BatchOptions options;  // defaults filled in, paths absolute
  int shards = 1;        // per preset
  int Tasks(const std::string& stage) const;
  const BatchResources& Resources(const std::string& stage) const;
};

// Fills in the defaults (measured figures, docs/batch.md) for a suite plan.
BatchLayout PlanBatch(const SuiteOptions& suite, const BatchOptions& options);

// Writes the batch folder of `layout` (plan.json, the sbatch scripts, submit.sh, logs/, state/).
// Refuses a folder that holds another plan.
void WriteBatchFolder(const BatchLayout& layout);
// Reads a batch folder's plan.json back.
BatchLayout LoadBatchFolder(const std::string& dir);

// The sbatch script of one stage (what WriteBatchFolder writes).
std::string BatchScript(const BatchLayout& layout, const std::string& stage);

// Runs task `index` of `stage` (called inside a Slurm job): marks state/<stage>_<index>.done or
// .failed; rethrows a failure.
void RunBatchTask(const std::string& dir, const std::string& stage, int index);

// Array indices as sbatch takes them ("0-3,7") and back.
std::string FormatIndices(const std::vector<int>& indices);
std::vector<int> ParseIndices(const std::string& text);

// State of one task.
// kUnknown: submitted, but squeue did not answer.
enum class TaskState { kDone, kFailed, kRunning, kPending, kLost, kUnknown, kNotSubmitted };
const char* TaskStateName(TaskState state);
struct TaskStatus {
  std::string stage;
  int index = 0;
  TaskState state = TaskState::kNotSubmitted;
  std::string job;     // Slurm id of the task's latest submission ("123_4"), if any
  std::string detail;  // failed: the error; lost: why we think so
  std::string log;     // log file
};
struct BatchStatus {
  std::vector<TaskStatus> tasks;
  bool squeue_ok = false;  // squeue answered; otherwise queued states are unknown
  std::string squeue_error;
};
// `squeue_lines` is `squeue -h -r -o "%i %T"` output (job id, state); nullptr runs squeue.
BatchStatus ReadBatchStatus(const std::string& dir, const std::string* squeue_lines = nullptr);
std::string FormatBatchStatus(const BatchLayout& layout, const BatchStatus& status);

// One sbatch call of a submission.
struct SubmitCall {
  std::string stage;
  std::vector<int> indices;  // array indices (all of the stage for a first submission)
  std::string depends_on;    // the stage this one waits for (afterok), or ""
};
// First submission: every task of every stage. Resume: the tasks that are not done, queued or
// running, and the stages after the first of them (throws when tasks are still queued).
std::vector<SubmitCall> PlanSubmission(const BatchLayout& layout, const BatchStatus* status);
// Runs (or, with dry_run, prints) the sbatch calls and appends the job ids to jobs.tsv.
void SubmitBatch(const BatchLayout& layout, const std::vector<SubmitCall>& calls, bool dry_run);

}  // namespace rovo
