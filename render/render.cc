#include "render/render.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <deque>
#include <exception>
#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "render/image_io.h"
#include "render/tracer.h"
#include "rovo/version.h"
#include "scenes/city.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

uint64_t SplitMix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// One rendered frame on its way to the writer thread.
struct FrameJob {
  int dataset_frame = 0;
  std::vector<CameraImage> images;
};

// Encodes and writes frames beside the tracer; at most kCapacity frames wait in memory, and as many
// written ones are kept for the tracer to render into again (Reuse).
class FrameWriter {
 public:
  FrameWriter(const std::string& out_dir, const Rig& rig, bool depth, bool masks, Progress* progress)
      : out_dir_(out_dir), rig_(rig), depth_(depth), masks_(masks), progress_(progress), thread_([this] { Run(); }) {}
  // Joins without rethrowing (the error was or will be reported by Push/Close).
  ~FrameWriter() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
      ready_.notify_one();
    }
    if (thread_.joinable()) thread_.join();
  }

  // Blocks while the queue is full; rethrows a writer error.
  void Push(FrameJob job) {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [&] { return queue_.size() < kCapacity || error_; });
    if (error_) std::rethrow_exception(error_);
    queue_.push_back(std::move(job));
    ready_.notify_one();
  }

  // A written frame's job, whose image buffers are allocated already (their pages stay mapped from
  // frame to frame), or a new one.
  FrameJob Reuse() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (written_.empty()) return FrameJob();
    FrameJob job = std::move(written_.back());
    written_.pop_back();
    return job;
  }

  // Waits for all pending frames; rethrows a writer error.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
      ready_.notify_one();
    }
    if (thread_.joinable()) thread_.join();
    if (error_) {
      std::exception_ptr e = error_;
      error_ = nullptr;
      std::rethrow_exception(e);
    }
  }

 private:
  static constexpr size_t kCapacity = 2;

  void Run() {
    for (;;) {
      FrameJob job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [&] { return !queue_.empty() || closing_; });
        if (queue_.empty()) return;
        job = std::move(queue_.front());
        queue_.pop_front();
        space_.notify_one();
      }
      try {
        Write(job);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
        queue_.clear();
        space_.notify_all();
        return;
      }
      if (progress_) progress_->Add(1);
      std::lock_guard<std::mutex> lock(mutex_);
      if (written_.size() < kCapacity) written_.push_back(std::move(job));
    }
  }

  // Images last: depth and masks first, so that the frame's files appear together at the end.
  void Write(const FrameJob& job) {
    for (int c = 0; c < rig_.NumCameras(); ++c) {
      const CameraImage& image = job.images[c];
      const std::string& name = rig_.cameras[c].name;
      if (depth_) WriteExrFloat(DepthPath(out_dir_, name, job.dataset_frame), image.width, image.height, image.depth);
      if (masks_) WritePngGray16(MaskPath(out_dir_, name, job.dataset_frame), image.width, image.height, image.mask);
    }
    for (int c = 0; c < rig_.NumCameras(); ++c) {
      const CameraImage& image = job.images[c];
      const std::string path = ImagePath(out_dir_, rig_.cameras[c].name, job.dataset_frame);
      if (!image.gray.empty()) {
        WritePngGray8(path, image.width, image.height, image.gray);  // a grayscale sensor
      } else {
        WritePngRgb8(path, image.width, image.height, image.rgb);
      }
    }
  }

  std::string out_dir_;
  Rig rig_;
  bool depth_, masks_;
  Progress* progress_;
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<FrameJob> queue_;
  std::vector<FrameJob> written_;  // at most kCapacity, for Reuse
  bool closing_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

