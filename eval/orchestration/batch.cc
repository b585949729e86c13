#include "eval/orchestration/batch.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "datasets/io.h"
#include "eval/orchestration/suite_systems.h"
#include "render/render.h"
#include "rovo/version.h"

namespace rovo {
namespace fs = std::filesystem;

namespace {

// Measured per-frame costs (docs/batch.md "Per-task figures"; 2-core Debian 12 machine under load,
// Release build): render CPU-seconds per frame (4 views, default spp) and OnlineExt VO seconds per
// frame at one thread, full size and quick form; memory requests about twice to six times the
// measured peak resident memory of one task (render 1.1 GB full / 0.5 GB quick, VO 0.5 / 0.26 GB,
// merge 0.14 GB).
constexpr double kRenderCoreSecondsFull = 1.55;
constexpr double kRenderCoreSecondsQuick = 0.45;
constexpr double kVoSecondsFull = 0.45;
constexpr double kVoSecondsQuick = 0.25;
constexpr const char* kRenderMemFull = "3G";
constexpr const char* kRenderMemQuick = "1G";
constexpr const char* kVoMemFull = "3G";
constexpr const char* kVoMemQuick = "1G";
constexpr const char* kMergeMem = "1G";
constexpr int kRenderCpus = 4;
constexpr int kVoCpus = 2;

// Requested time: three times the measured estimate plus 10 minutes for start-up and I/O, in minutes.
std::string TimeFor(double seconds) {
  return std::to_string(static_cast<int>(std::ceil((3.0 * seconds + 600.0) / 60.0)));
}

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string MarkerPath(const std::string& dir, const std::string& stage, int index, const char* ext) {
  return (fs::path(dir) / "state" / (stage + "_" + std::to_string(index) + ext)).string();
}

std::string LogPath(const std::string& dir, const std::string& stage, int index) {
  return (fs::path(dir) / "logs" / (stage + "_" + std::to_string(index) + ".log")).string();
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return text;
}

std::string EnvOr(const char* name, const std::string& fallback) {
  const char* value = std::getenv(name);
  return value && *value ? value : fallback;
}

// Runs a command line through /bin/sh; returns its exit status and stdout (stderr goes to ours).
int RunCommand(const std::string& command, std::string* out) {
  out->clear();
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) out->append(buffer, n);
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

nlohmann::json ResourcesToJson(const BatchResources& r) { return {{"cpus", r.cpus}, {"mem", r.mem}, {"time", r.time}}; }

BatchResources ResourcesFromJson(const nlohmann::json& j) {
  return {j.at("cpus").get<int>(), j.at("mem").get<std::string>(), j.at("time").get<std::string>()};
}

nlohmann::json LayoutToJson(const BatchLayout& layout) {
  const BatchOptions& o = layout.options;
  return {{"generator", "rovo batch"},
          {"generator_version", ROVO_VERSION},
          {"suite", SuiteOptionsToJson(layout.suite.options)},
          {"batch",
           {{"dir", o.dir},
            {"shards", layout.shards},
            {"render", ResourcesToJson(o.render)},
            {"vo", ResourcesToJson(o.vo)},
            {"merge", ResourcesToJson(o.merge)},
            {"partition", o.partition},
            {"sbatch_args", o.sbatch_args},
            {"rovo", o.rovo}}}};
}

std::string PlanJsonPath(const std::string& dir) { return (fs::path(dir) / "plan.json").string(); }
std::string JobsPath(const std::string& dir) { return (fs::path(dir) / "jobs.tsv").string(); }

// What task `index` of `stage` does, for logs and status.
std::string TaskWhat(const BatchLayout& layout, const std::string& stage, int index) {
  const SuitePlan& plan = layout.suite;
  if (stage == "render") {
    return "render " + plan.options.presets[index / layout.shards] + " shard " + std::to_string(index % layout.shards) +
           "/" + std::to_string(layout.shards);
  }
  if (stage == "vo") {
    const SuiteRun& run = plan.runs.at(index);
    const std::string system = run.system >= 0 ? plan.systems[static_cast<size_t>(run.system)].name + "/" : "";
    return "vo " + plan.options.presets[run.preset_index] + "/" + system + run.name;
  }
  return "merge";
}

// Submissions recorded in jobs.tsv: stage -> (job id, indices), oldest first.
std::map<std::string, std::vector<std::pair<std::string, std::vector<int>>>> ReadJobs(const std::string& dir) {
  std::map<std::string, std::vector<std::pair<std::string, std::vector<int>>>> jobs;
  std::ifstream in(JobsPath(dir));
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::stringstream fields(line);
    std::string stage, job, indices;
    if (!std::getline(fields, stage, '\t') || !std::getline(fields, job, '\t') || !std::getline(fields, indices)) {
      throw std::runtime_error(JobsPath(dir) + ": line " + std::to_string(number) +
                               ": expected stage, job id, indices");
    }
    jobs[stage].emplace_back(job, ParseIndices(indices));
  }
  return jobs;
}

// Last lines of a log file.
std::string LogTail(const std::string& path, int lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  std::string line;
  while (std::getline(in, line)) {
    // Progress lines end in carriage returns: keep the last state of each.
    const size_t cr = line.find_last_of('\r', line.size() >= 2 ? line.size() - 2 : 0);
    if (cr != std::string::npos && cr + 1 < line.size()) line = line.substr(cr + 1);
    all.push_back(line);
  }
  std::string out;
  for (size_t i = all.size() > static_cast<size_t>(lines) ? all.size() - lines : 0; i < all.size(); ++i) {
    out += "      | " + all[i] + "\n";
  }
  return out;
}

}  // namespace

