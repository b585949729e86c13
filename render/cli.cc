// `rovo` subcommands of render/: `rovo render`, `rovo scene preview`, `rovo bench render`.
#include "datasets/cli_groups.h"
#include "render/render.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace rovo {
namespace {


void ParseShard(const std::string& text, int* index, int* count) {
  const size_t slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("");
    *index = std::stoi(text.substr(0, slash));
    *count = std::stoi(text.substr(slash + 1));
  } catch (const std::exception&) {
    throw std::invalid_argument("--shard '" + text + "': expected I/N, e.g. 0/4");
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

}  // namespace

void AddRenderCommands(CliGroups& groups) {
  // ---- rovo render
  {
    struct Args {
      RenderOptions options;
      std::string frames, shard;
    };
    auto args = std::make_shared<Args>();
    CLI::App* cmd = groups.root->add_subcommand(
        "render",
        "Render a dataset (datasets/FORMAT.md) of a scene seen by a fisheye rig with the Embree tracer: "
        "camN/NNNNNN.png, groundtruth.tum, dataset.json, optional depth/ and masks/. Resumable: rerunning "
        "skips frames whose files all exist.");
    auto* preset = cmd->add_option("--preset", args->options.preset, "Scene preset to generate and render (e.g. static_urban)");
    auto* scene = cmd->add_option("--scene", args->options.scene_dir, "Scene folder (scenes/FORMAT.md)");
    preset->excludes(scene);
    cmd->add_flag("--quick", args->options.quick, "The preset's quick form: fewer frames, smaller images");
    cmd->add_option(
        "--rig", args->options.rig,
        "Rig preset (rovo4, omnimvs4, rovo4_real) or rig.json; default: the scene folder's rig.json, else the "
        "scene's rig_preset, else rovo4 (the rig used is printed)");
    cmd->add_option("--out", args->options.out_dir, "Output dataset folder")->required();
    cmd->add_option("--frames", args->frames, "Trajectory frame range A:B (B exclusive; default: all)");
    cmd->add_option("--shard", args->shard, "Render only shard I of N (chunks of 8 frames), e.g. 0/4");
    cmd->add_option("--spp", args->options.spp,
                    "Samples per pixel (default " + std::to_string(kDefaultSpp) + ", measured; 1 = pixel centres)");
    cmd->add_option("--threads", args->options.threads, "Render threads (default: all cores)");
    cmd->add_option("--seed", args->options.seed, "Scene seed (with --preset) and sensor-noise seed")->capture_default_str();
    cmd->add_flag("--depth", args->options.depth, "Also write depth/camN/NNNNNN.exr (ray length in metres)");
    cmd->add_flag("--masks", args->options.masks, "Also write masks/camN/NNNNNN.png (16-bit object ids)");
    cmd->add_option("--scale", args->options.scale,
                    "Image size relative to the rig (same lens); default 1, or the preset's quick scale with --quick");
    cmd->add_option("--noise", args->options.noise_sigma, "Gaussian sensor noise, std. dev. in 8-bit units (default 0)");
    cmd->add_option("--vignetting", args->options.vignetting, "Vignetting strength in [0, 1] (default 0)");
    cmd->add_flag("--quiet", args->options.quiet, "No progress output");
    cmd->callback([args] {
      RenderOptions options = args->options;
      if (!args->frames.empty()) ParseFrameRange(args->frames, &options.frame_begin, &options.frame_end);
      if (!args->shard.empty()) ParseShard(args->shard, &options.shard_index, &options.shard_count);
      const RenderSummary s = RenderDataset(options);
      std::printf("rendered %d frames, skipped %d complete, %d in this shard, %.1f s\n%s\n", s.frames_rendered,
                  s.frames_skipped, s.frames_total, s.seconds, s.rig.c_str());
    });
  }

  // ---- rovo scene preview
  {
    struct Args {
      PreviewOptions options;
      std::string frames;
      std::string dir;
    };
    auto args = std::make_shared<Args>();
    CLI::App* cmd = groups.scene->add_subcommand(
        "preview", "Render a contact sheet of a scene: one row per frame, the rig's views side by side (PNG)");
    cmd->add_option("dir", args->dir, "Scene folder (scenes/FORMAT.md)");
    cmd->add_option("--preset", args->options.preset, "Instead of a folder: a scene preset (quick form)");
    cmd->add_option("--seed", args->options.seed, "Seed of --preset")->capture_default_str();
    cmd->add_option("--frames", args->frames, "Comma-separated trajectory frames (default: first, middle, last)");
    cmd->add_option("--out", args->options.out_png, "Output PNG (default: <dir>/preview.png)");
    cmd->add_option("--rig", args->options.rig, "Rig preset or rig.json (default: the scene's)");
    cmd->add_option("--scale", args->options.scale, "Image scale of each view")->capture_default_str();
    cmd->add_option("--spp", args->options.spp, "Samples per pixel")->capture_default_str();
    cmd->add_option("--width", args->options.width, "Downscale the sheet to at most this many pixels wide (default: no limit)");
    cmd->add_option("--threads", args->options.threads, "Threads (default: all cores)");
    cmd->callback([args] {
      PreviewOptions options = args->options;
      options.scene_dir = args->dir;
      if (!args->frames.empty()) options.frames = ParseFrameList(args->frames);
      RenderScenePreview(options);
    });
  }

  // ---- rovo bench render
  {
    auto options = std::make_shared<RenderBenchOptions>();
    CLI::App* cmd = groups.bench->add_subcommand(
        "render",
        "Render speed: s/frame and Mrays/s at 1 spp and default quality, raw Embree cast of the same rays "
        "(ratio full/raw), BVH build time, peak memory, load average, optionally the Cycles ratio");
    cmd->add_option("--preset", options->preset, "Scene preset")->capture_default_str();
    cmd->add_option("--scene", options->scene_dir, "Scene folder instead of the preset");
    cmd->add_option("--seed", options->seed, "Scene seed")->capture_default_str();
    cmd->add_option("--frames", options->frames, "Frames to time")->capture_default_str();
    cmd->add_option("--scale", options->scale, "Image scale")->capture_default_str();
    cmd->add_option("--threads", options->threads, "Threads (default: all cores)");
    cmd->add_option("--spp", options->spp, "Default-quality spp (0 = the default)");
    cmd->add_flag("--quality", options->quality,
                  "Also measure anti-aliasing per spp, sample pattern and texture filter: mean error vs. a 32-spp "
                  "reference and shimmer (frame-to-frame change not in the reference) over quarter-pixel pan steps");
    cmd->add_flag("--breakdown", options->breakdown,
                  "Also time the 1-spp render with bilinear (single mip level) texturing and without textures");
    cmd->add_option("--cycles-timing", options->cycles_timing,
                    "timing.json written by scenes/blender/time_cycles_vs_rovo.py: print the Cycles/rovo ratio "
                    "(Cycles takes minutes per frame, so it is timed by that script, not here)");
    cmd->add_option("--write", options->write_dir, "Also time a full `rovo render` of the frames into this folder");
    cmd->callback([options] { RunRenderBenchmark(*options); });
  }
}

}  // namespace rovo
