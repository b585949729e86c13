#include "vo/pipeline.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <future>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/dataset_cameras.h"
#include "datasets/io.h"
#include "datasets/lens_angle_scale.h"
#include "datasets/progress.h"
#include "rovo/version.h"
#include "vo/image_loader.h"
#include "vo/startup_calibration.h"
#include "vo/stopwatch.h"

namespace rovo {

namespace {

using Clock = std::chrono::steady_clock;

nlohmann::json PoseJson(const Rigid3& x) {
  return {{"translation", {x.translation.x(), x.translation.y(), x.translation.z()}},
          {"rotation_xyzw", {x.rotation.x(), x.rotation.y(), x.rotation.z(), x.rotation.w()}}};
}

// The frame range and the camera folders: a missing folder is an input error, not lost frames.
void CheckRangeAndFolders(const VoOptions& options, const DatasetInfo& info, int begin, int end) {
  if (begin < 0 || end > info.frame_count || begin >= end) {
    throw std::invalid_argument("vo: --frames " + std::to_string(begin) + ":" + std::to_string(end) +
                                " is not a non-empty range within the dataset's " + std::to_string(info.frame_count) +
                                " frames (" + DatasetJsonPath(options.io.dataset_dir) + ": frame_count)");
  }
  if (options.io.timed_from >= end - begin) {
    throw std::invalid_argument("vo: --timed-from " + std::to_string(options.io.timed_from) + " leaves no frame of " +
                                std::to_string(begin) + ":" + std::to_string(end) + " to time");
  }
  for (const RigCamera& cam : info.rig.cameras) {
    const std::string folder = (std::filesystem::path(options.io.dataset_dir) / cam.name).string();
    if (!std::filesystem::is_directory(folder)) {
      throw std::runtime_error(folder + ": image folder of camera " + cam.name +
                               " (dataset.json rig.cameras) is missing");
    }
  }
}

// GTExt: the rig's; NoisyExt/OnlineExt: a fresh draw (--draw-seed) or a stored perturbed set.
std::vector<Rigid3> StartingExtrinsics(const VoOptions& options, const DatasetInfo& info) {
  std::vector<Rigid3> cam_from_rig = info.rig.Extrinsics();
  if (options.start.mode != ExtrinsicsMode::kGroundTruth && options.start.draw_seed >= 0) {
    cam_from_rig =
        PerturbExtrinsics(info.rig, options.start.draw_sigma_deg, 0.0, static_cast<uint64_t>(options.start.draw_seed))
            .cam_from_rig;
  } else if (options.start.mode != ExtrinsicsMode::kGroundTruth) {
    if (options.start.noise_set < 0 || options.start.noise_set >= static_cast<int>(info.perturbed.size())) {
      throw std::invalid_argument(DatasetJsonPath(options.io.dataset_dir) + ": perturbed[" +
                                  std::to_string(options.start.noise_set) + "] does not exist (the dataset has " +
                                  std::to_string(info.perturbed.size()) + " perturbed extrinsic sets)");
    }
    cam_from_rig = info.perturbed[options.start.noise_set].cam_from_rig;
    if (static_cast<int>(cam_from_rig.size()) != info.rig.NumCameras()) {
      throw std::runtime_error(DatasetJsonPath(options.io.dataset_dir) + ": perturbed[" +
                               std::to_string(options.start.noise_set) + "].cam_from_rig has the wrong camera count");
    }
  }
  return cam_from_rig;
}

bool RunsStartupCalibration(const VoOptions& options) {
  return options.start.mode == ExtrinsicsMode::kOnline && options.startup.enabled;
}

StartupCalibrationReport RunStartupCalibration(const VoOptions& options, const DatasetInfo& info,
                                               const FrameReader& reader, int begin, int end,
                                               const std::vector<Rigid3>& cam_from_rig) {
  StartupCalibrationOptions sopt;
  sopt.shots = options.startup.shots;
  sopt.shot_spacing = options.startup.spacing;
  sopt.max_shots = options.startup.max_shots;
  sopt.min_pair_inliers = options.startup.min_pair_inliers;
  auto load = [&](int frame) { return reader.Load(frame); };
  StartupCalibrationReport startup = CalibrateAtStartup(
      info.rig, cam_from_rig, load, begin, end,
      LoadStaticMasks(options.io.dataset_dir, info.rig, info.has_static_masks), sopt, options.io.quiet);
  if (!startup.converged) {
    std::fprintf(stderr, "vo online: WARNING: start-up calibration not converged: %s\n", startup.status.c_str());
  }
  return startup;
}

// The lenses the VO sees through: the dataset's, or scaled by the converged start-up's angle scale
// (VoStartupOptions::apply_lens_scale); `applied` receives the scale used (1: the dataset's).
Rig LensesForVo(const VoOptions& options, const Rig& rig, const StartupCalibrationReport& startup, double* applied) {
  *applied = 1.0;
  const double scale = startup.ring.angle_scale;
  if (!RunsStartupCalibration(options) || !options.startup.apply_lens_scale || !startup.converged || scale == 1.0) {
    return rig;
  }
  try {
    double error_deg = 0.0;
    Rig scaled = WithLensAngleScale(rig, scale, &error_deg);
    *applied = scale;
    if (!options.io.quiet) {
      std::fprintf(stderr, "vo online: lenses' off-axis angles scaled by the start-up's %.4f (refit within %.3f deg)\n",
                   scale, error_deg);
    }
    return scaled;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "vo online: WARNING: lenses kept as given, the start-up's angle scale %.4f not applied: %s\n",
                 scale, e.what());
    return rig;
  }
}

// Sums of per-frame stage times -> means per frame.
void AverageStageTimes(int frames, int total_hypotheses, VoStageTimes* ms) {
  const double n = std::max(1, frames);
  for (double* v :
       {&ms->warp, &ms->detect, &ms->track, &ms->match, &ms->cpu_warp, &ms->cpu_detect, &ms->cpu_track, &ms->cpu_match,
        &ms->load, &ms->ransac, &ms->refine, &ms->triangulate, &ms->ba, &ms->ba_wait, &ms->backend_total, &ms->total}) {
    *v /= n;
  }
  ms->ransac_us_per_hypothesis = total_hypotheses > 0 ? ms->ransac * n * 1000.0 / total_hypotheses : 0.0;
}

// The stage times of the frames from VoIoOptions::timed_from on, which the summary reports, and of
// the frames before them, which it leaves out.
struct StageSums {
  explicit StageSums(int from_in) : from(from_in) {}
  int from;  // index in the range of the first timed frame
  VoStageTimes timed, untimed;
  int timed_frames = 0, timed_hypotheses = 0;
  VoStageTimes& Of(int index) { return index >= from ? timed : untimed; }
  void Count(int index, int hypotheses) {
    if (index < from) return;
    ++timed_frames;
    timed_hypotheses += hypotheses;
  }
};

// Adds a frame's front-end and back-end stage times to the sums.
void AddStageTimes(const FrontendFrame& features, const BackendFrameResult& result, VoStageTimes* ms) {
  ms->warp += features.ms_warp;
  ms->detect += features.ms_detect;
  ms->track += features.ms_track;
  ms->match += features.ms_match;
  ms->cpu_warp += features.cpu_ms_warp;
  ms->cpu_detect += features.cpu_ms_detect;
  ms->cpu_track += features.cpu_ms_track;
  ms->cpu_match += features.cpu_ms_match;
  ms->ransac += result.ms_ransac;
  ms->refine += result.ms_refine;
  ms->triangulate += result.ms_triangulate;
  ms->ba += result.ms_ba;  // synchronous BA; async BA is counted when it is joined
}

// --preload (bench): every frame decoded before the clock starts, as a live rig delivers images.
std::vector<LoadedFrame> PreloadImages(const VoOptions& options, const FrameReader& reader, int begin, int end) {
  std::vector<LoadedFrame> preloaded;
  Progress load_progress("vo: decoding images", end - begin, "frames", options.io.quiet);
  for (int frame = begin; frame < end; ++frame) {
    preloaded.push_back(reader.Load(frame));
    load_progress.Add();
  }
  load_progress.Finish();
  return preloaded;
}

// Async BA: the records of a keyframe get its BA-refined pose and extrinsics when the BA is joined.
void ApplyBaUpdate(const VoBackend::BaUpdate& update, const std::vector<Rigid3>& cam_from_rig, RunData* run,
                   VoStageTimes* ms) {
  const int num_cams = static_cast<int>(cam_from_rig.size());
  ms->ba += update.ms_solve;
  ms->ba_wait += update.ms_wait;
  for (size_t i = run->frames.size(); i-- > 0;) {
    if (run->frames[i].frame != update.frame) continue;
    run->trajectory[i].world_from_rig = update.world_from_rig;
    for (int j = 0; j < num_cams; ++j) run->extrinsics[i * num_cams + j].cam_from_rig = cam_from_rig[j];
    break;
  }
}

// The front-end's side of a frame: its images (the wait for them) and their features.
struct FrontendStep {
  LoadedFrame loaded;
  FrontendFrame features;
  double ms_load = 0.0;
};

// The front-end's steps, frame by frame in order. With async BA, frame k + 1's step runs on its own
// thread beside frame k's back-end (Start, then Take): it sees the extrinsics it would see in turn, as the
// back-end changes them only when it joins a BA (VoBackend::FinishPendingBa). GTExt and NoisyExt start it
// before that join; OnlineExt starts it before the join too and hands it the joined extrinsics
// (FrontendFeed::SetExtrinsics) for its matching (Frontend::Process with late extrinsics). With
// synchronous BA, the back-end changes them in ProcessFrame, so the steps run in turn (Take computes).
class FrontendFeed {
 public:
  FrontendFeed(const VoOptions& options, const FrameReader& reader, Frontend* frontend, int begin, int end)
      : options_(options),
        frontend_(frontend),
        begin_(begin),
        preloaded_(options.io.preload ? PreloadImages(options, reader, begin, end) : std::vector<LoadedFrame>{}),
        prefetcher_(reader, begin, options.io.preload ? begin : end) {}
  FrontendFeed(const FrontendFeed&) = delete;
  FrontendFeed& operator=(const FrontendFeed&) = delete;
  // A step still waiting for its extrinsics (a back-end step threw) gets std::future_error from its
  // promise, which is broken before the step is joined.
  ~FrontendFeed() { extrinsics_ = std::promise<std::vector<Rigid3>>(); }