const std::vector<std::string>& BatchStages() {
  static const std::vector<std::string> stages = {"render", "vo", "merge"};
  return stages;
}

int BatchLayout::Tasks(const std::string& stage) const {
  if (stage == "render") return static_cast<int>(suite.options.presets.size()) * shards;
  if (stage == "vo") return static_cast<int>(suite.runs.size());
  if (stage == "merge") return 1;
  throw std::invalid_argument("unknown batch stage \"" + stage + "\" (render, vo, merge)");
}

const BatchResources& BatchLayout::Resources(const std::string& stage) const {
  if (stage == "render") return options.render;
  if (stage == "vo") return options.vo;
  if (stage == "merge") return options.merge;
  throw std::invalid_argument("unknown batch stage \"" + stage + "\" (render, vo, merge)");
}

BatchLayout PlanBatch(const SuiteOptions& suite, const BatchOptions& options) {
  if (suite.out_dir.empty()) throw std::invalid_argument("rovo batch plan: --out is required");
  if (options.shards < 0) throw std::invalid_argument("rovo batch plan: --shards must be >= 0");
  SuiteOptions absolute = suite;
  absolute.out_dir = fs::absolute(suite.out_dir).lexically_normal().string();
  absolute.data_dir =
      fs::absolute(suite.data_dir.empty() ? (fs::path(absolute.out_dir) / "data").string() : suite.data_dir)
          .lexically_normal()
          .string();
  absolute.jobs = 1;
  for (std::string& system : absolute.systems) system = fs::absolute(system).lexically_normal().string();
  BatchLayout layout;
  layout.suite = PlanSuite(absolute);
  CheckSuiteSystems(layout.suite);
  layout.options = options;
  BatchOptions& o = layout.options;
  o.dir =
      fs::absolute(o.dir.empty() ? (fs::path(absolute.out_dir) / "batch").string() : o.dir).lexically_normal().string();
  if (o.rovo.empty()) o.rovo = fs::read_symlink("/proc/self/exe").string();
  const int frames = *std::max_element(layout.suite.frame_ends.begin(), layout.suite.frame_ends.end());
  layout.shards =
      options.shards > 0 ? options.shards : std::max(1, (frames + kBatchFramesPerShard - 1) / kBatchFramesPerShard);
  const int shard_frames = std::min(frames, ((frames + layout.shards - 1) / layout.shards + kShardChunkFrames - 1) /
                                                kShardChunkFrames * kShardChunkFrames);
  if (o.render.cpus <= 0) o.render.cpus = kRenderCpus;
  if (o.vo.cpus <= 0) o.vo.cpus = suite.vo_threads > 0 ? suite.vo_threads : kVoCpus;
  if (o.merge.cpus <= 0) o.merge.cpus = 1;
  const bool quick = suite.quick;
  if (o.render.mem.empty()) o.render.mem = quick ? kRenderMemQuick : kRenderMemFull;
  if (o.vo.mem.empty()) o.vo.mem = quick ? kVoMemQuick : kVoMemFull;
  if (o.merge.mem.empty()) o.merge.mem = kMergeMem;
  if (o.render.time.empty()) {
    o.render.time = TimeFor(shard_frames * (quick ? kRenderCoreSecondsQuick : kRenderCoreSecondsFull) / o.render.cpus);
  }
  if (o.vo.time.empty()) {
    // An external system's task may take its whole timeout, and the export before it.
    double seconds = frames * (quick ? kVoSecondsQuick : kVoSecondsFull);
    for (const SystemDescription& system : layout.suite.systems) seconds = std::max(seconds, system.timeout_s + 600.0);
    o.vo.time = TimeFor(seconds);
  }
  if (o.merge.time.empty()) o.merge.time = TimeFor(layout.suite.runs.size() * 20.0);
  return layout;
}

