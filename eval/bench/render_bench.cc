// `rovo bench render`: speed table (full render vs. raw Embree cast of the same rays, BVH build,
// peak memory, optional Cycles ratio); --quality runs the studies of render_quality.h.
#include "eval/bench/render_bench.h"

#include <sys/resource.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "eval/bench/render_quality.h"
#include "render/render.h"
#include "render/tracer.h"
#include "scenes/city.h"

namespace rovo {
namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Process CPU seconds (user + system): stable on a shared machine where wall time is not.
double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double PeakMemoryMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

double LoadAverage() {
  double load[1] = {0.0};
  return getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

// Prints the Cycles comparison from WORK/timing.json of scenes/blender/time_cycles_vs_rovo.py.
void PrintCyclesRatio(const std::string& path, double bench_default_cpu, int spp_default) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open (run scenes/blender/time_cycles_vs_rovo.py first)");
  nlohmann::json timing;
  try {
    in >> timing;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not valid JSON: " + e.what());
  }
  if (!timing.contains("rows") || !timing["rows"].is_array() || timing["rows"].size() < 3)
    throw std::runtime_error(path + ": field 'rows': expected the Cycles row and two rovo rows");
  auto cpu = [&](size_t i) {
    const nlohmann::json& row = timing["rows"][i];
    if (!row.contains("cpu_seconds_per_frame") || !row["cpu_seconds_per_frame"].is_number())
      throw std::runtime_error(path + ": field 'rows/" + std::to_string(i) + "/cpu_seconds_per_frame' missing");
    return row["cpu_seconds_per_frame"].get<double>();
  };
  const double cycles = cpu(0), rovo_same_spp = cpu(1), rovo_default = cpu(2);
  std::printf(
      "\nCycles (%s, %s): %.1f CPU s/frame; rovo render --scene on the same exported frames "
      "(whole command incl. load, BVH, PNG): %.2f CPU s/frame at the same spp (%.1fx), %.2f at the "
      "default spp (%.1fx, target >= 30x)\n",
      path.c_str(), timing.value("rows", nlohmann::json::array())[0].value("renderer", "?").c_str(), cycles,
      rovo_same_spp, cycles / rovo_same_spp, rovo_default, cycles / rovo_default);
  std::printf("Cycles CPU s/frame over this bench's default-quality (%d spp) render: %.1fx (different scenes)\n",
              spp_default, cycles / bench_default_cpu);
}

// One row of the speed table.
struct BenchRow {
  std::string name;
  int spp;
  bool raw;
  bool textures = true;
  bool trilinear = true;
  double seconds_per_frame = 0;
  double cpu_seconds_per_frame = 0;
};

std::vector<BenchRow> BenchRows(int spp_default, bool breakdown) {
  std::vector<BenchRow> rows = {{"raw cast (same camera + shadow rays)", 1, true}, {"full render", 1, false}};
  if (spp_default != 1) {
    rows.push_back({"raw cast (same camera + shadow rays)", spp_default, true});
    rows.push_back({"full render", spp_default, false});
  }
  if (breakdown) {
    rows.push_back({"full render, bilinear on the nearest mip level", 1, false, true, false});
    rows.push_back({"full render, no textures", 1, false, false, true});
  }
  return rows;
}

// A scene ready to time: the scene, its rig, the tracer and the camera rays at the default spp.
struct BenchScene {
  Scene scene;
  Rig rig;
  std::unique_ptr<Tracer> tracer;
  RigCameraRays rays;
  std::vector<CameraImage> images;  // RenderFrame's, reused
  int frames = 0;
  double scene_seconds = 0.0, rays_seconds = 0.0;
};

std::unique_ptr<BenchScene> LoadBenchScene(const RenderBenchOptions& options, const std::string& preset,
                                           const std::string& scene_dir, int spp, tbb::task_arena& arena) {
  auto b = std::make_unique<BenchScene>();
  const auto t_scene = std::chrono::steady_clock::now();
  b->scene = SceneForOptions(scene_dir.empty() ? preset : "", false, options.seed, scene_dir);
  b->scene_seconds = Seconds(t_scene);
  b->rig = RigForOptions("", b->scene, options.scale, scene_dir);
  b->frames = std::min<int>(options.frames, static_cast<int>(b->scene.rig_trajectory.size()));
  arena.execute([&] {
    b->tracer = std::make_unique<Tracer>(b->scene);
    const auto t = std::chrono::steady_clock::now();
    std::vector<Camera> cameras;
    for (const RigCamera& cam : b->rig.cameras) cameras.push_back(cam.camera);
    b->rays = MakeCameraRays(cameras, 0, spp);
    b->rays_seconds = Seconds(t);
  });
  return b;
}

// Renders frame f of `b` with every camera at `settings` into b.images (reused, as rovo render reuses
// its buffers).
void RenderFrame(BenchScene& b, const ShadeSettings& settings, int f, tbb::task_arena& arena) {
  b.images.resize(b.rig.NumCameras());
  arena.execute([&] {
    b.tracer->SetFrame(f);
    const Rigid3& world_from_rig = b.scene.rig_trajectory[f].world_from_rig;
    for (int c = 0; c < b.rig.NumCameras(); ++c)
      b.tracer->Render(*b.rays[c], world_from_rig * b.rig.cameras[c].cam_from_rig.Inverse(), settings, &b.images[c]);
  });
}

// Times every row over b.frames frames. Rows interleaved frame by frame (one untimed warm-up frame
// per row first), so that every row sees the same load on a shared machine and the ratios between
// rows are robust to it.
void TimeRows(BenchScene& b, tbb::task_arena& arena, std::vector<BenchRow>* rows) {
  auto settings_for = [](const BenchRow& row) {
    ShadeSettings settings;
    settings.spp = row.spp;
    settings.raw_cast_only = row.raw;
    settings.textures = row.textures;
    settings.trilinear = row.trilinear;
    return settings;
  };
  for (const BenchRow& row : *rows) RenderFrame(b, settings_for(row), 0, arena);
  for (int f = 0; f < b.frames; ++f) {
    for (BenchRow& row : *rows) {
      const auto t = std::chrono::steady_clock::now();
      const double cpu0 = CpuSeconds();
      RenderFrame(b, settings_for(row), f, arena);
      row.seconds_per_frame += Seconds(t) / b.frames;
      row.cpu_seconds_per_frame += (CpuSeconds() - cpu0) / b.frames;
    }
  }
}

// Seconds per frame of a full `rovo render` of the frames into options.write_dir.
double TimeDatasetWriting(const RenderBenchOptions& options, int frames, int spp) {
  RenderOptions ro;
  ro.preset = options.scene_dir.empty() ? options.preset : "";
  ro.scene_dir = options.scene_dir;
  ro.seed = options.seed;
  ro.out_dir = options.write_dir;
  ro.frame_end = frames;
  ro.scale = options.scale;
  ro.threads = options.threads;
  ro.spp = spp;
  ro.quiet = true;
  const RenderSummary s = RenderDataset(ro);
  return s.frames_rendered > 0 ? s.seconds / s.frames_rendered : -1.0;
}

// The speed table and the ratios against the targets.
void PrintRowTable(const std::vector<BenchRow>& rows, int64_t valid_pixels, int spp_default) {
  std::printf(
      "\n| mode | spp | wall s/frame | CPU s/frame | camera Mrays/s (wall) | camera Mrays/CPU-s |\n"
      "|---|---:|---:|---:|---:|---:|\n");
  for (const BenchRow& row : rows) {
    const double rays_per_frame = valid_pixels * static_cast<double>(row.spp);
    std::printf("| %s | %d | %.3f | %.3f | %.1f | %.1f |\n", row.name.c_str(), row.spp, row.seconds_per_frame,
                row.cpu_seconds_per_frame, rays_per_frame / row.seconds_per_frame / 1e6,
                rays_per_frame / row.cpu_seconds_per_frame / 1e6);
  }
  std::printf("\nfull/raw at 1 spp: wall %.2f, CPU %.2f (target <= 1.15)\n",
              rows[1].seconds_per_frame / rows[0].seconds_per_frame,
              rows[1].cpu_seconds_per_frame / rows[0].cpu_seconds_per_frame);
  const BenchRow& full_default = spp_default != 1 ? rows[3] : rows[1];
  if (spp_default != 1)
    std::printf("full/raw at %d spp: wall %.2f, CPU %.2f\n", spp_default,
                rows[3].seconds_per_frame / rows[2].seconds_per_frame,
                rows[3].cpu_seconds_per_frame / rows[2].cpu_seconds_per_frame);
  std::printf("default quality (%d spp): %.3f s/frame wall, %.3f CPU s/frame (target <= 1 s wall on 2 idle cores)\n",
              spp_default, full_default.seconds_per_frame, full_default.cpu_seconds_per_frame);
}

// CPU seconds of rendering frame f of `b` at `settings` (all cameras).
double FrameCpuSeconds(BenchScene& b, const ShadeSettings& settings, int f, tbb::task_arena& arena) {
  const double cpu0 = CpuSeconds();
  RenderFrame(b, settings, f, arena);
  return CpuSeconds() - cpu0;
}

// --against: the default-quality render of this scene and of the reference preset, frame by frame in
// turn (so that both see the same load, after an untimed frame each), and the ratio of their CPU.
void PrintRatioAgainst(const RenderBenchOptions& options, BenchScene& main, int spp, tbb::task_arena& arena) {
  const std::unique_ptr<BenchScene> ref = LoadBenchScene(options, options.against, "", spp, arena);
  const int frames = std::min(main.frames, ref->frames);
  ShadeSettings settings;
  settings.spp = spp;
  FrameCpuSeconds(main, settings, 0, arena);
  FrameCpuSeconds(*ref, settings, 0, arena);
  double cpu_main = 0.0, cpu_ref = 0.0;
  for (int f = 0; f < frames; ++f) {
    cpu_main += FrameCpuSeconds(main, settings, f, arena) / frames;
    cpu_ref += FrameCpuSeconds(*ref, settings, f, arena) / frames;
  }
  std::printf(
      "default quality (%d spp) against preset %s, frames in turn: %.4f / %.4f CPU s/frame = %.2fx (target <= 1.5 "
      "for every preset against cloudy_urban)\n",
      spp, options.against.c_str(), cpu_main, cpu_ref, cpu_ref > 0.0 ? cpu_main / cpu_ref : 0.0);
}

}  // namespace