  bool overlaps() const { return options_.backend.async_ba; }
  // With `late_extrinsics`, the step asks for its extrinsics (SetExtrinsics below) after its per-view
  // stages. One step at a time: Take the last one first.
  void Start(int frame, bool late_extrinsics) {
    if (!overlaps()) return;
    if (next_.valid()) throw std::logic_error("FrontendFeed::Start: the previous step was not taken");
    std::shared_future<std::vector<Rigid3>> extrinsics;
    if (late_extrinsics) {
      extrinsics_ = std::promise<std::vector<Rigid3>>();
      extrinsics = extrinsics_.get_future().share();
    }
    next_ = std::async(std::launch::async, [this, frame, extrinsics] { return Run(frame, extrinsics); });
  }
  void SetExtrinsics(const std::vector<Rigid3>& cam_from_rig) { extrinsics_.set_value(cam_from_rig); }
  FrontendStep Take(int frame) { return next_.valid() ? next_.get() : Run(frame, {}); }

 private:
  FrontendStep Run(int frame, const std::shared_future<std::vector<Rigid3>>& extrinsics) {
    FrontendStep step;
    const auto start = Clock::now();
    step.loaded = options_.io.preload ? std::move(preloaded_[frame - begin_]) : prefetcher_.Get(frame);
    step.ms_load = MsSince(start);
    if (extrinsics.valid())
      step.features = frontend_->Process(step.loaded.images, [&extrinsics] { return extrinsics.get(); });
    else
      step.features = frontend_->Process(step.loaded.images);
    return step;
  }