std::string BatchScript(const BatchLayout& layout, const std::string& stage) {
  const BatchOptions& o = layout.options;
  const BatchResources& r = layout.Resources(stage);
  const int tasks = layout.Tasks(stage);
  std::string s = "#!/bin/bash\n";
  s += "# rovo batch, stage " + stage + " of the suite in " + layout.suite.options.out_dir + " (" +
       std::to_string(tasks) + (tasks == 1 ? " task" : " tasks") + "). Written by `rovo batch plan`.\n";
  s += "#SBATCH --job-name=rovo-" + stage + "\n";
  s += "#SBATCH --array=" + FormatIndices([&] {
         std::vector<int> all(tasks);
         for (int i = 0; i < tasks; ++i) all[i] = i;
         return all;
       }()) +
       "\n";
  s += "#SBATCH --cpus-per-task=" + std::to_string(r.cpus) + "\n";
  s += "#SBATCH --mem=" + r.mem + "\n";
  s += "#SBATCH --time=" + r.time + "\n";
  s += "#SBATCH --chdir=" + o.dir + "\n";
  s += "#SBATCH --output=" + o.dir + "/logs/" + stage + "_%a.log\n";
  s += "#SBATCH --open-mode=append\n";
  s += "#SBATCH --kill-on-invalid-dep=yes\n";
  if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
  for (const std::string& arg : o.sbatch_args) s += "#SBATCH " + arg + "\n";
  s += "exec " + ShellQuote(o.rovo) + " batch task " + ShellQuote(o.dir) + " " + stage +
       " \"${SLURM_ARRAY_TASK_ID:-0}\"\n";
  return s;
}

std::string FormatIndices(const std::vector<int>& indices) {
  std::vector<int> sorted = indices;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  std::string out;
  for (size_t i = 0; i < sorted.size();) {
    size_t j = i;
    while (j + 1 < sorted.size() && sorted[j + 1] == sorted[j] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(sorted[i]) + (j > i ? "-" + std::to_string(sorted[j]) : "");
    i = j + 1;
  }
  return out;
}

std::vector<int> ParseIndices(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    int a = 0, b = 0;
    char dash = 0;
    std::stringstream range(item);
    if (!(range >> a) || a < 0)
      throw std::invalid_argument("array indices \"" + text + "\": bad item \"" + item + "\"");
    b = a;
    if (range >> dash) {
      if (dash != '-' || !(range >> b) || b < a) {
        throw std::invalid_argument("array indices \"" + text + "\": bad range \"" + item + "\"");
      }
    }
    for (int i = a; i <= b; ++i) out.push_back(i);
  }
  return out;
}