void RunRenderBenchmark(const RenderBenchOptions& options) {
  if (options.frames < 1) throw std::invalid_argument("--frames: must be >= 1");
  if (!options.against.empty()) FindScenePreset(options.against);  // an unknown name fails before the timing
  const double load_before = LoadAverage();
  const int spp_default = options.spp > 0 ? options.spp : kDefaultSpp;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  const std::unique_ptr<BenchScene> bench =
      LoadBenchScene(options, options.preset, options.scene_dir, spp_default, arena);
  const Scene& scene = bench->scene;
  const Rig& rig = bench->rig;
  const RigCameraRays& rays = bench->rays;
  Tracer* tracer = bench->tracer.get();
  const int frames = bench->frames;
  int64_t valid_pixels = 0;
  for (const auto& r : rays) valid_pixels += r->num_valid;

  std::vector<BenchRow> rows = BenchRows(spp_default, options.breakdown);
  TimeRows(*bench, arena, &rows);
  const double write_seconds_per_frame =
      options.write_dir.empty() ? -1.0 : TimeDatasetWriting(options, frames, spp_default);

  const Camera& cam0 = rig.cameras[0].camera;
  std::printf("rovo bench render: %s, %d frames, rig %d x %dx%d, threads %d, load average %.1f before / %.1f after\n",
              options.scene_dir.empty() ? ("preset " + options.preset).c_str() : options.scene_dir.c_str(), frames,
              rig.NumCameras(), cam0.width, cam0.height,
              options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency(), load_before,
              LoadAverage());
  std::printf(
      "scene: %zu static triangles, %zu objects; generate/load %.2f s; static BVH build %.3f s; "
      "pixel and sample bearings (%d spp) %.2f s\n",
      tracer->num_static_triangles(), scene.objects.size(), bench->scene_seconds, tracer->static_build_seconds(),
      spp_default, bench->rays_seconds);
  PrintRowTable(rows, valid_pixels, spp_default);
  const BenchRow& full_default = spp_default != 1 ? rows[3] : rows[1];
  if (write_seconds_per_frame >= 0.0)
    std::printf("rovo render incl. PNG writing (%d spp): %.3f s/frame (includes scene generation and set-up)\n",
                spp_default, write_seconds_per_frame);
  std::printf("peak memory (getrusage): %.0f MB\n", PeakMemoryMb());
  if (!options.cycles_timing.empty())
    PrintCyclesRatio(options.cycles_timing, full_default.cpu_seconds_per_frame, spp_default);
  if (!options.against.empty()) PrintRatioAgainst(options, *bench, spp_default, arena);
  if (options.quality) {
    RunQualityStudy(scene, rig, *tracer, arena);
    RunLightQualityStudy(scene, rig, *tracer, arena);
  }
  if (options.blur_quality_ms > 0.0) RunBlurQualityStudy(scene, rig, *tracer, arena, options.blur_quality_ms);
}

}  // namespace rovo
