// Running a suite's tasks: datasets, VO runs (reused when their settings match), the whole suite.
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <type_traits>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "datasets/run.h"
#include "eval/format.h"
#include "eval/orchestration/external_run.h"
#include "eval/orchestration/suite.h"
#include "eval/orchestration/suite_systems.h"
#include "eval/plots.h"
#include "eval/report.h"
#include "render/render.h"
#include "render/timing.h"
#include "scenes/city.h"
#include "scenes/rng.h"
#include "vo/pipeline.h"
#include "vo/vo_options.h"

namespace rovo {
namespace fs = std::filesystem;

namespace {

// The options of a suite run (RunSettings recorded by RunVo).
VoOptions VoOptionsFor(const RunSettings& settings) {
  VoOptions vo;
  vo.start.mode = settings.mode;
  vo.start.noise_set = settings.noise_set;
  vo.start.draw_seed = settings.draw_seed;
  vo.start.draw_sigma_deg = settings.draw_sigma_deg;
  vo.frontend.max_new_features_per_view = settings.max_new_features;
  vo.backend.ransac.seed = settings.seed;
  vo.io.frames.end = settings.frame_end;
  return vo;
}

}  // namespace

bool RunReusable(const std::string& run_dir, const RunSettings& want, std::string* mismatch) {
  mismatch->clear();
  std::error_code ec;
  if (!fs::is_regular_file(RunInfoPath(run_dir), ec)) return false;
  nlohmann::json info;
  try {
    info = ReadJsonFile(RunInfoPath(run_dir));
  } catch (const std::exception&) {
    return false;
  }
  if (!info.is_object() || !info.contains("dataset") || !info.contains("frames") ||
      info["frames"] != nlohmann::json::array({0, want.frame_end}) ||
      !fs::is_regular_file(RunTrajectoryPath(run_dir), ec) || !fs::is_regular_file(RunFramesPath(run_dir), ec) ||
      !fs::is_regular_file(RunExtrinsicsPath(run_dir), ec)) {
    return false;  // incomplete (a run writes run.json last)
  }
  return VoRunSettingsMatch(info, VoOptionsFor(want), mismatch);
}

namespace {

// Whether the dataset's sensor and timing records are the ones `render` would write (the timing's
// sampling aside), and it has an IMU exactly when `render` adds one (a variant's dataset rendered with
// other effects is not reused).
bool EffectsMatch(const DatasetInfo& info, const RenderOptions& render) {
  const int n = info.rig.NumCameras();
  if (render.sensor.enabled != info.sensor.has_value() || render.timing.Enabled() != info.timing.has_value() ||
      render.imu != info.imu.has_value())
    return false;
  if (info.sensor &&
      *info.sensor != MakeSensorRecord(render.sensor, CameraSensitivities(render.sensor, n, render.seed)))
    return false;
  return !info.timing ||
         info.timing->SameExposure(MakeTimingRecord(render.timing, TriggerOffsetsMs(render.timing, n, render.seed)));
}

// Complete: the first `max_frames` frames (all when <= 0) have every camera's image, and the effects
// match `render`'s.
bool DatasetComplete(const std::string& dataset_dir, int max_frames, const RenderOptions& render) {
  std::error_code ec;
  if (!fs::is_regular_file(DatasetJsonPath(dataset_dir), ec) ||
      !fs::is_regular_file(GroundTruthPath(dataset_dir), ec)) {
    return false;
  }
  try {
    const DatasetInfo info = ReadDatasetInfo(dataset_dir);
    if (!EffectsMatch(info, render)) return false;
    const int frames = max_frames > 0 ? std::min(max_frames, info.frame_count) : info.frame_count;
    for (int f = 0; f < frames; ++f) {
      for (const RigCamera& cam : info.rig.cameras) {
        if (!fs::is_regular_file(ImagePath(dataset_dir, cam.name, f), ec)) return false;
      }
    }
    return info.frame_count > 0 && info.frame_count >= max_frames;
  } catch (const std::exception&) {
    return false;
  }
}

// The render settings of a variant (ParseSuiteEntry), on top of the preset's.
void ApplySuiteVariant(const std::string& variant, RenderOptions* render) {
  if (variant.empty()) return;
  const bool sensor = variant == "sensor" || variant == "gray" || variant == "optics" || variant == "realistic";
  if (variant == "ideal") render->sensor = MakeSensorSettings("ideal", {});
  if (sensor) {
    SensorOverrides overrides;
    if (variant == "gray") overrides.grayscale = true;
    render->sensor = MakeSensorSettings("realistic", overrides);
  }
  if (variant == "optics" || variant == "realistic") render->optics = OpticsProfile("realistic");
  if (variant == "realistic") render->timing = RealisticTiming();
  if (variant == "blur") render->timing.shutter_ms = 10.0;
  if (variant == "rolling") render->timing.rolling_shutter_ms = 30.0;
  if (variant == "trigger") render->timing.trigger_offset_std_ms = 1.0;
}

// The dataset must cover the runs' frames and hold the noise sets they use.
void CheckSuiteDataset(const SuitePlan& plan, size_t preset_index) {
  const std::string& dir = plan.dataset_dirs[preset_index];
  const DatasetInfo info = ReadDatasetInfo(dir);
  if (info.frame_count < plan.frame_ends[preset_index]) {
    throw std::runtime_error(DatasetJsonPath(dir) + ": field \"frame_count\" is " + std::to_string(info.frame_count) +
                             ", the suite runs frames [0, " + std::to_string(plan.frame_ends[preset_index]) + ")");
  }
  if (static_cast<int>(info.perturbed.size()) < plan.options.noise_sets) {
    throw std::runtime_error(DatasetJsonPath(dir) + ": field \"perturbed\" holds " +
                             std::to_string(info.perturbed.size()) + " noise sets, --seeds asks for " +
                             std::to_string(plan.options.noise_sets));
  }
}

// Runs `todo` with `parallel` runs at a time; rethrows the first error after the running ones end.
void RunSuiteRunsInParallel(const SuitePlan& plan, const std::vector<const SuiteRun*>& todo, int parallel,
                            int threads_per_run) {
  Progress progress("suite VO runs", static_cast<int64_t>(todo.size()), "runs", plan.options.quiet);
  std::atomic<size_t> next{0};
  std::mutex error_mutex;
  std::exception_ptr first_error;
  auto worker = [&] {
    while (true) {
      const size_t index = next.fetch_add(1);
      if (index >= todo.size()) return;
      {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (first_error) return;
      }
      try {
        RunSuiteRun(plan, *todo[index], threads_per_run, plan.options.quiet || parallel > 1);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
      }
      progress.Add(1);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < parallel; ++i) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  progress.Finish();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace

void RenderSuiteDataset(const SuitePlan& plan, size_t preset_index, int shard, int shards, int threads) {
  const SuiteOptions& options = plan.options;
  const std::string& dir = plan.dataset_dirs.at(preset_index);
  const std::string& preset = options.presets[preset_index];
  RenderOptions render;
  const SuiteEntry entry = ParseSuiteEntry(preset);
  render.preset = entry.preset;
  ApplySuiteVariant(entry.variant, &render);
  render.seed = options.scene_seed;
  render.imu = plan.imu;  // a system needs it (rovo render --imu, default settings)
  if (DatasetComplete(dir, plan.frame_ends[preset_index], render)) {
    if (!options.quiet) std::fprintf(stderr, "rovo suite: dataset %s is complete, not rendering\n", dir.c_str());
    return;
  }
  if (!options.quiet) {
    std::fprintf(stderr, "rovo suite: rendering %s%s%s -> %s%s\n", preset.c_str(), options.quick ? " (quick)" : "",
                 plan.imu ? " with an IMU" : "", dir.c_str(),
                 shards > 1 ? (" (shard " + std::to_string(shard) + "/" + std::to_string(shards) + ")").c_str() : "");
  }
  EnsureWritableDir(plan.data_dir);
  render.quick = options.quick;
  render.out_dir = dir;
  if (options.frames > 0) render.frame_end = plan.frame_ends[preset_index];
  render.shard_index = shard;
  render.shard_count = shards;
  render.threads = threads;
  render.depth = false;
  render.quiet = options.quiet;
  RenderDataset(render);
}

namespace {

// Suite runs of this process in flight, and started so far: a run knows whether another ran beside it
// (--jobs > 1), which makes its process-wide CPU time include theirs.
std::atomic<int> g_runs_in_flight{0};
std::atomic<uint64_t> g_runs_started{0};

class RunOverlap {
 public:
  RunOverlap() : started_before_(g_runs_started.fetch_add(1)), alone_at_start_(g_runs_in_flight.fetch_add(1) == 0) {}
  ~RunOverlap() { g_runs_in_flight.fetch_sub(1); }
  RunOverlap(const RunOverlap&) = delete;
  RunOverlap& operator=(const RunOverlap&) = delete;
  // Whether another run was in flight at the start, started since, or is in flight now.
  bool Overlapped() const {
    return !alone_at_start_ || g_runs_started.load() != started_before_ + 1 || g_runs_in_flight.load() > 1;
  }

 private:
  uint64_t started_before_;
  bool alone_at_start_;
};

rusage ProcessUsage() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return usage;
}

// rovo's own run is in-process, on several threads (so RUSAGE_THREAD would miss its workers): its CPU
// time is the delta of getrusage(RUSAGE_SELF) over the run, exact when runs are serial (--jobs 1, and
// every Slurm task), and marked "cpu_overlapped" when another run of this process ran beside it. Its
// memory is the process's ru_maxrss: the peak of the whole rovo process since it started, labelled so.
// Written as the run's system_run.json, in the layout of an external run's (suite_systems.h).
void WriteRovoRunRecord(const SuitePlan& plan, const SuiteRun& run, int threads, double wall_s, const rusage& before,
                        const rusage& after, bool overlapped) {
  const double user = Seconds(after.ru_utime) - Seconds(before.ru_utime);
  const double system = Seconds(after.ru_stime) - Seconds(before.ru_stime);
  nlohmann::json record = SystemRunRecordHead(plan, run, kBuiltInSystem, threads);
  record.update(nlohmann::json{
      {"status", "ok"},
      {"in_process", true},
      {"wall_s", wall_s},
      {"user_cpu_s", user},
      {"system_cpu_s", system},
      {"cpu_s", user + system},
      {"cpu_source", "getrusage(RUSAGE_SELF) delta over the run: the whole rovo process"},
      {"cpu_overlapped", overlapped},
      {"process_maxrss_mb", static_cast<double>(after.ru_maxrss) / 1024.0},
      {"memory_source",
       "ru_maxrss of the rovo process at the run's end: its peak since it started (rendering and earlier runs "
       "included), not the run's own"}});
  WriteJsonFileAtomic((fs::path(run.run_dir) / kSystemRunFile).string(), record);
}

}  // namespace

bool RunSuiteRun(const SuitePlan& plan, const SuiteRun& run, int threads, bool quiet) {
  const RunOverlap overlap;
  if (run.system >= 0) {
    CheckSuiteDataset(plan, run.preset_index);
    return RunSystemRun(plan, run, threads, quiet);
  }
  std::string mismatch;
  if (RunReusable(run.run_dir, run.settings, &mismatch)) {
    if (!plan.options.quiet) std::fprintf(stderr, "rovo suite: run %s is complete, skipping\n", run.run_dir.c_str());
    return false;
  }
  if (!mismatch.empty()) {
    std::fprintf(stderr, "rovo suite: run %s was made with other settings (%s), running it again\n",
                 run.run_dir.c_str(), mismatch.c_str());
  }
  CheckSuiteDataset(plan, run.preset_index);
  VoOptions vo = VoOptionsFor(run.settings);
  vo.io.dataset_dir = plan.dataset_dirs[run.preset_index];
  vo.io.out_dir = run.run_dir;
  vo.io.threads = threads;
  vo.io.quiet = quiet;
  const rusage before = ProcessUsage();
  const auto start = std::chrono::steady_clock::now();
  RunVo(vo);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  WriteRovoRunRecord(plan, run, threads, wall_s, before, ProcessUsage(), overlap.Overlapped());
  return true;
}

std::vector<PresetSummary> RunSuite(const SuiteOptions& options) {
  const SuitePlan plan = PlanSuite(options);
  CheckSuiteSystems(plan);
  EnsureWritableDir(options.out_dir);
  EnsureWritableDir(plan.data_dir);
  const int cores = options.threads > 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  // Datasets: rendering uses all cores, one dataset at a time.
  for (size_t i = 0; i < plan.dataset_dirs.size(); ++i) {
    RenderSuiteDataset(plan, i, 0, 1, cores);
    CheckSuiteDataset(plan, i);
  }
  // VO runs, --jobs at a time.
  std::vector<const SuiteRun*> todo;
  for (const SuiteRun& run : plan.runs) {
    std::string mismatch;
    if (run.system >= 0 || !RunReusable(run.run_dir, run.settings, &mismatch)) todo.push_back(&run);
  }
  const int parallel = std::min<int>(options.jobs, std::max<int>(1, static_cast<int>(todo.size())));
  const int threads_per_run = options.vo_threads > 0 ? options.vo_threads : std::max(1, cores / parallel);
  RunSuiteRunsInParallel(plan, todo, parallel, threads_per_run);
  return MergeSuite(plan);
}

}  // namespace rovo