// Checks that an existing dataset.json describes the same rendering; throws naming the field.
void CheckExistingDataset(const std::string& out_dir, const DatasetInfo& info) {
  if (!fs::exists(DatasetJsonPath(out_dir))) return;
  const DatasetInfo old = ReadDatasetInfo(out_dir);
  const std::string file = DatasetJsonPath(out_dir);
  auto differ = [&](const std::string& field) {
    throw std::runtime_error(
        file + ": field '" + field +
        "' differs from this render's settings; the folder holds another dataset (use a new --out)");
  };
  if (old.scene_hash != info.scene_hash) differ("scene_hash");
  if (old.frame_count != info.frame_count) differ("frame_count");
  if (old.seed != info.seed) differ("seed");
  if (old.has_depth != info.has_depth) differ("has_depth");
  if (old.has_masks != info.has_masks) differ("has_masks");
  if (old.sensor.has_value() != info.sensor.has_value() || (old.sensor && *old.sensor != *info.sensor))
    differ("sensor");
  if (old.timing.has_value() != info.timing.has_value() || (old.timing && !old.timing->SameExposure(*info.timing)))
    differ("timing");
  // A record without `sampling` resumes with any sampling.
  if (old.timing && old.timing->spp > 0 && *old.timing != *info.timing) differ("timing/sampling");
  if (old.optics.has_value() != info.optics.has_value() || (old.optics && *old.optics != *info.optics))
    differ("optics");
  if (old.rig.NumCameras() != info.rig.NumCameras()) differ("rig/cameras");
  for (int c = 0; c < info.rig.NumCameras(); ++c) {
    const Camera& a = old.rig.cameras[c].camera;
    const Camera& b = info.rig.cameras[c].camera;
    if (a.width != b.width || a.height != b.height || a.model != b.model) differ("rig/cameras/" + std::to_string(c));
  }
}

}  // namespace

Scene SceneForOptions(const std::string& preset, bool quick, uint64_t seed, const std::string& scene_dir) {
  if (preset.empty() == scene_dir.empty())
    throw std::invalid_argument("give exactly one of --preset NAME or --scene DIR");
  if (!preset.empty()) {
    FindScenePreset(preset);  // throws listing the valid names
    return GenerateScene(preset, seed, quick);
  }
  if (!fs::is_directory(scene_dir)) throw std::runtime_error(scene_dir + ": scene folder does not exist");
  return LoadScene(scene_dir);
}

RigChoice ChooseRig(const std::string& rig, const Scene& scene, const std::string& scene_dir, double scale) {
  if (scale < 0.0 || scale > 4.0)
    throw std::invalid_argument("--scale " + std::to_string(scale) + ": must be in (0, 4]");
  const std::string scene_rig_json = scene_dir.empty() ? "" : (fs::path(scene_dir) / "rig.json").string();
  RigChoice choice;
  if (!rig.empty() && EndsWith(rig, ".json")) {
    if (!fs::exists(rig)) throw std::runtime_error(rig + ": rig file does not exist");
    choice.rig = ReadRigJson(rig);
    choice.source = rig + " (--rig)";
  } else if (!rig.empty()) {
    choice.rig = MakeRigPreset(rig);
    choice.source = "preset " + rig + " (--rig)";
  } else if (!scene_rig_json.empty() && fs::exists(scene_rig_json)) {
    choice.rig = ReadRigJson(scene_rig_json);
    choice.source = scene_rig_json + " (the scene's rig.json)";
  } else if (!scene.rig_preset.empty()) {
    choice.rig = MakeRigPreset(scene.rig_preset);
    choice.source = "preset " + scene.rig_preset + " (the scene's rig_preset)";
  } else {
    choice.rig = MakeRigPreset("rovo4");
    choice.source = "preset rovo4 (the default: the scene names no rig)";
  }
  if (scale > 0.0 && scale != 1.0) choice.rig = choice.rig.Scaled(scale);
  choice.rig.Check("rig from " + choice.source);
  return choice;
}

Rig RigForOptions(const std::string& rig, const Scene& scene, double scale, const std::string& scene_dir) {
  return ChooseRig(rig, scene, scene_dir, scale).rig;
}

std::string DescribeRigChoice(const RigChoice& choice) {
  std::string cameras;
  for (const RigCamera& cam : choice.rig.cameras) {
    const std::string one = CameraModelName(cam.camera.model) + " " + std::to_string(cam.camera.width) + "x" +
                            std::to_string(cam.camera.height);
    if (cameras.find(one) == std::string::npos) cameras += (cameras.empty() ? "" : ", ") + one;
  }
  return "rig: " + choice.source + ": " + std::to_string(choice.rig.NumCameras()) + " cameras, " + cameras;
}

