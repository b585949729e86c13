// External systems in a suite (suite_systems.h).
#include "eval/orchestration/suite_systems.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "datasets/dataset.h"
#include "datasets/exchange/exchange.h"
#include "datasets/exchange/ros2_bag.h"
#include "datasets/io.h"
#include "datasets/rig_json.h"
#include "eval/foreign_run.h"
#include "eval/format.h"
#include "eval/orchestration/external_run.h"
#include "rovo/version.h"

namespace rovo {
namespace fs = std::filesystem;
const char* SuiteModeName(ExtrinsicsMode mode) {
  switch (mode) {
    case ExtrinsicsMode::kGroundTruth:
      return "gt";
    case ExtrinsicsMode::kNoisy:
      return "noisy";
    case ExtrinsicsMode::kOnline:
      return "online";
  }
  return "?";
}

nlohmann::json SystemRunRecordHead(const SuitePlan& plan, const SuiteRun& run, const std::string& system, int threads) {
  return {{"generator", "rovo suite"},
          {"generator_version", ROVO_VERSION},
          {"system", system},
          {"run", run.name},
          {"mode", SuiteModeName(run.settings.mode)},
          {"noise_set", run.settings.mode == ExtrinsicsMode::kGroundTruth ? -1 : run.settings.noise_set},
          {"draw_seed", run.settings.draw_seed},
          {"seed", plan.options.vo_seed},
          {"threads", threads}};
}

namespace {

const SystemDescription& SystemOf(const SuitePlan& plan, const SuiteRun& run) {
  return plan.systems.at(static_cast<size_t>(run.system));
}

// The rig cameras the export writes, in export order.
std::vector<int> ExportCameras(const SystemDescription& system, int rig_cameras) {
  if (!system.cameras.empty()) return system.cameras;
  std::vector<int> all(static_cast<size_t>(std::max(0, rig_cameras)));
  for (int i = 0; i < rig_cameras; ++i) all[static_cast<size_t>(i)] = i;
  return all;
}

std::string ExportDirFor(const SuitePlan& plan, size_t preset_index, const SystemDescription& system) {
  std::string subset;
  for (int c : system.cameras) subset += "_c" + std::to_string(c);
  return plan.dataset_dirs[preset_index] + ".exports/" + system.input + (system.lens.empty() ? "" : "_" + system.lens) +
         subset;
}

// A lock file held while the export is written (runs of a suite, and Slurm tasks, share exports).
class FileLock {
 public:
  explicit FileLock(const std::string& path) : fd_(::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644)) {
    if (fd_ < 0) throw std::runtime_error(path + ": cannot open lock file: " + std::strerror(errno));
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno != EINTR) throw std::runtime_error(path + ": cannot lock: " + std::strerror(errno));
    }
  }
  ~FileLock() { ::close(fd_); }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_;
};

// The first `frames` frames of a dataset as a dataset of their own (--frames): dataset.json and
// groundtruth.tum cut to them, the image folders and the IMU's streams (whole) linked.
std::string FramesView(const std::string& dataset_dir, const DatasetInfo& info, int frames) {
  const fs::path view = fs::path(dataset_dir + ".exports") / ("frames_" + std::to_string(frames));
  nlohmann::json json = ReadJsonFile(DatasetJsonPath(dataset_dir));
  json["frame_count"] = frames;
  const Trajectory gt = ReadTum(GroundTruthPath(dataset_dir));
  fs::create_directories(view);
  std::vector<std::string> folders;
  for (const RigCamera& camera : info.rig.cameras) folders.push_back(camera.name);
  if (info.imu) folders.emplace_back("imu");
  for (const std::string& folder : folders) {
    const fs::path link = view / folder;
    std::error_code ec;
    if (!fs::is_symlink(link, ec)) fs::create_symlink(fs::absolute(fs::path(dataset_dir) / folder), link);
  }
  WriteTum(GroundTruthPath(view.string()),
           Trajectory(gt.begin(), gt.begin() + std::min<long>(frames, static_cast<long>(gt.size()))));
  WriteJsonFileAtomic(DatasetJsonPath(view.string()), json);
  return view.string();
}

// The dataset an export is written from: the dataset, or (--frames) the view of its first frames, made
// under the exports' lock.
std::string ExportSource(const SuitePlan& plan, size_t preset_index, const DatasetInfo& info) {
  const int frames = plan.frame_ends[preset_index];
  const std::string& dataset_dir = plan.dataset_dirs[preset_index];
  if (frames >= info.frame_count) return dataset_dir;
  EnsureWritableDir(dataset_dir + ".exports");
  const FileLock lock(dataset_dir + ".exports/export.lock");
  return FramesView(dataset_dir, info, frames);
}