  const VoOptions& options_;
  Frontend* frontend_;
  int begin_;
  std::vector<LoadedFrame> preloaded_;
  ImagePrefetcher prefetcher_;
  std::future<FrontendStep> next_;  // joined by its destructor if a back-end step throws
  std::promise<std::vector<Rigid3>> extrinsics_;
};

// The cameras whose image was missing or unreadable, in the record and the summary.
void NoteMissingImages(const LoadedFrame& loaded, FrameRecord* rec, VoSummary* summary) {
  for (int cam : loaded.missing_cameras) {
    rec->missing_cameras += (rec->missing_cameras.empty() ? "" : ";") + std::to_string(cam);
  }
  summary->missing_images += static_cast<int>(loaded.missing_cameras.size());
  summary->frames_with_missing_images += loaded.missing_cameras.empty() ? 0 : 1;
}

// A frame's record, pose and extrinsics (camera j is dataset camera vo_cameras[j]) into the run's files.
void AddToRun(const FrameRecord& rec, const Rigid3& world_from_rig, const std::vector<int>& vo_cameras,
              const std::vector<Rigid3>& cam_from_rig, RunData* run) {
  run->frames.push_back(rec);
  run->trajectory.push_back({rec.timestamp, world_from_rig});
  for (size_t j = 0; j < cam_from_rig.size(); ++j) {
    run->extrinsics.push_back({rec.frame, rec.timestamp, vo_cameras[j], cam_from_rig[j]});
  }
}

// Counts a frame by status; "ok" frames add to the sums of inlier ratio and error.
void CountFrame(const FrameRecord& rec, VoSummary* summary, double* ok_ratio_sum, double* ok_error_sum) {
  ++summary->frames;
  if (rec.status == FrameStatus::kOk) {
    ++summary->frames_ok;
    *ok_ratio_sum += rec.inlier_ratio;
    *ok_error_sum += rec.mean_reproj_error_deg;
  } else if (rec.status == FrameStatus::kInit) {
    ++summary->frames_init;
  } else {
    ++summary->frames_lost;
  }
}

// run.json: every setting, seeds, the start-up calibration and the summary.
nlohmann::json RunInfoJson(const VoOptions& options, const DatasetInfo& info, const BackendOptions& backend_options,
                           const VoSummary& summary, const StartupCalibrationReport& startup, int begin, int end,
                           const Rigid3& world_from_rig0) {
  const std::string dataset_json = ReadFile(DatasetJsonPath(options.io.dataset_dir));
  const VoStageTimes& ms = summary.stage_ms;
  nlohmann::json j = VoOptionsJson(options);  // the registry's fields (vo_options.h)
  j["dataset"] = std::filesystem::absolute(options.io.dataset_dir).lexically_normal().string();
  j["dataset_json_hash"] = HashHex(dataset_json.data(), dataset_json.size());
  j["scene_hash"] = info.scene_hash;
  j["dataset_seed"] = info.seed;
  j["frames"] = {begin, end};
  j["generator"] = "rovo vo";
  j["version"] = ROVO_VERSION;
  j["initial_world_from_rig"] = PoseJson(world_from_rig0);
  j["lens_angle_scale_applied"] = summary.lens_angle_scale;
  if (RunsStartupCalibration(options)) {
    j["startup_calibration"] = startup.ToJson();
    j["startup_calibration"]["ms"] = summary.startup_ms;
    j["startup_calibration"]["cpu_ms"] = summary.startup_cpu_ms;
  }
  // The back-end's other settings (its user-set ones are in the registry's "backend." keys).
  nlohmann::json& backend = j["backend"];
  backend["ransac_max_iterations"] = backend_options.ransac.max_iterations;
  backend["ransac_confidence"] = backend_options.ransac.confidence;
  backend["refine_cauchy_scale_deg"] = backend_options.refine.cauchy_scale_rad * 180.0 / M_PI;
  backend["ba_cauchy_scale_deg"] = backend_options.ba.cauchy_scale_rad * 180.0 / M_PI;
  backend["ba_max_iterations"] = backend_options.ba.max_iterations;
  backend["ba_online_extrinsics"] = backend_options.ba.optimize_extrinsics;
  backend["ba_extrinsic_prior_deg"] = backend_options.ba.extrinsic_prior_deg;
  backend["window_keyframes"] = backend_options.window_keyframes;
  backend["keyframe_max_frame_gap"] = backend_options.keyframes.max_frame_gap;
  backend["online_max_error_deg"] = backend_options.online_max_error_deg;
  j["summary"] = {{"frames", summary.frames},
                  {"frames_ok", summary.frames_ok},
                  {"frames_init", summary.frames_init},
                  {"frames_lost", summary.frames_lost},
                  {"frames_with_missing_images", summary.frames_with_missing_images},
                  {"missing_images", summary.missing_images},
                  {"mean_inlier_ratio", summary.mean_inlier_ratio},
                  {"mean_reproj_error_deg", summary.mean_reproj_error_deg},
                  {"seconds", summary.seconds},
                  {"ms_per_frame", ms.total},
                  {"ms_backend_per_frame", ms.backend_total}};
  return j;
}

// OnlineExt's start-up calibration when it runs: `cam_from_rig` becomes its result and a converged one
// anchors the BA's extrinsics; its wall and CPU time go to `summary`.
StartupCalibrationReport StartUp(const VoOptions& options, const DatasetInfo& info, const FrameReader& reader,
                                 int begin, int end, std::vector<Rigid3>* cam_from_rig, BackendOptions* backend_options,
                                 VoSummary* summary) {
  StartupCalibrationReport startup;
  if (!RunsStartupCalibration(options)) return startup;
  const auto start = Clock::now();
  const double cpu_start = CpuMs();
  startup = RunStartupCalibration(options, info, reader, begin, end, *cam_from_rig);
  summary->startup_ms = MsSince(start);
  summary->startup_cpu_ms = CpuMs() - cpu_start;
  *cam_from_rig = startup.cam_from_rig;
  if (startup.converged) {
    backend_options->ba.extrinsic_anchor = startup.cam_from_rig;
    backend_options->ba.extrinsic_anchor_deg = options.startup.anchor_deg;
    // The centres are held only where the start-up knew them (it turned them by a well-determined turn).
    backend_options->ba.extrinsic_anchor_m = startup.ring.centres_known ? 0.001 * options.startup.anchor_mm : 0.0;
  }
  return startup;
}

// The dataset's ground truth (the first pose gives the metric start); empty without one.
Trajectory GroundTruthIfAny(const std::string& dataset_dir) {
  if (!std::filesystem::exists(GroundTruthPath(dataset_dir))) return {};
  return ReadTum(GroundTruthPath(dataset_dir));
}

// TBB's parallelism capped at `threads` while the result lives (none for 0: all cores).
std::unique_ptr<tbb::global_control> ThreadLimit(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
}

// The dataset's images as the VO reads them: with the lens's lateral colour and relative illumination
// undone unless --lateral-colour off / --flat-field off.
FrameReader VoFrameReader(const VoOptions& options, const DatasetInfo& info) {
  LensCorrections corrections = DatasetLensCorrections(info);
  if (!options.io.undo_lateral_colour) corrections.lateral_colour = {};
  if (!options.io.flat_field) corrections.relative_illumination = {};
  return {options.io.dataset_dir, info.rig, corrections};
}

// The dataset as the VO sees it: only the cameras of --cameras; its camera j is dataset camera
// (*vo_cameras)[j].
DatasetInfo DatasetForVo(const VoOptions& options, std::vector<int>* vo_cameras) {
  DatasetInfo full_info = ReadDatasetInfo(options.io.dataset_dir);
  *vo_cameras = VoCameraIndices(options.io.cameras, full_info.rig);
  if (static_cast<int>(vo_cameras->size()) == full_info.rig.NumCameras()) return full_info;
  return SelectDatasetCameras(full_info, *vo_cameras, "vo: --cameras");
}

}  // namespace