bool FrameComplete(const std::string& out_dir, const Rig& rig, int frame, bool depth, bool masks) {
  std::error_code ec;
  for (const RigCamera& cam : rig.cameras) {
    if (!fs::exists(ImagePath(out_dir, cam.name, frame), ec)) return false;
    if (depth && !fs::exists(DepthPath(out_dir, cam.name, frame), ec)) return false;
    if (masks && !fs::exists(MaskPath(out_dir, cam.name, frame), ec)) return false;
  }
  return true;
}

namespace {

// Option checks that need no scene; throws naming the option.
void CheckRenderOptions(const RenderOptions& options) {
  if (options.out_dir.empty()) throw std::invalid_argument("--out: an output folder is required");
  if (options.shard_count < 1 || options.shard_index < 0 || options.shard_index >= options.shard_count)
    throw std::invalid_argument("--shard " + std::to_string(options.shard_index) + "/" +
                                std::to_string(options.shard_count) + ": need 0 <= I < N");
  if (options.spp < 0 || options.spp > 1024) throw std::invalid_argument("--spp: must be in [1, 1024]");
  if (options.threads < 0) throw std::invalid_argument("--threads: must be >= 0");
  if (!(options.vignetting >= 0.0f && options.vignetting <= 1.0f))
    throw std::invalid_argument("--vignetting must be in [0, 1]");
  options.sensor.Check();
  options.optics.Check();
  if (options.optics.enabled && !options.sensor.enabled)
    throw std::invalid_argument(
        "--optics " + options.optics.profile +
        ": the lens model works on the sensor model's linear image; add --sensor (or --realistic)");
  if (options.imu) options.imu_settings.Check();
}

// The scene has a trajectory and every dynamic object has one pose per trajectory frame.
void CheckSceneMotion(const Scene& scene, const std::string& scene_name) {
  const size_t num_traj = scene.rig_trajectory.size();
  if (num_traj == 0) throw std::runtime_error(scene_name + ": trajectory: the scene has no rig poses");
  for (const Object& obj : scene.objects) {
    if (obj.IsDynamic() && obj.world_from_object_per_frame.size() != num_traj)
      throw std::runtime_error(scene_name + ": object '" + obj.name +
                               "': " + std::to_string(obj.world_from_object_per_frame.size()) +
                               " motion frames for a trajectory of " + std::to_string(num_traj));
  }
}

// The sensor model's per-render state: camera sensitivities, the meter of every dataset frame and
// camera, and the exposure schedule (empty without the sensor model).
struct SensorPlan {
  std::vector<double> sensitivity;
  std::vector<std::vector<double>> meter;
  std::vector<std::vector<CameraExposure>> exposure;
  std::vector<double> trigger_offset_ms;  // per camera (timing; empty when timing is off)
  std::vector<double> mtf50_factor;       // per camera (optics; empty when the lens is ideal)
  // The dataset's continuous-time ground truth, which timing and the IMU sample (timing or IMU on).
  std::optional<ContinuousTrajectory> rig_motion;
  std::optional<ImuStreams> imu;  // the IMU's streams and record (--imu)
  ImuRecord imu_record;
};

// The lens's relative illumination (render/optics.h) on a linear render of `rays`' camera.
void ApplyIllumination(const OpticsSettings& optics, const CameraRays& rays, std::vector<float>* linear) {
  const double theta_max = rays.camera.max_fov_deg * M_PI / 360.0;
  for (size_t i = 0; i < rays.valid.size(); ++i) {
    if (!rays.valid[i]) continue;
    const Eigen::Vector3f& b = rays.bearing[i];
    const auto e = static_cast<float>(
        LensRelativeIllumination(optics, std::atan2(std::hypot(b.x(), b.y()), static_cast<double>(b.z())), theta_max));
    for (int k = 0; k < 3; ++k) (*linear)[i * 3 + k] *= e;
  }
}

// The auto-exposure meter of dataset frames [0, count) (trajectory frames begin + f): per camera a
// 1-spp linear render with the sun, sensor.meter_width pixels wide (at most the image width), and
// its MeterLuminance.
std::vector<std::vector<double>> MeterFrames(const RenderOptions& options, const Scene& scene, const Rig& rig,
                                             int begin, int count, tbb::task_arena& arena, Tracer& tracer) {
  RigCameraRays rays;
  arena.execute([&] {
    std::vector<Camera> cameras;
    for (const RigCamera& cam : rig.cameras) {
      Rig one;
      one.cameras = {cam};
      const double scale = std::min(1.0, static_cast<double>(options.sensor.meter_width) / cam.camera.width);
      cameras.push_back(scale < 1.0 ? one.Scaled(scale).cameras[0].camera : cam.camera);
    }
    rays = MakeCameraRays(cameras, 0, 1);
  });
  ShadeSettings settings;
  settings.spp = 1;
  settings.vignetting = options.vignetting;
  settings.linear_output = true;
  settings.sun_disc = true;
  settings.sun_aureole = true;
  std::vector<std::vector<double>> meter(count, std::vector<double>(rig.NumCameras(), 0.0));
  Progress progress("meter " + options.out_dir, count, "frames", options.quiet);
  CameraImage image;
  for (int f = 0; f < count; ++f) {
    const Rigid3& world_from_rig = scene.rig_trajectory[begin + f].world_from_rig;
    arena.execute([&] {
      tracer.SetFrame(begin + f);
      for (int c = 0; c < rig.NumCameras(); ++c) {
        tracer.Render(*rays[c], world_from_rig * rig.cameras[c].cam_from_rig.Inverse(), settings, &image);
        if (options.optics.enabled) ApplyIllumination(options.optics, *rays[c], &image.linear);
        meter[f][c] = MeterLuminance(image.linear, rays[c]->bearing, rays[c]->valid, options.sensor.ae_target);
      }
    });
    progress.Add(1);
  }
  progress.Finish();
  return meter;
}

// Sensitivities, meter and exposure schedule of a render with the sensor model (else empty), and the
// cameras' MTF50 factors with the lens model.
SensorPlan PlanSensor(const RenderOptions& options, const Scene& scene, const Rig& rig, int begin, int count,
                      tbb::task_arena& arena, Tracer& tracer) {
  SensorPlan plan;
  if (!options.sensor.enabled) return plan;
  if (options.optics.enabled) plan.mtf50_factor = CameraMtf50Factors(options.optics, rig.NumCameras(), options.seed);
  plan.sensitivity = CameraSensitivities(options.sensor, rig.NumCameras(), options.seed);
  plan.meter = MeterFrames(options, scene, rig, begin, count, arena, tracer);
  plan.exposure = ExposureSchedule(options.sensor, plan.meter, scene.frame_rate);
  return plan;
}

// dataset.json of `count` frames rendered with `rig`.
DatasetInfo MakeDatasetInfo(const RenderOptions& options, const Scene& scene, const Rig& rig, int count,
                            const SensorPlan& plan) {
  DatasetInfo info;
  info.generator = "rovo render";
  info.generator_version = ROVO_VERSION;
  info.seed = options.seed;
  info.preset = options.preset.empty() ? scene.metadata.preset : options.preset;
  info.scene_hash = SceneHash(scene);
  info.frame_rate = scene.frame_rate;
  info.frame_count = count;
  info.rig = rig;
  for (int k = 0; k < kNumPerturbedSets; ++k) {
    info.perturbed.push_back(PerturbExtrinsics(rig, 5.0, 0.0, SplitMix(options.seed * 1000003ull + 17 + k)));
  }
  info.has_depth = options.depth;
  info.has_masks = options.masks;
  if (options.sensor.enabled) info.sensor = MakeSensorRecord(options.sensor, plan.sensitivity);
  if (options.timing.Enabled()) info.timing = MakeTimingRecord(options.timing, plan.trigger_offset_ms);
  if (options.optics.enabled) info.optics = MakeOpticsRecord(options.optics, plan.mtf50_factor);
  // A dataset's rig carries the IMU mount exactly when the dataset has an IMU.
  info.rig.imu_from_rig.reset();
  if (plan.imu) {
    info.rig.imu_from_rig = rig.imu_from_rig.value_or(PresetImuFromRig());
    info.imu = plan.imu_record;
  }
  return info;
}

// The timing record's samples per pixel.
void RecordSampling(int spp, const AdaptiveSampling& adaptive, TimingRecord* timing) {
  timing->spp = spp;
  const bool on = AdaptiveApplies(adaptive, spp);
  timing->min_spp = on ? adaptive.min_spp : spp;
  timing->threshold_codes = on ? std::round(adaptive.threshold * 255.0 * 1e6) / 1e6 : 0.0;
}

void PrepareDir(const std::string& file_in_dir) {
  const std::string dir = fs::path(file_in_dir).parent_path().string();
  EnsureWritableDir(dir);
  RemoveStaleTempFiles(dir);
}

// The output folder, its whole-range files (identical from every shard) and the per-camera folders.
void PrepareOutput(const RenderOptions& options, const DatasetInfo& info, const Trajectory& groundtruth,
                   const SensorPlan& plan) {
  EnsureWritableDir(options.out_dir);
  CheckExistingDataset(options.out_dir, info);
  WriteTum(GroundTruthPath(options.out_dir), groundtruth);
  if (options.sensor.enabled) {
    std::vector<std::string> names;
    for (const RigCamera& cam : info.rig.cameras) names.push_back(cam.name);
    WriteExposureCsv(ExposurePath(options.out_dir),
                     MakeExposureRows(options.sensor, plan.exposure, plan.meter, plan.sensitivity, names));
  }
  if (plan.imu) {
    WriteImuStreams(options.out_dir, *plan.imu);
  } else {
    // A render without --imu into a folder rendered with it (resume): the IMU files go with the record.
    std::error_code ec;
    for (const std::string& path :
         {ImuDataPath(options.out_dir), ImuExactPath(options.out_dir), ImuBiasPath(options.out_dir)})
      fs::remove(path, ec);
    fs::remove(fs::path(ImuDataPath(options.out_dir)).parent_path(), ec);  // only when empty
  }
  WriteDatasetInfo(options.out_dir, info);
  for (const RigCamera& cam : info.rig.cameras) {
    PrepareDir(ImagePath(options.out_dir, cam.name, 0));
    if (options.depth) PrepareDir(DepthPath(options.out_dir, cam.name, 0));
    if (options.masks) PrepareDir(MaskPath(options.out_dir, cam.name, 0));
  }
}

// Dataset frames of this shard that are not complete on disk; counts the shard's frames in `summary`.
std::vector<int> FramesToRender(const RenderOptions& options, const Rig& rig, int count, RenderSummary* summary) {
  std::vector<int> todo;
  for (int f = 0; f < count; ++f) {
    if ((f / kShardChunkFrames) % options.shard_count != options.shard_index) continue;
    ++summary->frames_total;
    if (FrameComplete(options.out_dir, rig, f, options.depth, options.masks)) {
      ++summary->frames_skipped;
      continue;
    }
    todo.push_back(f);
  }
  return todo;
}

// Exposure times (ms) of dataset frame f's cameras for the motion blur: the fixed shutter, the
// sensor's exposure, or zeros.
std::vector<double> ShutterMs(const TimingSettings& timing, const SensorPlan& plan, int f, int num_cameras) {
  std::vector<double> shutter(num_cameras, timing.shutter_ms);
  if (timing.shutter_from_sensor)
    for (int c = 0; c < num_cameras; ++c) shutter[c] = plan.exposure[f][c].exposure_ms;
  return shutter;
}

// Timing needs the trajectory around every frame: the window of each frame (HalfWindowSeconds)
// must stay within its neighbouring trajectory intervals, so that the three motion steps of the
// dynamic objects (Tracer::SetFrameWindow) hold the exact poses. Throws naming the options.
void CheckTimingWindows(const RenderOptions& options, const Scene& scene, int begin, int count, const SensorPlan& plan,
                        int num_cameras) {
  const Trajectory& traj = scene.rig_trajectory;
  for (int f = 0; f < count; ++f) {
    const int i = begin + f;
    const double h = HalfWindowSeconds(plan.trigger_offset_ms, options.timing.rolling_shutter_ms,
                                       ShutterMs(options.timing, plan, f, num_cameras));
    double room = std::numeric_limits<double>::infinity();
    if (i > 0) room = std::min(room, traj[i].timestamp - traj[i - 1].timestamp);
    if (i + 1 < static_cast<int>(traj.size())) room = std::min(room, traj[i + 1].timestamp - traj[i].timestamp);
    if (h > room)
      throw std::invalid_argument("--shutter-ms/--motion-blur, --rolling-shutter-ms, --trigger-offset(s)-ms: frame " +
                                  std::to_string(i) + " is exposed up to " + std::to_string(h * 1000.0) +
                                  " ms from its time, beyond the trajectory interval of " +
                                  std::to_string(room * 1000.0) + " ms");
  }
}

// The continuous-time ground truth of the dataset's poses, the trigger offsets and the IMU streams
// (timing or IMU on); throws naming the options when the poses cannot make one.
void PlanMotion(const RenderOptions& options, const Scene& scene, const Rig& rig, const Trajectory& groundtruth,
                int begin, SensorPlan* plan) {
  if (!options.timing.Enabled() && !options.imu) return;
  try {
    plan->rig_motion.emplace(groundtruth);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(
        std::string(options.imu ? "--imu" : "--shutter-ms/--rolling-shutter-ms/--trigger-offset") + ": " + e.what());
  }
  if (options.timing.Enabled()) {
    plan->trigger_offset_ms = TriggerOffsetsMs(options.timing, rig.NumCameras(), options.seed);
    CheckTimingWindows(options, scene, begin, static_cast<int>(groundtruth.size()), *plan, rig.NumCameras());
  }
  if (options.imu) {
    plan->imu = SimulateImu(*plan->rig_motion, rig.imu_from_rig.value_or(PresetImuFromRig()), options.imu_settings,
                            options.seed, &plan->imu_record);
  }
}

// The settings of camera c at dataset frame f: with adaptive sampling and the sensor model, the factor
// from linear radiance to the sensor's full scale, K q_c t G / FWC (render/sensor.h).
ShadeSettings CameraShadeSettings(const ShadeSettings& settings, const RenderOptions& options, const SensorPlan& plan,
                                  int f, int c) {
  ShadeSettings out = settings;
  if (settings.adaptive.enabled && options.sensor.enabled) {
    const CameraExposure& e = plan.exposure[f][c];
    out.adaptive.output_scale = static_cast<float>(options.sensor.sensitivity_e_per_ms * plan.sensitivity[c] *
                                                   e.exposure_ms * e.gain / options.sensor.full_well_e);
  }
  return out;
}

// The images of one frame with timing (render/timing.h): the dynamic objects over the frame's
// window (the scene's motion), each camera at its own times (the rig from the dataset's poses).
void RenderTimedFrame(const RenderOptions& options, const Rig& rig, int traj_frame, int f, const SensorPlan& plan,
                      const RigCameraRays& rays, const ShadeSettings& settings, Tracer& tracer,
                      std::vector<float>* linear, const SensorPipeline* pipeline, const std::vector<LensOptics>& lenses,
                      FrameJob* job) {
  const std::vector<double> shutter = ShutterMs(options.timing, plan, f, rig.NumCameras());
  const double h = HalfWindowSeconds(plan.trigger_offset_ms, options.timing.rolling_shutter_ms, shutter);
  tracer.SetFrameWindow(traj_frame, h);
  for (int c = 0; c < rig.NumCameras(); ++c) {
    Rigid3 world_from_cam;
    const CameraMotion motion =
        MakeCameraMotion(*plan.rig_motion, f, rig.cameras[c].cam_from_rig, h > 0.0 ? h : 1.0, plan.trigger_offset_ms[c],
                         shutter[c], options.timing.rolling_shutter_ms, rays[c]->height, &world_from_cam);
    CameraImage& image = job->images[c];
    if (pipeline) image.linear.swap(*linear);
    tracer.Render(*rays[c], world_from_cam, CameraShadeSettings(settings, options, plan, f, c), &image, &motion);
    if (!pipeline) continue;
    if (!lenses.empty()) lenses[c].Apply(&image.linear);
    pipeline->Apply(image.linear, rays[c]->valid, plan.exposure[f][c], plan.sensitivity[c],
                    SensorNoiseSeed(options.seed, f, c), options.sensor.grayscale ? &image.gray : &image.rgb);
    image.linear.swap(*linear);
  }
}

// Renders the dataset frames `todo` (trajectory frames begin + f) and writes them beside the tracer.
void RenderFrames(const RenderOptions& options, const Scene& scene, const Rig& rig, int begin,
                  const std::vector<int>& todo, int spp, const AdaptiveSampling& adaptive, const SensorPlan& plan,
                  tbb::task_arena& arena, Tracer& tracer, RenderSummary* summary) {
  RigCameraRays rays;
  arena.execute([&] {
    std::vector<Camera> cameras;
    for (const RigCamera& cam : rig.cameras) cameras.push_back(cam.camera);
    // Adaptive sampling takes its own sample positions: no table of the fixed pattern's bearings.
    rays = MakeCameraRays(cameras, 0, AdaptiveApplies(adaptive, spp) ? 1 : spp);
  });

  ShadeSettings settings;
  settings.spp = spp;
  settings.want_depth = options.depth;
  settings.want_mask = options.masks;
  settings.vignetting = options.vignetting;
  settings.adaptive = adaptive;
  // The sensor model: the tracer hands over linear radiance (with the sun), the pipeline makes the image.
  const bool sensor = options.sensor.enabled;
  settings.linear_output = sensor;
  settings.sun_disc = sensor;
  settings.sun_aureole = sensor;
  std::optional<SensorPipeline> pipeline;
  if (sensor) pipeline.emplace(options.sensor);
  std::vector<LensOptics> lenses;
  if (options.optics.enabled) {
    arena.execute([&] {
      for (int c = 0; c < rig.NumCameras(); ++c)
        lenses.emplace_back(options.optics, rig.cameras[c].camera, rays[c]->bearing, rays[c]->valid,
                            plan.mtf50_factor[c]);
    });
  }
  std::vector<float> linear;  // reused between images

  Progress progress("render " + options.out_dir, static_cast<int64_t>(todo.size()), "frames", options.quiet);
  {
    FrameWriter writer(options.out_dir, rig, options.depth, options.masks, &progress);
    for (int f : todo) {
      const int traj_frame = begin + f;
      const Rigid3& world_from_rig = scene.rig_trajectory[traj_frame].world_from_rig;
      FrameJob job = writer.Reuse();
      job.dataset_frame = f;
      job.images.resize(rig.NumCameras());
      arena.execute([&] {
        if (options.timing.Enabled()) {
          RenderTimedFrame(options, rig, traj_frame, f, plan, rays, settings, tracer, &linear,
                           pipeline ? &*pipeline : nullptr, lenses, &job);
          return;
        }
        tracer.SetFrame(traj_frame);
        for (int c = 0; c < rig.NumCameras(); ++c) {
          const Rigid3 world_from_cam = world_from_rig * rig.cameras[c].cam_from_rig.Inverse();
          CameraImage& image = job.images[c];
          if (sensor) image.linear.swap(linear);
          tracer.Render(*rays[c], world_from_cam, CameraShadeSettings(settings, options, plan, f, c), &image);
          if (!sensor) continue;
          if (!lenses.empty()) lenses[c].Apply(&image.linear);
          pipeline->Apply(image.linear, rays[c]->valid, plan.exposure[f][c], plan.sensitivity[c],
                          SensorNoiseSeed(options.seed, f, c), options.sensor.grayscale ? &image.gray : &image.rgb);
          image.linear.swap(linear);
        }
      });
      writer.Push(std::move(job));
      ++summary->frames_rendered;
    }
    writer.Close();
  }
  progress.Finish();
}

}  // namespace