// The export the system reads, written once (under a lock) and reused while it covers the frames.
std::string EnsureExport(const SuitePlan& plan, size_t preset_index, const SystemDescription& system,
                         const DatasetInfo& info) {
  const int frames = plan.frame_ends[preset_index];
  const bool part = frames < info.frame_count;
  std::string dir = ExportDirFor(plan, preset_index, system) + (part ? "_frames_" + std::to_string(frames) : "");
  EnsureWritableDir(fs::path(dir).parent_path().string());
  const FileLock lock(fs::path(dir).parent_path().string() + "/export.lock");
  const std::string marker = (fs::path(dir) / "rovo_export.json").string();
  std::error_code ec;
  if (fs::is_regular_file(marker, ec)) {
    try {
      if (ReadJsonFile(marker).at("frames").get<int>() == frames) return dir;
    } catch (const std::exception&) {
    }
  }
  ExportOptions options;
  options.format = ExchangeFormatFromName(system.input);
  options.out_dir = dir;
  if (!system.lens.empty()) options.model = ExchangeLensModelFromName(system.lens);
  options.cameras = system.cameras;
  const std::string& dataset_dir = plan.dataset_dirs[preset_index];
  ExportDataset(part ? FramesView(dataset_dir, info, frames) : dataset_dir, options);
  return dir;
}

// The extrinsics a run is given: the true ones, a stored noise set, or a fresh draw.
std::vector<Rigid3> GivenExtrinsics(const DatasetInfo& info, const RunSettings& settings) {
  if (settings.draw_seed >= 0) {
    return PerturbExtrinsics(info.rig, settings.draw_sigma_deg, 0.0, static_cast<uint64_t>(settings.draw_seed))
        .cam_from_rig;
  }
  if (settings.mode == ExtrinsicsMode::kGroundTruth) return info.rig.Extrinsics();
  return info.perturbed.at(static_cast<size_t>(settings.noise_set)).cam_from_rig;
}

// The calibration of one run: the files written for it, what {input} and {calibration} are.
struct RunCalibration {
  std::string input, calibration;
  std::vector<std::pair<std::string, std::string>> files;  // path, content
  std::vector<std::pair<std::string, std::string>> links;  // link path, target
  std::string hash;
};

// The export's cameras with the given extrinsics (the export's own turn of each camera frame kept).
// An export's camera pose is turn * cam_from_rig * rig_from_body, the body being the rig, or the IMU
// when the dataset has one (exchange.h); the given one is turn * given_cam_from_rig * rig_from_body.
std::vector<ExchangeCamera> GivenCameras(std::vector<ExchangeCamera> exported, const DatasetInfo& info,
                                         const std::vector<int>& cameras, const std::vector<Rigid3>& given) {
  const Rigid3 rig_from_body = info.imu && info.rig.imu_from_rig ? info.rig.imu_from_rig->Inverse() : Rigid3();
  for (size_t k = 0; k < exported.size() && k < cameras.size(); ++k) {
    const size_t c = static_cast<size_t>(cameras[k]);
    exported[k].cam_from_rig = exported[k].cam_from_rig * (info.rig.cameras[c].cam_from_rig * rig_from_body).Inverse() *
                               given[c] * rig_from_body;
  }
  return exported;
}

void EurocCalibration(const std::string& export_dir, const std::string& run_dir, const DatasetInfo& info,
                      const std::vector<int>& cameras, const std::vector<Rigid3>& given, RunCalibration* out) {
  const fs::path view = fs::path(run_dir) / "input";
  std::vector<ExchangeCamera> exported;
  for (size_t k = 0; k < cameras.size(); ++k) {
    const std::string name = "cam" + std::to_string(k);
    exported.push_back(ReadEurocSensorYaml((fs::path(export_dir) / "mav0" / name / "sensor.yaml").string(), name));
  }
  const std::vector<ExchangeCamera> given_cameras = GivenCameras(exported, info, cameras, given);
  for (const ExchangeCamera& camera : given_cameras) {
    const fs::path from = fs::path(export_dir) / "mav0" / camera.name, to = view / "mav0" / camera.name;
    out->files.emplace_back(
        (to / "sensor.yaml").string(),
        EurocSensorYaml(camera, info.frame_rate, "rovo " + camera.name + ", the run's calibration"));
    out->links.emplace_back((to / "data").string(), (from / "data").string());
    out->links.emplace_back((to / "data.csv").string(), (from / "data.csv").string());
  }
  for (const char* stream : {"state_groundtruth_estimate0", "imu0"}) {
    const fs::path from = fs::path(export_dir) / "mav0" / stream;
    if (fs::exists(from)) out->links.emplace_back((view / "mav0" / stream).string(), from.string());
  }
  out->input = view.string();
  out->calibration = (view / "mav0").string();
}

