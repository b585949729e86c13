// `rovo scene preview` (contact sheet) and `rovo bench render` (speed table).
#include "datasets/io.h"
#include "render/image_io.h"
#include "render/render.h"
#include "render/tracer.h"

#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include <sys/resource.h>

namespace rovo {
namespace {
namespace fs = std::filesystem;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Process CPU seconds (user + system): stable on a shared machine where wall time is not.
double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double MeanAbsDiff(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, const std::vector<uint8_t>& valid) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < valid.size(); ++i) {
    if (!valid[i]) continue;
    for (int c = 0; c < 3; ++c) sum += std::abs(static_cast<int>(a[3 * i + c]) - static_cast<int>(b[3 * i + c]));
    n += 3;
  }
  return n ? sum / n : 0.0;
}

// Renders camera 0 of frame 0 nudged by quarter-pixel yaw steps and prints, per (spp, LOD bias),
// the mean absolute difference to a 16-spp reference and the shimmer (frame-to-frame change that
// deviates from the reference's change).
void RunQualityStudy(const Scene& scene, const Rig& rig, Tracer& tracer, const CameraRays& rays,
                     tbb::task_arena& arena) {
  const int kSteps = 5;
  const Rigid3 world_from_cam =
      scene.rig_trajectory[0].world_from_rig * rig.cameras[0].cam_from_rig.Inverse();
  const size_t centre = static_cast<size_t>(rays.height / 2) * rays.width + rays.width / 2;
  const double step_rad = 0.25 * rays.pixel_angle[centre];
  auto render_steps = [&](int spp, float lod_bias) {
    std::vector<std::vector<uint8_t>> images;
    ShadeSettings settings;
    settings.spp = spp;
    settings.lod_bias = lod_bias;
    for (int k = 0; k < kSteps; ++k) {
      // Yaw about the camera's y axis (image columns shift by about k/4 px at the centre).
      const Rigid3 nudge = Rigid3::FromAxisAngle(Eigen::Vector3d(0, k * step_rad, 0), Eigen::Vector3d::Zero());
      CameraImage image;
      arena.execute([&] {
        tracer.SetFrame(0);
        tracer.Render(rays, world_from_cam * nudge, settings, &image);
      });
      images.push_back(std::move(image.rgb));
    }
    return images;
  };
  // Shimmer: how far the frame-to-frame change deviates from the reference's change,
  // mean |(I_k - I_k-1) - (R_k - R_k-1)| (a perfectly filtered image moves like the reference).
  auto shimmer = [&](const std::vector<std::vector<uint8_t>>& images, const std::vector<std::vector<uint8_t>>& ref) {
    double sum = 0.0;
    size_t n = 0;
    for (int k = 1; k < kSteps; ++k) {
      for (size_t i = 0; i < rays.valid.size(); ++i) {
        if (!rays.valid[i]) continue;
        for (int c = 0; c < 3; ++c) {
          const int d_img = images[k][3 * i + c] - images[k - 1][3 * i + c];
          const int d_ref = ref[k][3 * i + c] - ref[k - 1][3 * i + c];
          sum += std::abs(d_img - d_ref);
          ++n;
        }
      }
    }
    return n ? sum / n : 0.0;
  };
  const auto reference = render_steps(16, 0.0f);
  std::printf("\nanti-aliasing (camera 0, %dx%d, %d quarter-pixel yaw steps; 8-bit units, mean over valid pixels)\n",
              rays.width, rays.height, kSteps);
  std::printf("| spp | LOD bias | mean abs error vs 16 spp | shimmer vs 16 spp | CPU s/view |\n");
  std::printf("|---:|---:|---:|---:|---:|\n");
  for (int spp : {1, 2, 4, 8}) {
    for (float bias : {-1.0f, -0.5f, 0.0f}) {
      const double cpu0 = CpuSeconds();
      const auto images = render_steps(spp, bias);
      const double cpu = (CpuSeconds() - cpu0) / kSteps;
      double error = 0.0;
      for (int k = 0; k < kSteps; ++k) error += MeanAbsDiff(images[k], reference[k], rays.valid);
      std::printf("| %d | %+.1f | %.3f | %.3f | %.3f |\n", spp, bias, error / kSteps, shimmer(images, reference), cpu);
    }
  }
}

double PeakMemoryMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace

void RenderScenePreview(const PreviewOptions& options) {
  if (options.scale <= 0.0 || options.scale > 4.0) throw std::invalid_argument("--scale: must be in (0, 4]");
  if (options.spp < 1) throw std::invalid_argument("--spp: must be >= 1");
  const Scene scene = SceneForOptions(options.preset, true, options.seed, options.scene_dir);
  const Rig rig = RigForOptions(options.rig, scene, options.scale);
  const int num_traj = static_cast<int>(scene.rig_trajectory.size());
  if (num_traj == 0) throw std::runtime_error("scene: trajectory: the scene has no rig poses");
  std::vector<int> frames = options.frames;
  if (frames.empty()) frames = num_traj >= 3 ? std::vector<int>{0, num_traj / 2, num_traj - 1} : std::vector<int>{0};
  for (int f : frames)
    if (f < 0 || f >= num_traj)
      throw std::out_of_range("--frames: frame " + std::to_string(f) + " outside the trajectory (0:" +
                              std::to_string(num_traj) + ")");
  std::string out = options.out_png;
  if (out.empty()) {
    if (options.scene_dir.empty()) throw std::invalid_argument("--out: required with --preset");
    out = (fs::path(options.scene_dir) / "preview.png").string();
  }

  int cell_w = 0, cell_h = 0;
  for (const RigCamera& cam : rig.cameras) {
    cell_w = std::max(cell_w, cam.camera.width);
    cell_h = std::max(cell_h, cam.camera.height);
  }
  const int sheet_w = cell_w * rig.NumCameras();
  const int sheet_h = cell_h * static_cast<int>(frames.size());
  std::vector<uint8_t> sheet(static_cast<size_t>(sheet_w) * sheet_h * 3, 0);

  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    Tracer tracer(scene);
    std::vector<CameraRays> rays;
    for (const RigCamera& cam : rig.cameras) rays.push_back(CameraRays::Make(cam.camera));
    ShadeSettings settings;
    settings.spp = options.spp;
    for (size_t row = 0; row < frames.size(); ++row) {
      tracer.SetFrame(frames[row]);
      const Rigid3& world_from_rig = scene.rig_trajectory[frames[row]].world_from_rig;
      for (int c = 0; c < rig.NumCameras(); ++c) {
        CameraImage image;
        tracer.Render(rays[c], world_from_rig * rig.cameras[c].cam_from_rig.Inverse(), settings, &image);
        for (int y = 0; y < image.height; ++y) {
          const size_t dst = ((row * cell_h + y) * static_cast<size_t>(sheet_w) + static_cast<size_t>(c) * cell_w) * 3;
          std::copy_n(&image.rgb[static_cast<size_t>(y) * image.width * 3], image.width * 3, &sheet[dst]);
        }
      }
    }
  });
  WritePngRgb8(out, sheet_w, sheet_h, sheet);
  std::printf("wrote %s (%d frames x %d views, %dx%d)\n", out.c_str(), static_cast<int>(frames.size()),
              rig.NumCameras(), sheet_w, sheet_h);
}