AdaptiveSampling RenderAdaptiveSampling(const RenderOptions& options, int spp, bool defaulted) {
  if (options.adaptive != "auto" && options.adaptive != "on" && options.adaptive != "off")
    throw std::invalid_argument("--adaptive " + options.adaptive + ": expected auto, on or off");
  if (!(options.adaptive_threshold_codes >= 0.0 && options.adaptive_threshold_codes <= 255.0))
    throw std::invalid_argument("--adaptive-threshold " + std::to_string(options.adaptive_threshold_codes) +
                                ": expected 8-bit codes in [0, 255]");
  AdaptiveSampling adaptive;
  adaptive.enabled = options.adaptive == "on" || (options.adaptive == "auto" && defaulted && spp == kDefaultBlurSpp);
  adaptive.min_spp = kDefaultSpp;
  if (options.adaptive == "on" && !options.timing.Enabled())
    throw std::invalid_argument(
        "--adaptive on: needs timing (--shutter-ms, --motion-blur, --rolling-shutter-ms or "
        "--trigger-offset-ms), whose record in dataset.json states the sampling");
  if (options.adaptive == "on" && !AdaptiveApplies(adaptive, spp))
    throw std::invalid_argument("--adaptive on: --spp " + std::to_string(spp) + " must be a power of two in [" +
                                std::to_string(2 * kDefaultSpp) + ", 64]");
  const double codes =
      options.adaptive_threshold_codes > 0.0 ? options.adaptive_threshold_codes : kAdaptiveThresholdCodes;
  adaptive.threshold = static_cast<float>(codes / 255.0);
  return adaptive;
}

