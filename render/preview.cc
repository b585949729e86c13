// `rovo scene preview` (contact sheet). (`rovo bench render` is in render/bench.cc.)
#include <sys/resource.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <stdexcept>

#include "datasets/image_file.h"
#include "datasets/io.h"
#include "render/image_io.h"
#include "render/render.h"
#include "render/tracer.h"
#include "rovo/version.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

// Area-weighted (box) downscale of an 8-bit RGB image: each output pixel averages the input area
// it covers, partial pixels weighted by their overlap. Separable: rows first, then columns.
std::vector<uint8_t> DownscaleRgb8(const std::vector<uint8_t>& src, int width, int height, int out_width,
                                   int out_height) {
  // Overlap weights of output cell o with the input pixels along one axis.
  auto weights = [](int in, int out, int o, std::vector<std::pair<int, float>>* w) {
    w->clear();
    const double scale = static_cast<double>(in) / out;
    const double a = o * scale, b = (o + 1) * scale;
    for (int i = static_cast<int>(a); i < std::min(in, static_cast<int>(std::ceil(b))); ++i) {
      const double overlap = std::min<double>(b, i + 1) - std::max<double>(a, i);
      if (overlap > 0.0) w->push_back({i, static_cast<float>(overlap / scale)});
    }
  };
  std::vector<float> rows(static_cast<size_t>(height) * out_width * 3, 0.0f);
  std::vector<std::pair<int, float>> w;
  for (int ox = 0; ox < out_width; ++ox) {
    weights(width, out_width, ox, &w);
    for (int y = 0; y < height; ++y)
      for (const auto& [x, wx] : w)
        for (int c = 0; c < 3; ++c)
          rows[(static_cast<size_t>(y) * out_width + ox) * 3 + c] +=
              wx * src[(static_cast<size_t>(y) * width + x) * 3 + c];
  }
  std::vector<uint8_t> out(static_cast<size_t>(out_height) * out_width * 3);
  for (int oy = 0; oy < out_height; ++oy) {
    weights(height, out_height, oy, &w);
    for (int ox = 0; ox < out_width; ++ox)
      for (int c = 0; c < 3; ++c) {
        float sum = 0.0f;
        for (const auto& [y, wy] : w) sum += wy * rows[(static_cast<size_t>(y) * out_width + ox) * 3 + c];
        out[(static_cast<size_t>(oy) * out_width + ox) * 3 + c] =
            static_cast<uint8_t>(std::clamp(std::lround(sum), 0L, 255L));
      }
  }
  return out;
}

// A contact sheet is written once and kept: PNG at compression level 6 (smaller than the datasets'
// speed-oriented level 1), atomically.
void WriteCompactPng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  WritePng8(path, width, height, 3, rgb, "rovo " ROVO_VERSION, 6);
}

}  // namespace

void RenderScenePreview(const PreviewOptions& options) {
  if (options.scale <= 0.0 || options.scale > 4.0) throw std::invalid_argument("--scale: must be in (0, 4]");
  if (options.spp < 1) throw std::invalid_argument("--spp: must be >= 1");
  if (options.width < 0) throw std::invalid_argument("--width: must be >= 0");
  const Scene scene = SceneForOptions(options.preset, true, options.seed, options.scene_dir);
  const Rig rig = RigForOptions(options.rig, scene, options.scale, options.scene_dir);
  const int num_traj = static_cast<int>(scene.rig_trajectory.size());
  if (num_traj == 0) throw std::runtime_error("scene: trajectory: the scene has no rig poses");
  std::vector<int> frames = options.frames;
  if (frames.empty()) frames = num_traj >= 3 ? std::vector<int>{0, num_traj / 2, num_traj - 1} : std::vector<int>{0};
  for (int f : frames)
    if (f < 0 || f >= num_traj)
      throw std::out_of_range("--frames: frame " + std::to_string(f) +
                              " outside the trajectory (0:" + std::to_string(num_traj) + ")");
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
  int out_w = sheet_w, out_h = sheet_h;
  if (options.width > 0 && options.width < sheet_w) {
    out_w = options.width;
    out_h = std::max(1, static_cast<int>(std::lround(static_cast<double>(sheet_h) * out_w / sheet_w)));
    sheet = DownscaleRgb8(sheet, sheet_w, sheet_h, out_w, out_h);
  }
  WriteCompactPng(out, out_w, out_h, sheet);
  std::printf("wrote %s (%d frames x %d views, %dx%d)\n", out.c_str(), static_cast<int>(frames.size()),
              rig.NumCameras(), out_w, out_h);
}

}  // namespace rovo