void RunRenderBenchmark(const RenderBenchOptions& options) {
  if (options.frames < 1) throw std::invalid_argument("--frames: must be >= 1");
  const auto t_scene = std::chrono::steady_clock::now();
  const Scene scene = SceneForOptions(options.scene_dir.empty() ? options.preset : "", false, options.seed,
                                      options.scene_dir);
  const double scene_seconds = Seconds(t_scene);
  const Rig rig = RigForOptions("", scene, options.scale);
  const int frames = std::min<int>(options.frames, static_cast<int>(scene.rig_trajectory.size()));
  const int spp_default = options.spp > 0 ? options.spp : kDefaultSpp;

  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  std::unique_ptr<Tracer> tracer;
  std::vector<CameraRays> rays;
  double rays_seconds = 0.0;
  arena.execute([&] {
    tracer = std::make_unique<Tracer>(scene);
    const auto t = std::chrono::steady_clock::now();
    for (const RigCamera& cam : rig.cameras) rays.push_back(CameraRays::Make(cam.camera));
    rays_seconds = Seconds(t);
  });
  int64_t valid_pixels = 0;
  for (const CameraRays& r : rays) valid_pixels += r.num_valid;

  struct Row {
    std::string name;
    int spp;
    bool raw;
    double seconds_per_frame = 0;
    double cpu_seconds_per_frame = 0;
  };
  std::vector<Row> rows = {{"raw cast (primary + sun shadow)", 1, true},
                           {"full render", 1, false},
                           {"raw cast (primary + sun shadow)", spp_default, true},
                           {"full render", spp_default, false}};
  for (Row& row : rows) {
    ShadeSettings settings;
    settings.spp = row.spp;
    settings.raw_cast_only = row.raw;
    std::vector<CameraImage> images(rig.NumCameras());
    // One untimed warm-up frame, then the timed frames.
    for (int pass = 0; pass < 2; ++pass) {
      const auto t = std::chrono::steady_clock::now();
      const double cpu0 = CpuSeconds();
      const int n = pass == 0 ? 1 : frames;
      for (int f = 0; f < n; ++f) {
        arena.execute([&] {
          tracer->SetFrame(f);
          const Rigid3& world_from_rig = scene.rig_trajectory[f].world_from_rig;
          for (int c = 0; c < rig.NumCameras(); ++c)
            tracer->Render(rays[c], world_from_rig * rig.cameras[c].cam_from_rig.Inverse(), settings, &images[c]);
        });
      }
      if (pass == 1) {
        row.seconds_per_frame = Seconds(t) / frames;
        row.cpu_seconds_per_frame = (CpuSeconds() - cpu0) / frames;
      }
    }
  }

  double write_seconds_per_frame = -1.0;
  if (!options.write_dir.empty()) {
    RenderOptions ro;
    ro.preset = options.scene_dir.empty() ? options.preset : "";
    ro.scene_dir = options.scene_dir;
    ro.seed = options.seed;
    ro.out_dir = options.write_dir;
    ro.frame_end = frames;
    ro.scale = options.scale;
    ro.threads = options.threads;
    ro.quiet = true;
    const RenderSummary s = RenderDataset(ro);
    write_seconds_per_frame = s.frames_rendered > 0 ? s.seconds / s.frames_rendered : -1.0;
  }

  const Camera& cam0 = rig.cameras[0].camera;
  std::printf("rovo bench render: %s, %d frames, rig %d x %dx%d, threads %d\n",
              options.scene_dir.empty() ? ("preset " + options.preset).c_str() : options.scene_dir.c_str(), frames,
              rig.NumCameras(), cam0.width, cam0.height,
              options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency());
  std::printf("scene: %zu static triangles, %zu objects; generate/load %.2f s; static BVH build %.3f s; "
              "pixel bearings %.2f s\n",
              tracer->num_static_triangles(), scene.objects.size(), scene_seconds, tracer->static_build_seconds(),
              rays_seconds);
  std::printf("\n| mode | spp | wall s/frame | CPU s/frame | camera Mrays/s (wall) | camera Mrays/CPU-s |\n"
              "|---|---:|---:|---:|---:|---:|\n");
  for (const Row& row : rows) {
    const double rays_per_frame = valid_pixels * static_cast<double>(row.spp);
    std::printf("| %s | %d | %.3f | %.3f | %.1f | %.1f |\n", row.name.c_str(), row.spp, row.seconds_per_frame,
                row.cpu_seconds_per_frame, rays_per_frame / row.seconds_per_frame / 1e6,
                rays_per_frame / row.cpu_seconds_per_frame / 1e6);
  }
  std::printf("\nfull/raw at 1 spp: wall %.2f, CPU %.2f (target <= 1.5); full/raw at %d spp: wall %.2f, CPU %.2f\n",
              rows[1].seconds_per_frame / rows[0].seconds_per_frame,
              rows[1].cpu_seconds_per_frame / rows[0].cpu_seconds_per_frame, spp_default,
              rows[3].seconds_per_frame / rows[2].seconds_per_frame,
              rows[3].cpu_seconds_per_frame / rows[2].cpu_seconds_per_frame);
  if (write_seconds_per_frame >= 0.0)
    std::printf("rovo render incl. PNG writing (%d spp): %.3f s/frame (includes scene generation and set-up)\n", spp_default, write_seconds_per_frame);
  std::printf("peak memory (getrusage): %.0f MB\n", PeakMemoryMb());
  if (options.quality) RunQualityStudy(scene, rig, *tracer, rays[0], arena);
}

}  // namespace rovo