RunCalibration MakeRunCalibration(const SystemDescription& system, const std::string& dataset_dir,
                                  const std::string& export_dir, const std::string& run_dir, const DatasetInfo& info,
                                  const std::vector<Rigid3>& given) {
  RunCalibration out;
  const std::vector<int> cameras = ExportCameras(system, info.rig.NumCameras());
  if (system.input == "rovo" || system.input == "ros2") {  // ros2: the run's bag is written beside it (WriteRunBag)
    nlohmann::json rig;
    rig["schema_version"] = kRigSchemaVersion;
    rig["source"] = "rovo suite: the extrinsics of this run";
    rig["cameras"] = RigToJson(info.rig.WithExtrinsics(given))["cameras"];
    out.input = system.input == "rovo" ? dataset_dir : (fs::path(run_dir) / "input").string();
    out.calibration = (fs::path(run_dir) / "calibration.json").string();
    out.files.emplace_back(out.calibration, rig.dump(2) + "\n");
  } else if (system.input == "kalibr") {
    const std::vector<ExchangeCamera> c =
        GivenCameras(ReadKalibrCamchain((fs::path(export_dir) / "camchain.yaml").string()), info, cameras, given);
    out.input = export_dir;
    out.calibration = (fs::path(run_dir) / "camchain.yaml").string();
    out.files.emplace_back(out.calibration, KalibrCamchainYaml(c, "rovo suite: the extrinsics of this run"));
  } else if (system.input == "basalt") {
    const std::vector<ExchangeCamera> c =
        GivenCameras(ReadBasaltCalibration((fs::path(export_dir) / "calibration.json").string()), info, cameras, given);
    out.input = export_dir;
    out.calibration = (fs::path(run_dir) / "calibration.json").string();
    out.files.emplace_back(out.calibration, BasaltCalibrationJson(c).dump(4) + "\n");
  } else {
    EurocCalibration(export_dir, run_dir, info, cameras, given, &out);
  }
  std::string all;
  for (const auto& [path, content] : out.files)
    all += fs::path(path).lexically_relative(run_dir).string() + "\n" + content;
  out.hash = HashHex(all.data(), all.size());
  return out;
}

void WriteRunCalibration(const RunCalibration& calibration) {
  for (const auto& [path, content] : calibration.files) WriteFileAtomic(path, content);
  for (const auto& [link, target] : calibration.links) {
    std::error_code ec;
    fs::remove(link, ec);
    fs::create_directories(fs::path(link).parent_path());
    fs::create_symlink(target, link, ec);
    if (ec) throw std::runtime_error(link + ": cannot link to " + target + ": " + ec.message());
  }
}

// input: ros2: the run's own bag, `<run>/input/`, its /tf_static carrying the given extrinsics (a bag has
// no calibration file to swap, so each run gets the whole bag).
void WriteRunBag(const SuitePlan& plan, size_t preset_index, const DatasetInfo& info, const std::vector<Rigid3>& given,
                 const std::string& bag_dir) {
  Ros2ExportOptions options;
  options.out_dir = bag_dir;
  options.cam_from_rig = given;
  ExportRos2Bag(ExportSource(plan, preset_index, info), options);
}

nlohmann::json EnvJson(const std::vector<std::pair<std::string, std::string>>& env) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [key, value] : env) j[key] = value;
  return j;
}

// Whether `run_dir` holds a finished run of this command, environment and calibration.
bool FinishedRunMatches(const std::string& run_dir, const std::vector<std::string>& argv, const nlohmann::json& env,
                        const std::string& calibration_hash) {
  try {
    const nlohmann::json j = ReadJsonFile((fs::path(run_dir) / kSystemRunFile).string());
    return j.at("command") == nlohmann::json(argv) && j.at("env") == env &&
           j.at("calibration_sha") == calibration_hash && j.at("status").is_string();
  } catch (const std::exception&) {
    return false;
  }
}