void WriteBatchFolder(const BatchLayout& layout) {
  const std::string& dir = layout.options.dir;
  EnsureWritableDir(dir);
  const nlohmann::json plan = LayoutToJson(layout);
  std::error_code ec;
  if (fs::is_regular_file(PlanJsonPath(dir), ec)) {
    const nlohmann::json old = ReadJsonFile(PlanJsonPath(dir));
    if (old.value("suite", nlohmann::json()) != plan["suite"] ||
        old.value("batch", nlohmann::json()) != plan["batch"]) {
      throw std::runtime_error(PlanJsonPath(dir) +
                               " holds another plan (fields \"suite\"/\"batch\" differ): choose "
                               "another --batch folder or remove this one");
    }
  }
  EnsureWritableDir((fs::path(dir) / "logs").string());
  EnsureWritableDir((fs::path(dir) / "state").string());
  WriteJsonFileAtomic(PlanJsonPath(dir), plan);
  for (const std::string& stage : BatchStages()) {
    const std::string path = (fs::path(dir) / (stage + ".sbatch")).string();
    WriteFileAtomic(path, BatchScript(layout, stage));
    fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
  }
  std::string submit =
      "#!/usr/bin/env bash\n"
      "# Submits the batch: each stage is a job array that starts when the one before has succeeded\n"
      "# (--dependency=afterok); job ids go to jobs.tsv for `rovo batch status`. Same as `rovo batch submit`.\n"
      "set -euo pipefail\ncd \"$(dirname \"$0\")\"\n";
  for (const SubmitCall& call : PlanSubmission(layout, nullptr)) {
    const std::string indices = FormatIndices(call.indices);
    submit += call.stage + "=$(sbatch --parsable --array=" + indices +
              (call.depends_on.empty() ? "" : " --dependency=afterok:$" + call.depends_on) + " " + call.stage +
              ".sbatch)\n" + call.stage + "=${" + call.stage + "%%;*}\nprintf '" + call.stage + "\\t%s\\t" + indices +
              "\\n' \"$" + call.stage + "\" >> jobs.tsv\necho \"" + call.stage + ": job $" + call.stage + "\"\n";
  }
  const std::string submit_path = (fs::path(dir) / "submit.sh").string();
  WriteFileAtomic(submit_path, submit);
  fs::permissions(submit_path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
}

BatchLayout LoadBatchFolder(const std::string& dir) {
  const std::string path = PlanJsonPath(dir);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw std::runtime_error(path + ": no batch plan here (write one with `rovo batch plan`)");
  }
  const nlohmann::json j = ReadJsonFile(path);
  if (!j.contains("suite") || !j.contains("batch"))
    throw std::runtime_error(path + ": missing field \"suite\" or \"batch\"");
  BatchLayout layout;
  layout.suite = PlanSuite(SuiteOptionsFromJson(j["suite"], path));
  try {
    const nlohmann::json& b = j["batch"];
    layout.options.dir = b.at("dir").get<std::string>();
    layout.shards = b.at("shards").get<int>();
    layout.options.shards = layout.shards;
    layout.options.render = ResourcesFromJson(b.at("render"));
    layout.options.vo = ResourcesFromJson(b.at("vo"));
    layout.options.merge = ResourcesFromJson(b.at("merge"));
    layout.options.partition = b.at("partition").get<std::string>();
    layout.options.sbatch_args = b.at("sbatch_args").get<std::vector<std::string>>();
    layout.options.rovo = b.at("rovo").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": field \"batch\": " + e.what());
  }
  if (layout.shards < 1) throw std::runtime_error(path + ": field \"batch.shards\" must be >= 1");
  return layout;
}

