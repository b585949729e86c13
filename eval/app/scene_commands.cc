// `rovo scene generate | info | list | preview`.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "datasets/trajectory.h"
#include "eval/app/commands.h"
#include "render/render.h"
#include "scenes/city.h"
#include "scenes/city_layout.h"
#include "scenes/scene.h"

namespace rovo {
namespace {

struct GenerateOptions {
  std::string preset;
  uint64_t seed = 0;  // the default of `rovo render --seed` and `rovo scene preview --seed`
  bool quick = false;
  std::string out_dir;
};

size_t SceneBytes(const Scene& scene, size_t* texture_bytes) {
  size_t tex = 0, geo = 0;
  for (const Texture& t : scene.textures) tex += t.rgb.size();
  for (const Mesh& m : scene.meshes) {
    geo += m.positions.size() * 12 + m.uvs.size() * 8 + m.triangles.size() * 12 + m.triangle_materials.size() * 4;
  }
  for (const Object& o : scene.objects) geo += o.world_from_object_per_frame.size() * sizeof(Rigid3);
  *texture_bytes = tex;
  return tex + geo;
}

// Sizes, path and lighting of a scene; `nominal` is the preset it was made from, if any.
void PrintSceneSummary(const Scene& scene, const ScenePreset* nominal, bool quick) {
  size_t triangles = 0, instanced = 0, dynamic = 0;
  for (const Mesh& m : scene.meshes) triangles += m.triangles.size();
  for (const Object& ob : scene.objects) {
    instanced += scene.meshes[ob.mesh].triangles.size();
    dynamic += ob.IsDynamic() ? 1 : 0;
  }
  size_t texture_bytes = 0;
  const size_t bytes = SceneBytes(scene, &texture_bytes);
  std::printf("preset       %s%s, seed %llu, lighting %s, rig %s\n", scene.metadata.preset.c_str(),
              quick ? " (quick)" : "", static_cast<unsigned long long>(scene.metadata.seed),
              scene.lighting.preset.c_str(), scene.rig_preset.c_str());
  std::printf("hash         %s\n", SceneHash(scene).c_str());
  std::printf("meshes       %zu (%zu triangles; %zu placed in the world)\n", scene.meshes.size(), triangles, instanced);
  std::printf("objects      %zu (%zu moving)\n", scene.objects.size(), dynamic);
  std::printf("textures     %zu (%.1f MB)\n", scene.textures.size(), texture_bytes / 1048576.0);
  std::printf("materials    %zu\n", scene.materials.size());
  std::printf("lights       %zu point/spot lights\n", scene.lights.size());
  std::printf("memory       %.1f MB\n", bytes / 1048576.0);
  std::printf("path         %.1f m in %zu frames at %.0f Hz", PathLength(scene.rig_trajectory),
              scene.rig_trajectory.size(), scene.frame_rate);
  if (nominal) {
    std::printf(" (preset: %.0f m, %d frames)", quick ? QuickPathLength(*nominal) : nominal->path_length_m,
                quick ? nominal->quick_frames : nominal->frames);
  }
  std::printf("\n");
}

const ScenePreset* PresetOf(const Scene& scene) {
  for (const auto* list : {&ScenePresets(), &HarderScenePresets()})
    for (const ScenePreset& p : *list)
      if (p.name == scene.metadata.preset) return &p;
  return nullptr;
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void RunGenerate(const GenerateOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const Scene scene = GenerateScene(o.preset, o.seed, o.quick);
  const double generate_seconds = SecondsSince(t0);
  const auto t1 = std::chrono::steady_clock::now();
  SaveScene(scene, o.out_dir);
  const double save_seconds = SecondsSince(t1);
  std::printf("scene        %s\n", o.out_dir.c_str());
  PrintSceneSummary(scene, &FindScenePreset(o.preset), o.quick);
  std::printf("time         %.2f s generate, %.2f s save\n", generate_seconds, save_seconds);
}

void RunSceneInfo(const std::string& dir) {
  const auto t0 = std::chrono::steady_clock::now();
  const Scene scene = LoadScene(dir);
  const double load_seconds = SecondsSince(t0);
  std::printf("scene        %s\n", dir.c_str());
  PrintSceneSummary(scene, PresetOf(scene), scene.metadata.source == "procedural (quick form)");
  std::printf("time         %.2f s load\n", load_seconds);
}

void RunList() {
  std::printf("%-16s %7s %9s %7s %8s %7s %-9s  %s\n", "preset", "frames", "length_m", "quick", "scale", "traffic",
              "lighting", "description");
  for (const ScenePreset& p : AllScenePresets()) {
    std::printf("%-16s %7d %9.0f %7d %8.2f %7s %-9s  %s\n", p.name.c_str(), p.frames, p.path_length_m, p.quick_frames,
                p.quick_scale, p.traffic ? "yes" : "no", SceneLightingName(p.lighting).c_str(), p.description.c_str());
  }
}

std::vector<int> ParseFrameList(const std::string& text) {
  std::vector<int> frames;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      frames.push_back(std::stoi(item));
    } catch (const std::exception&) {
      throw std::invalid_argument("--frames '" + text + "': expected a comma-separated list of frame numbers");
    }
  }
  return frames;
}

// `rovo scene preview`.
void AddPreviewCommand(CLI::App* scene) {
  struct Args {
    PreviewOptions options;
    std::string frames;
    std::string dir;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = scene->add_subcommand(
      "preview", "Render a contact sheet of a scene: one row per frame, the rig's views side by side (PNG)");
  cmd->add_option("dir", args->dir, "Scene folder (scenes/FORMAT.md)");
  cmd->add_option("--preset", args->options.preset, "Instead of a folder: a scene preset (quick form)");
  cmd->add_option("--seed", args->options.seed, "Seed of --preset")->capture_default_str();
  cmd->add_option("--frames", args->frames, "Comma-separated trajectory frames (default: first, middle, last)");
  cmd->add_option("--out", args->options.out_png, "Output PNG (default: <dir>/preview.png)");
  cmd->add_option("--rig", args->options.rig, "Rig preset or rig.json (default: the scene's)");
  cmd->add_option("--scale", args->options.scale, "Image scale of each view")->capture_default_str();
  cmd->add_option("--spp", args->options.spp, "Samples per pixel")->capture_default_str();
  cmd->add_option("--width", args->options.width,
                  "Downscale the sheet to at most this many pixels wide (default: no limit)");
  cmd->add_option("--threads", args->options.threads, "Threads (default: all cores)");
  cmd->callback([args] {
    PreviewOptions options = args->options;
    options.scene_dir = args->dir;
    if (!args->frames.empty()) options.frames = ParseFrameList(args->frames);
    RenderScenePreview(options);
  });
}

}  // namespace

void AddSceneCommands(CommandTree& tree) {
  auto opts = std::make_shared<GenerateOptions>();
  CLI::App* gen = tree.scene->add_subcommand(
      "generate",
      "Generate a procedural scene (streets, a suburb or an indoor hall, its lighting and the rig's path) and save it "
      "as a scene folder");
  gen->add_option("--preset", opts->preset, "Scene preset (see `rovo scene list`)")->required();
  gen->add_option("--seed", opts->seed, "Random seed; the same preset, seed and form give the same scene byte for byte")
      ->capture_default_str();
  gen->add_flag("--quick", opts->quick, "The preset's short form (CI-sized: a few dozen frames)");
  gen->add_option("--out", opts->out_dir, "Output scene folder (scenes/FORMAT.md)")->required();
  gen->callback([opts] { RunGenerate(*opts); });

  auto info_dir = std::make_shared<std::string>();
  CLI::App* info =
      tree.scene->add_subcommand("info", "Load a scene folder and print its size, path, lighting and load time");
  info->add_option("dir", *info_dir, "Scene folder (scenes/FORMAT.md)")->required();
  info->callback([info_dir] { RunSceneInfo(*info_dir); });

  CLI::App* list = tree.scene->add_subcommand(
      "list", "List the scene presets (the paper's Table I sequences, then the harder worlds)");
  list->callback([] { RunList(); });

  AddPreviewCommand(tree.scene);
}

}  // namespace rovo