std::string SignalText(int signal) {
  const char* name = ::strsignal(signal);  // NOLINT(concurrency-mt-unsafe): descriptive text only
  return "signal " + std::to_string(signal) + (name ? std::string(" (") + name + ")" : "");
}

// Status of a child that ran, and the trajectory read back into trajectory.tum when there is one.
void ReadBackTrajectory(const ChildResult& child, const std::string& trajectory_path, const Trajectory& gt,
                        const std::string& run_dir, nlohmann::json* record) {
  std::string status = "ok", detail;
  if (!child.started) {
    status = "not started";
    detail = child.start_error;
  } else if (child.timed_out) {
    status = "timeout";
    detail = "killed after " + Fmt("%g", (*record)["timeout_s"].get<double>()) + " s";
  } else if (child.signal != 0) {
    status = "crashed";
    detail = SignalText(child.signal);
  } else if (child.exit_code != 0) {
    status = "failed";
    detail = "exit status " + std::to_string(child.exit_code);
  } else if (!fs::exists(trajectory_path)) {
    status = "no trajectory";
    detail = trajectory_path + " was not written";
  } else {
    try {
      std::string note;
      const RunData data = ReadRunOrTrajectory(trajectory_path, gt, "auto", &note);
      WriteTum((fs::path(run_dir) / "trajectory.tum").string(), data.trajectory);
      (*record)["trajectory_format"] = note;
    } catch (const std::exception& e) {
      status = "unparsable trajectory";
      detail = e.what();
    }
  }
  (*record)["status"] = status;
  (*record)["status_detail"] = detail;
}

}  // namespace

void PlanSystemRuns(const SuitePlan& plan, size_t preset_index, const std::string& runs_dir, int frame_end,
                    std::vector<SuiteRun>* runs) {
  const SuiteOptions& options = plan.options;
  for (size_t s = 0; s < plan.systems.size(); ++s) {
    const SystemDescription& system = plan.systems[s];
    const auto add = [&](const std::string& name, ExtrinsicsMode mode, int noise_set, int64_t draw_seed) {
      SuiteRun run;
      run.preset_index = preset_index;
      run.system = static_cast<int>(s);
      run.name = name;
      run.run_dir = (fs::path(runs_dir) / "systems" / system.name / name).string();
      run.settings = RunSettings{
          mode, noise_set, draw_seed, options.draw_sigma_deg, frame_end, options.vo_seed, options.MaxNewFeatures()};
      runs->push_back(run);
    };
    add("gt", ExtrinsicsMode::kGroundTruth, 0, -1);
    for (int k = 0; k < options.noise_sets; ++k) {
      add("noisy_" + std::to_string(k), ExtrinsicsMode::kNoisy, k, -1);
      if (system.online_calibration) add("online_" + std::to_string(k), ExtrinsicsMode::kOnline, k, -1);
    }
    const ExtrinsicsMode draw_mode = system.online_calibration ? ExtrinsicsMode::kOnline : ExtrinsicsMode::kNoisy;
    for (int d = 0; d < options.draws; ++d) {
      add("draw_" + std::to_string(d), draw_mode, 0, SuiteDrawSeed(options.scene_seed, options.vo_seed, d));
    }
  }
}

void CheckSuiteSystems(const SuitePlan& plan) {
  for (size_t i = 0; i < plan.systems.size(); ++i) {
    const SystemDescription& system = plan.systems[i];
    for (size_t j = 0; j < i; ++j) {
      if (plan.systems[j].name == system.name) {
        throw std::runtime_error(system.file + ": name: \"" + system.name + "\" is also the name of " +
                                 plan.systems[j].file);
      }
    }
    CheckSystemProgram(system);
  }
}