VoSummary RunVo(const VoOptions& options) {
  const auto run_start = Clock::now();
  options.Check();
  std::vector<int> vo_cameras;
  const DatasetInfo info = DatasetForVo(options, &vo_cameras);
  const int begin = options.io.frames.begin;
  const int end = options.io.frames.end < 0 ? info.frame_count : options.io.frames.end;
  CheckRangeAndFolders(options, info, begin, end);
  std::vector<Rigid3> cam_from_rig = StartingExtrinsics(options, info);
  const Trajectory ground_truth = GroundTruthIfAny(options.io.dataset_dir);  // first pose, time stamps
  auto timestamp_of = [&](int frame) {
    return frame < static_cast<int>(ground_truth.size()) ? ground_truth[frame].timestamp : frame / info.frame_rate;
  };
  const Rigid3 world_from_rig0 =
      begin < static_cast<int>(ground_truth.size()) ? ground_truth[begin].world_from_rig : Rigid3::Identity();

  const std::unique_ptr<tbb::global_control> thread_limit = ThreadLimit(options.io.threads);
  EnsureWritableDir(options.io.out_dir);

  BackendOptions backend_options = options.backend;
  backend_options.ba.optimize_extrinsics = options.start.mode == ExtrinsicsMode::kOnline;
  const FrameReader reader = VoFrameReader(options, info);
  VoSummary summary;
  const StartupCalibrationReport startup =
      StartUp(options, info, reader, begin, end, &cam_from_rig, &backend_options, &summary);
  const Rig lenses = LensesForVo(options, info.rig, startup, &summary.lens_angle_scale);
  Frontend frontend(lenses.WithExtrinsics(cam_from_rig), options.frontend);
  frontend.SetStaticMasks(LoadStaticMasks(options.io.dataset_dir, info.rig, info.has_static_masks));
  VoBackend backend(cam_from_rig, world_from_rig0, backend_options);

  RunData run;
  StageSums sums(options.io.timed_from);
  double ok_ratio_sum = 0.0, ok_error_sum = 0.0;
  Progress progress("vo " + ExtrinsicsModeName(options.start.mode), end - begin, "frames", options.io.quiet);
  FrontendFeed feed(options, reader, &frontend, begin, end);
  const bool online = options.start.mode == ExtrinsicsMode::kOnline;
  auto frame_start = Clock::now();
  for (int frame = begin; frame < end; ++frame) {
    const FrontendStep step = feed.Take(frame);  // started beside the previous frame's back-end, or computed now
    VoStageTimes& ms = sums.Of(frame - begin);
    ms.load += step.ms_load;
    if (!step.loaded.problems.empty() && !options.io.quiet) {
      std::fprintf(stderr, "vo: frame %d: %s\n", frame, step.loaded.problems.c_str());
    }
    // The next front-end beside this back-end (async BA); OnlineExt's gets the joined BA's extrinsics.
    if (frame + 1 < end) feed.Start(frame + 1, online);
    auto backend_start = Clock::now();
    if (auto update = backend.FinishPendingBa()) ApplyBaUpdate(*update, backend.cam_from_rig(), &run, &ms);
    ms.backend_total += MsSince(backend_start);
    if (online && frame + 1 < end && feed.overlaps()) feed.SetExtrinsics(backend.cam_from_rig());
    backend_start = Clock::now();
    BackendFrameResult result = backend.ProcessFrame(frame, step.features);
    ms.backend_total += MsSince(backend_start);
    if (online && !feed.overlaps()) frontend.SetExtrinsics(backend.cam_from_rig());
    AddStageTimes(step.features, result, &ms);
    sums.Count(frame - begin, result.ransac_hypotheses);

    FrameRecord rec = result.record;
    NoteMissingImages(step.loaded, &rec, &summary);
    rec.frame = frame;
    rec.timestamp = timestamp_of(frame);
    rec.time_ms = MsSince(frame_start);  // from the previous frame's end: the sum is the loop's time
    frame_start = Clock::now();
    ms.total += rec.time_ms;
    CountFrame(rec, &summary, &ok_ratio_sum, &ok_error_sum);
    AddToRun(rec, result.world_from_rig, vo_cameras, backend.cam_from_rig(), &run);
    progress.Add();
  }
  if (auto update = backend.FinishPendingBa()) ApplyBaUpdate(*update, backend.cam_from_rig(), &run, &sums.timed);
  progress.Finish();
  AverageStageTimes(sums.timed_frames, sums.timed_hypotheses, &sums.timed);
  summary.stage_ms = sums.timed;
  summary.mean_inlier_ratio = summary.frames_ok > 0 ? ok_ratio_sum / summary.frames_ok : 0.0;
  summary.mean_reproj_error_deg = summary.frames_ok > 0 ? ok_error_sum / summary.frames_ok : 0.0;
  summary.seconds = std::chrono::duration<double>(Clock::now() - run_start).count();
  run.info = RunInfoJson(options, info, backend_options, summary, startup, begin, end, world_from_rig0);
  run.info["vo_cameras"] = vo_cameras;
  WriteRun(options.io.out_dir, run);
  return summary;
}

}  // namespace rovo
