// `rovo scene preview` (contact sheet). (`rovo bench render` is in render/bench.cc.)
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

}  // namespace rovo