bool RunSystemRun(const SuitePlan& plan, const SuiteRun& run, int threads, bool quiet) {
  const SystemDescription& system = SystemOf(plan, run);
  const std::string& dataset_dir = plan.dataset_dirs[run.preset_index];
  const DatasetInfo info = ReadDatasetInfo(dataset_dir);
  const bool shared_export = system.input != "rovo" && system.input != "ros2";
  const std::string export_dir = shared_export ? EnsureExport(plan, run.preset_index, system, info) : "";
  const std::string run_dir = fs::absolute(run.run_dir).lexically_normal().string();
  const std::vector<Rigid3> given = GivenExtrinsics(info, run.settings);
  const RunCalibration calibration = MakeRunCalibration(system, fs::absolute(dataset_dir).lexically_normal().string(),
                                                        export_dir, run_dir, info, given);
  const SystemPlaceholders values{calibration.input,
                                  calibration.calibration,
                                  run_dir + "/out",
                                  std::to_string(threads),
                                  std::to_string(plan.options.vo_seed),
                                  SuiteModeName(run.settings.mode)};
  const std::vector<std::string> argv = ExpandCommand(system, values);
  std::vector<std::pair<std::string, std::string>> env;
  for (const auto& [key, value] : system.env)
    env.emplace_back(key, ExpandPlaceholders(value, values, system.file, "env." + key));
  if (FinishedRunMatches(run_dir, argv, EnvJson(env), calibration.hash)) {
    if (!plan.options.quiet) std::fprintf(stderr, "rovo suite: run %s is complete, skipping\n", run_dir.c_str());
    return false;
  }
  std::error_code ec;
  fs::remove_all(run_dir, ec);  // a run of another command or calibration, or an unfinished one
  fs::create_directories(fs::path(run_dir) / "out");
  WriteRunCalibration(calibration);
  if (system.input == "ros2") WriteRunBag(plan, run.preset_index, info, given, calibration.input);
  if (!quiet) std::fprintf(stderr, "rovo suite: %s: %s\n", system.name.c_str(), ShellQuoteWords(argv).c_str());
  ChildSpec spec{argv, env, run_dir + "/stdout.log", run_dir + "/stderr.log", run_dir + "/out", system.timeout_s};
  const ChildResult child = RunChild(spec);
  nlohmann::json record = SystemRunRecordHead(plan, run, system.name, threads);
  record.update(nlohmann::json{{"description", fs::absolute(system.file).lexically_normal().string()},
                               {"command", argv},
                               {"command_line", ShellQuoteWords(argv)},
                               {"env", EnvJson(env)},
                               {"input", calibration.input},
                               {"calibration", calibration.calibration},
                               {"calibration_sha", calibration.hash},
                               {"timeout_s", system.timeout_s},
                               {"exit_code", child.exit_code},
                               {"signal", child.signal},
                               {"timed_out", child.timed_out},
                               {"wall_s", child.wall_s},
                               {"user_cpu_s", child.user_cpu_s},
                               {"system_cpu_s", child.system_cpu_s},
                               {"cpu_s", child.user_cpu_s + child.system_cpu_s},
                               {"peak_rss_mb", child.peak_rss_mb}});
  const std::string trajectory = ExpandPlaceholders(system.trajectory, values, system.file, "trajectory");
  record["trajectory"] = trajectory;
  ReadBackTrajectory(child, trajectory, ReadTum(GroundTruthPath(dataset_dir)), run_dir, &record);
  record["stderr_tail"] = FileTail(run_dir + "/stderr.log", 4000);
  WriteJsonFileAtomic((fs::path(run_dir) / kSystemRunFile).string(), record);
  if (record["status"] != "ok") {
    std::fprintf(stderr, "rovo suite: %s run %s: %s (%s); stderr (%s/stderr.log) ends:\n%s\n", system.name.c_str(),
                 run_dir.c_str(), record["status"].get<std::string>().c_str(),
                 record["status_detail"].get<std::string>().c_str(), run_dir.c_str(),
                 FileTail(run_dir + "/stderr.log", 600).c_str());
  }
  return true;
}

ExternalRunRecord ReadExternalRunRecord(const std::string& run_dir) {
  ExternalRunRecord r;
  try {
    const nlohmann::json j = ReadJsonFile((fs::path(run_dir) / kSystemRunFile).string());
    r.status = j.at("status").get<std::string>();
    r.detail = j.value("status_detail", std::string());
    r.wall_s = j.value("wall_s", 0.0);
    r.cpu_s = j.value("cpu_s", 0.0);
    r.peak_rss_mb = j.value("peak_rss_mb", 0.0);
    std::error_code ec;
    if (r.Ok() && !fs::is_regular_file(fs::path(run_dir) / "trajectory.tum", ec)) {
      r.status = "no trajectory";
      r.detail = "trajectory.tum is missing";
    }
  } catch (const std::exception& e) {
    r.detail = e.what();
  }
  return r;
}

std::optional<RovoRunCost> ReadRovoRunCost(const std::string& run_dir) {
  std::error_code ec;
  const fs::path path = fs::path(run_dir) / kSystemRunFile;
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  try {
    const nlohmann::json j = ReadJsonFile(path.string());
    return RovoRunCost{j.at("wall_s").get<double>(), j.at("cpu_s").get<double>(),
                       j.at("process_maxrss_mb").get<double>()};
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

}  // namespace rovo