int DefaultSpp(const TimingSettings& timing, const std::vector<std::vector<CameraExposure>>& exposure) {
  if (timing.shutter_ms > 0.0) return kDefaultBlurSpp;
  if (!timing.shutter_from_sensor) return kDefaultSpp;
  for (const auto& frame : exposure)
    for (const CameraExposure& e : frame)
      if (e.exposure_ms >= kBlurSppMinExposureMs) return kDefaultBlurSpp;
  return kDefaultSpp;
}

RenderSummary RenderDataset(const RenderOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  // ---- Validate everything before writing anything.
  CheckRenderOptions(options);
  const Scene scene = SceneForOptions(options.preset, options.quick, options.seed, options.scene_dir);
  const std::string scene_name = options.preset.empty() ? options.scene_dir : "preset " + options.preset;
  CheckSceneMotion(scene, scene_name);
  const int num_traj = static_cast<int>(scene.rig_trajectory.size());
  double scale = options.scale;
  if (scale == 0.0)
    scale = options.quick && !options.preset.empty() ? FindScenePreset(options.preset).quick_scale : 1.0;
  const RigChoice rig_choice = ChooseRig(options.rig, scene, options.scene_dir, scale);
  const Rig& rig = rig_choice.rig;

  const int begin = options.frame_begin;
  const int end = options.frame_end < 0 ? num_traj : options.frame_end;
  if (begin < 0 || begin >= end || end > num_traj)
    throw std::out_of_range("--frames " + std::to_string(begin) + ":" + std::to_string(options.frame_end) +
                            ": outside the trajectory of " + scene_name + " (frames 0:" + std::to_string(num_traj) +
                            ")");
  const int count = end - begin;
  const SensorSettings& sensor = options.sensor;
  if (sensor.enabled && !sensor.auto_exposure && sensor.exposure_ms > 1000.0 / scene.frame_rate)
    throw std::invalid_argument("--exposure-ms " + std::to_string(sensor.exposure_ms) +
                                ": longer than the frame period of " + scene_name + " (" +
                                std::to_string(1000.0 / scene.frame_rate) + " ms)");
  const Trajectory groundtruth(scene.rig_trajectory.begin() + begin, scene.rig_trajectory.begin() + end);
  RenderSummary summary;
  summary.rig = DescribeRigChoice(rig_choice);
  if (!options.quiet) std::fprintf(stderr, "%s\n", summary.rig.c_str());  // before the long part

  options.timing.Check(rig.NumCameras(), sensor.enabled);
  if (options.timing.Enabled() && count < 2)
    throw std::invalid_argument("--frames " + std::to_string(begin) + ":" + std::to_string(end) +
                                ": timing needs at least 2 frames (the rig between frames comes from groundtruth.tum)");

  // The build of the tracer validates the scene's indices (before any output).
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  std::unique_ptr<Tracer> tracer;
  arena.execute([&] { tracer = std::make_unique<Tracer>(scene); });
  // The sensor model's exposure schedule covers every frame of the range (before any output).
  SensorPlan plan = PlanSensor(options, scene, rig, begin, count, arena, *tracer);
  PlanMotion(options, scene, rig, groundtruth, begin, &plan);
  const int spp = options.spp > 0 ? options.spp : DefaultSpp(options.timing, plan.exposure);
  const AdaptiveSampling adaptive = RenderAdaptiveSampling(options, spp, options.spp <= 0);
  DatasetInfo info = MakeDatasetInfo(options, scene, rig, count, plan);
  if (info.timing) RecordSampling(spp, adaptive, &*info.timing);

  PrepareOutput(options, info, groundtruth, plan);
  const std::vector<int> todo = FramesToRender(options, rig, count, &summary);
  const std::clock_t frames_start = std::clock();
  RenderFrames(options, scene, rig, begin, todo, spp, adaptive, plan, arena, *tracer, &summary);
  summary.frames_cpu_seconds = static_cast<double>(std::clock() - frames_start) / CLOCKS_PER_SEC;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace rovo