void RunBatchTask(const std::string& dir, const std::string& stage, int index) {
  const BatchLayout layout = LoadBatchFolder(dir);
  if (index < 0 || index >= layout.Tasks(stage)) {
    throw std::invalid_argument("rovo batch task: " + stage + " has tasks 0.." +
                                std::to_string(layout.Tasks(stage) - 1) + ", not " + std::to_string(index));
  }
  const std::string slurm_job = EnvOr("SLURM_ARRAY_JOB_ID", EnvOr("SLURM_JOB_ID", ""));
  const std::string job = slurm_job.empty() ? "(not under Slurm)" : slurm_job + "_" + std::to_string(index);
  const std::string host = EnvOr("SLURMD_NODENAME", EnvOr("HOSTNAME", ""));
  std::fprintf(stderr, "rovo batch: %s task %d (%s), job %s on %s, started %s\n", stage.c_str(), index,
               TaskWhat(layout, stage, index).c_str(), job.c_str(), host.c_str(), UtcNow().c_str());
  std::error_code ec;
  fs::remove(MarkerPath(dir, stage, index, ".failed"), ec);
  const auto start = std::chrono::steady_clock::now();
  const int cpus = std::atoi(EnvOr("SLURM_CPUS_PER_TASK", std::to_string(layout.Resources(stage).cpus)).c_str());
  const int threads = std::max(1, cpus);
  const SuitePlan& plan = layout.suite;
  try {
    if (stage == "render") {
      RenderSuiteDataset(plan, index / layout.shards, index % layout.shards, layout.shards, threads);
    } else if (stage == "vo") {
      const bool ran = RunSuiteRun(plan, plan.runs[index],
                                   plan.options.vo_threads > 0 ? plan.options.vo_threads : threads, plan.options.quiet);
      if (!ran) std::fprintf(stderr, "rovo batch: the run was complete already\n");
    } else {
      const std::vector<PresetSummary> summaries = MergeSuite(plan);
      std::printf("%s\n", SuiteTableMarkdown(summaries, plan.options.quick).c_str());
    }
  } catch (const std::exception& e) {
    WriteFileAtomic(
        MarkerPath(dir, stage, index, ".failed"),
        nlohmann::json({{"job", job}, {"host", host}, {"error", e.what()}, {"at", UtcNow()}}).dump(2) + "\n");
    throw;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  WriteFileAtomic(
      MarkerPath(dir, stage, index, ".done"),
      nlohmann::json({{"job", job}, {"host", host}, {"seconds", seconds}, {"at", UtcNow()}}).dump(2) + "\n");
  std::fprintf(stderr, "rovo batch: %s task %d done in %.1f s\n", stage.c_str(), index, seconds);
}

const char* TaskStateName(TaskState state) {
  switch (state) {
    case TaskState::kDone:
      return "done";
    case TaskState::kFailed:
      return "failed";
    case TaskState::kRunning:
      return "running";
    case TaskState::kPending:
      return "pending";
    case TaskState::kLost:
      return "lost";
    case TaskState::kUnknown:
      return "unknown";
    case TaskState::kNotSubmitted:
      return "not submitted";
  }
  return "?";
}

BatchStatus ReadBatchStatus(const std::string& dir, const std::string* squeue_lines) {
  const BatchLayout layout = LoadBatchFolder(dir);
  BatchStatus status;
  std::string queue;
  if (squeue_lines) {
    queue = *squeue_lines;
    status.squeue_ok = true;
  } else {
    status.squeue_ok = RunCommand("squeue -h -r -o '%i %T' 2>&1", &queue) == 0;
    if (!status.squeue_ok) status.squeue_error = queue;
  }
  std::map<std::string, std::string> queued;  // "job_index" -> Slurm state
  if (status.squeue_ok) {
    std::stringstream in(queue);
    std::string id, state;
    while (in >> id >> state) queued[id] = state;
  }
  const auto jobs = ReadJobs(dir);
  for (const std::string& stage : BatchStages()) {
    for (int index = 0; index < layout.Tasks(stage); ++index) {
      TaskStatus t;
      t.stage = stage;
      t.index = index;
      t.log = LogPath(dir, stage, index);
      if (const auto it = jobs.find(stage); it != jobs.end()) {
        for (const auto& [job, indices] : it->second) {
          if (std::find(indices.begin(), indices.end(), index) != indices.end())
            t.job = job + "_" + std::to_string(index);
        }
      }
      std::error_code ec;
      const auto q = queued.find(t.job);
      if (fs::is_regular_file(MarkerPath(dir, stage, index, ".done"), ec)) {
        t.state = TaskState::kDone;
      } else if (!t.job.empty() && q != queued.end()) {
        t.state = q->second == "PENDING" || q->second == "CONFIGURING" ? TaskState::kPending : TaskState::kRunning;
        t.detail = q->second;
      } else if (fs::is_regular_file(MarkerPath(dir, stage, index, ".failed"), ec)) {
        t.state = TaskState::kFailed;
        try {
          t.detail = ReadJsonFile(MarkerPath(dir, stage, index, ".failed")).value("error", "");
        } catch (const std::exception& e) {
          t.detail = e.what();
        }
      } else if (!t.job.empty() && status.squeue_ok) {
        t.state = TaskState::kLost;
        t.detail =
            "not in squeue and no marker: cancelled, timed out, out of memory, its node was lost, or a stage "
            "before it failed";
      } else if (!t.job.empty()) {
        t.state = TaskState::kUnknown;
      } else {
        t.state = TaskState::kNotSubmitted;
      }
      status.tasks.push_back(t);
    }
  }
  return status;
}

std::string FormatBatchStatus(const BatchLayout& layout, const BatchStatus& status) {
  std::string out = "Batch " + layout.options.dir + " (suite " + layout.suite.options.out_dir + ")\n";
  int done = 0;
  std::string problems;
  for (const std::string& stage : BatchStages()) {
    std::map<TaskState, int> counts;
    for (const TaskStatus& t : status.tasks) {
      if (t.stage != stage) continue;
      ++counts[t.state];
      if (t.state == TaskState::kDone) ++done;
      if (t.state == TaskState::kFailed || t.state == TaskState::kLost) {
        std::error_code ec;
        const bool has_log = fs::is_regular_file(t.log, ec);
        problems += "  " + stage + "[" + std::to_string(t.index) + "] " + TaskStateName(t.state) + " (" +
                    TaskWhat(layout, stage, t.index) + ", job " + t.job + "): " + t.detail + "\n    log " + t.log +
                    (has_log ? ":\n" + LogTail(t.log, 4) : std::string(" (none: the task never started)\n"));
      }
    }
    std::string line;
    for (const auto& [state, n] : counts)
      line += (line.empty() ? "" : ", ") + std::to_string(n) + " " + TaskStateName(state);
    out += "  " + stage + std::string(8 - std::min<size_t>(7, stage.size()), ' ') +
           std::to_string(layout.Tasks(stage)) + (layout.Tasks(stage) == 1 ? " task: " : " tasks: ") + line + "\n";
  }
  out += problems;
  if (!status.squeue_ok) {
    out += "squeue failed (" + status.squeue_error + "): queued and running tasks are not known\n";
  }
  out += "Task states come from squeue and the markers in " + layout.options.dir +
         "/state (sacct is not used: it needs Slurm's accounting storage).\n";
  out += "Done: " + std::to_string(done) + " of " + std::to_string(status.tasks.size()) + " tasks";
  if (done == static_cast<int>(status.tasks.size())) {
    out += "; results in " + layout.suite.options.out_dir + " (suite.json, table.md)\n";
  } else if (!problems.empty()) {
    out += "; `rovo batch resume " + layout.options.dir + "` resubmits the tasks that are not done\n";
  } else {
    out += "\n";
  }
  return out;
}

std::vector<SubmitCall> PlanSubmission(const BatchLayout& layout, const BatchStatus* status) {
  std::vector<SubmitCall> calls;
  std::string queued;
  for (const std::string& stage : BatchStages()) {
    SubmitCall call;
    call.stage = stage;
    for (int index = 0; index < layout.Tasks(stage); ++index) {
      if (!status) {
        call.indices.push_back(index);
        continue;
      }
      for (const TaskStatus& t : status->tasks) {
        if (t.stage != stage || t.index != index) continue;
        if (t.state == TaskState::kRunning || t.state == TaskState::kPending) {
          queued += (queued.empty() ? "" : ", ") + t.job;
        } else if (t.state != TaskState::kDone) {
          call.indices.push_back(index);
        }
      }
    }
    // The merge reads every run: it runs again after anything before it was resubmitted.
    if (call.indices.empty() && stage == "merge" && !calls.empty()) call.indices.push_back(0);
    if (call.indices.empty()) continue;
    if (!calls.empty()) call.depends_on = calls.back().stage;
    calls.push_back(call);
  }
  if (status && !status->squeue_ok)
    throw std::runtime_error("rovo batch resume: squeue failed: " + status->squeue_error);
  if (!queued.empty()) {
    throw std::runtime_error("rovo batch resume: tasks are still queued or running (" + queued +
                             "): wait for them, or scancel them, then resume");
  }
  return calls;
}

void SubmitBatch(const BatchLayout& layout, const std::vector<SubmitCall>& calls, bool dry_run) {
  const std::string& dir = layout.options.dir;
  std::map<std::string, std::string> job_of;
  for (const SubmitCall& call : calls) {
    const std::string indices = FormatIndices(call.indices);
    std::string command = "sbatch --parsable --array=" + indices;
    if (!call.depends_on.empty()) {
      command += " --dependency=afterok:" + (dry_run ? "<" + call.depends_on + " job id>" : job_of.at(call.depends_on));
    }
    command += " " + ShellQuote((fs::path(dir) / (call.stage + ".sbatch")).string());
    if (dry_run) {
      std::printf("%s\n", command.c_str());
      continue;
    }
    std::string out;
    const int rc = RunCommand(command, &out);
    const std::string job = out.substr(0, out.find_first_of(";\n"));
    if (rc != 0 || job.empty() || job.find_first_not_of("0123456789") != std::string::npos) {
      throw std::runtime_error("rovo batch: `" + command + "` failed (exit " + std::to_string(rc) + "): " + out);
    }
    job_of[call.stage] = job;
    std::string jobs;
    std::error_code ec;
    if (fs::is_regular_file(JobsPath(dir), ec)) jobs = ReadFile(JobsPath(dir));
    WriteFileAtomic(JobsPath(dir), jobs + call.stage + "\t" + job + "\t" + indices + "\n");
    std::printf("%s: job %s, array %s\n", call.stage.c_str(), job.c_str(), indices.c_str());
  }
}

}  // namespace rovo
