// `rovo bench render | vo`: speed tables (eval/bench/).
#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "eval/app/commands.h"
#include "eval/app/vo_args.h"
#include "eval/bench/render_bench.h"
#include "eval/bench/vo_bench.h"
#include "eval/bench/vo_floor.h"

namespace rovo {
namespace {

// `rovo bench render`.
void AddRenderBenchCommand(CLI::App* bench) {
  auto options = std::make_shared<RenderBenchOptions>();
  CLI::App* cmd = bench->add_subcommand(
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
                "reference and shimmer (frame-to-frame change not in the reference) over quarter-pixel pan steps; on a "
                "scene with point or spot lights also the light choice (strongest lights' shadow rays, share floor, "
                "one drawn light per sample) against a reference that shadows every light in reach");
  cmd->add_option("--blur-quality", options->blur_quality_ms,
                  "Also measure motion-blur sampling at this shutter in ms: fixed spp and adaptive sampling at "
                  "several thresholds against a 64-spp reference (mean error, values off by more than 8 codes, mean "
                  "samples per pixel, CPU), camera 0 of frame 1")
      ->check(CLI::Range(0.001, 1000.0));
  cmd->add_flag("--breakdown", options->breakdown,
                "Also time the 1-spp render with bilinear (single mip level) texturing and without textures");
  cmd->add_option("--cycles-timing", options->cycles_timing,
                  "timing.json written by scenes/blender/time_cycles_vs_rovo.py: print the Cycles/rovo ratio "
                  "(Cycles takes minutes per frame, so it is timed by that script, not here)");
  cmd->add_option("--write", options->write_dir, "Also time a full `rovo render` of the frames into this folder");
  cmd->add_option("--against", options->against,
                  "Also time the default-quality render of this preset (e.g. cloudy_urban), frame by frame in turn "
                  "with the scene's, and print the ratio of their CPU per frame");
  cmd->callback([options] { RunRenderBenchmark(*options); });
}

}  // namespace

void AddBenchCommands(CommandTree& tree) {
  AddRenderBenchCommand(tree.bench);

  // `rovo bench vo`.
  auto bench_args = std::make_shared<VoArgs>();
  CLI::App* bench = tree.bench->add_subcommand(
      "vo",
      "Time the whole pipeline on a dataset (full image size) and print a table of mean ms per frame by stage, "
      "with a machine reference taken before and after the run (full-size hybrid warps by cv::remap, one per core "
      "at once); compare speeds only between runs whose references agree");
  AddVoRunOptions(bench, bench_args.get());
  bench->add_option("--out", bench_args->options.io.out_dir,
                    "Run folder to write (default: DATASET_bench_vo_run, beside the dataset; with --against-mode "
                    "one folder per mode, OUT_<mode>)");
  bench->add_flag("--preload", bench_args->options.io.preload,
                  "Decode every frame's images before timing (a live rig delivers decoded images; without it, the "
                  "replay decodes PNGs ahead on a thread of its own). Keeps all frames in memory: use --frames");
  CLI::Option* timed_from =
      bench
          ->add_option("--timed-from", bench_args->options.io.timed_from,
                       "Average the stage times over the frames from this index of the range on (the frames before it "
                       "run as usual), e.g. OnlineExt after its settle phase (--online-settle)")
          ->check(CLI::NonNegativeNumber)
          ->capture_default_str();
  auto floor = std::make_shared<bool>(false);
  CLI::Option* floor_flag = bench->add_flag(
      "--floor", *floor,
      "Instead of the pipeline: the front-end's CPU per frame against the floor, the bare OpenCV calls it "
      "is made of (remap in bands of rows, pyramid, LK with a backward pass, FAST, ORB, Hamming matching) with its "
      "parameters on the same images on one thread, by stage, and their ratio (eval/bench/vo_floor.h)");
  timed_from->excludes(floor_flag);
  auto against_mode = std::make_shared<std::string>();
  auto rounds = std::make_shared<int>(3);
  CLI::Option* against =
      bench
          ->add_option("--against-mode", *against_mode,
                       "Instead of the stage table: run the run's own extrinsics mode (--extrinsics) and this one in "
                       "turn, --rounds times (which runs first alternates; run folders OUT_<mode>), and print each "
                       "round's whole frame in both with their ratio, then the median ratio (e.g. --extrinsics online "
                       "--against-mode gt --timed-from 60: OnlineExt after its start-up against GTExt)")
          ->check(CLI::IsMember({"gt", "noisy", "online"}));
  against->excludes(floor_flag);
  bench->add_option("--rounds", *rounds, "Rounds of --against-mode")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->needs(against);
  bench->callback([bench, bench_args, floor, against_mode, rounds] {
    FinaliseVoArgs(bench, bench_args.get());
    if (*floor) {
      RunVoFloorBenchmark(bench_args->options);
      return;
    }
    if (!against_mode->empty()) {
      RunVoModeComparison(bench_args->options, ExtrinsicsModeFromName(*against_mode), *rounds);
      return;
    }
    RunVoBenchmark(bench_args->options);
  });
}

}  // namespace rovo
