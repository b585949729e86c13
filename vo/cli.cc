// `rovo` subcommands of vo/: `rovo vo` (run the pipeline on a dataset) and `rovo bench vo`.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <opencv2/core.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "datasets/cli_groups.h"
#include "datasets/rig.h"
#include "vo/hybrid_projection.h"
#include "vo/pipeline.h"
#include "vo/projection_study.h"
#include "vo/vo_options.h"

namespace rovo {
namespace {

// Machine reference printed with the bench table: full-size hybrid warps (rovo4, camera 0, a fixed
// random image), one per core on `cores` cores at once (shared caches and memory bandwidth included),
// median wall time of 31 rounds after 9 warm-up rounds (single rounds vary by 2x on this machine, the
// median by about 10 % between seconds). Measured before and after the run: the machine's speed
// drifts by a third or more between hours (the one-core warp took 6.8 ms one evening, 10.5 ms
// another), so runs are comparable only when their references agree.
double MachineReferenceWarpMs(int cores) {
  const Rig rig = MakeRigPreset("rovo4");
  const std::vector<HybridLayout> layouts = ComputeHybridLayouts(rig);
  const HybridProjection projection(rig.cameras[0].camera, rig.cameras[0].cam_from_rig, layouts[0]);
  cv::Mat image(rig.cameras[0].camera.height, rig.cameras[0].camera.width, CV_8UC1);
  cv::RNG(7).fill(image, cv::RNG::UNIFORM, 0, 255);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  std::vector<cv::Mat> warped(cores);
  std::vector<double> ms;
  for (int k = 0; k < 40; ++k) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> workers;
    for (int c = 0; c < cores; ++c) workers.emplace_back([&, c] { projection.Warp(image, &warped[c]); });
    for (std::thread& w : workers) w.join();
    const double round_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (k >= 9) ms.push_back(round_ms);  // the first rounds of a process run slow (warm-up)
  }
  cv::setNumThreads(threads);
  std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
  return ms[ms.size() / 2];
}

// --realtime: the two front-end settings that trade some accuracy for speed (docs/design-notes.md: warp extents).
// Measured 2026-11-24 on full-size cloudy_urban (150 frames, idle, images in memory): front-end 63 -> 45.5-47 ms wall
// per frame, whole pipeline 14.8 -> 19.8-20.4 frames/s; first 300 frames relative RMSE GTExt cloudy_urban 0.012 ->
// 0.025 %, sunset_urban 0.020 -> 0.018 %, OnlineExt 0.012 -> 0.025 % and 0.014 -> 0.012 %.
constexpr double kRealtimeWarpBelowDeg = 25.0;
constexpr int kRealtimeMaxNewFeatures = 150;

// Binds each field of the registry (ForEachVoOption, vo/vo_options.h) to its flag.
struct CliBinder {
  CLI::App* cmd;
  template <typename T>
  static std::string DefaultText(const T& value) {
    std::ostringstream text;
    text << value;
    return text.str();
  }
  // The range check of a numeric field (CLI11's own validators, as their help texts show them).
  template <typename T>
  static void AddRange(const OptionSpec& spec, CLI::Option* option) {
    if (spec.min == 0.0 && spec.max == kUnbounded) {
      option->check(CLI::NonNegativeNumber);
    } else if (spec.min != -kUnbounded || spec.max != kUnbounded) {
      option->check(CLI::Range(static_cast<T>(spec.min), static_cast<T>(spec.max)));
    }
  }
  template <typename T>
  void operator()(const OptionSpec& spec, T& value) {
    CLI::Option* option = cmd->add_option(spec.flag, value, spec.help);
    if (spec.flag[0] != '-') option->required();
    if constexpr (std::is_arithmetic_v<T>) AddRange<T>(spec, option);
    if (spec.show_default) option->capture_default_str();
  }
  void operator()(const OptionSpec& spec, bool& value) { cmd->add_flag(spec.flag, value, spec.help); }
  void operator()(const OptionSpec& spec, const InvertedFlag& field) {
    bool* value = field.value;
    cmd->add_flag(
        spec.flag, [value](int64_t) { *value = false; }, spec.help);
  }
  void operator()(const OptionSpec& spec, FrameRange& range) {
    FrameRange* target = &range;
    cmd->add_option_function<std::string>(
        spec.flag, [target](const std::string& text) { ParseFrameRange(text, &target->begin, &target->end); },
        spec.help);
  }
  void operator()(const OptionSpec& spec, const DegreesOfRadians& field) {
    double* radians = field.radians;
    CLI::Option* option = cmd->add_option_function<double>(
        spec.flag, [radians](double degrees) { *radians = degrees * M_PI / 180.0; }, spec.help);
    AddRange<double>(spec, option);
    if (spec.show_default) option->default_str(DefaultText(*radians * 180.0 / M_PI));
  }
  template <typename E>
  void operator()(const OptionSpec& spec, const Named<E>& field) {
    std::vector<std::string> names;
    for (const auto& entry : field.names) names.push_back(entry.second);
    auto table = field.names;
    E* value = field.value;
    CLI::Option* option = cmd->add_option_function<std::string>(
        spec.flag,
        [value, table](const std::string& name) {
          for (const auto& entry : table) {
            if (name == entry.second) *value = entry.first;
          }
        },
        spec.help);
    option->check(CLI::IsMember(names));
    for (const auto& entry : table) {
      if (spec.show_default && entry.first == *value) option->default_str(entry.second);
    }
  }
};

struct VoArgs {
  VoOptions options;
  bool realtime = false;
};

// Every registry field as a flag (one place), and --realtime.
void AddVoRunOptions(CLI::App* cmd, VoArgs* args) {
  CliBinder binder{cmd};
  ForEachVoOption(args->options, binder);
  cmd->add_flag("--realtime", args->realtime,
                "Real-time profile for full-size live rigs: --warp-below 25 --max-new-features 150 unless given "
                "(front-end about 28 % cheaper, trajectories slightly less accurate; docs/design-notes.md)");
}

void Finalise(CLI::App* cmd, VoArgs* args) {
  if (args->realtime) {
    FrontendOptions& frontend = args->options.frontend;
    if (cmd->get_option("--warp-below")->count() == 0)
      frontend.projection.vertical_fov_below_deg = kRealtimeWarpBelowDeg;
    if (cmd->get_option("--max-new-features")->count() == 0)
      frontend.max_new_features_per_view = kRealtimeMaxNewFeatures;
  }
}

}  // namespace

void AddVoCommands(CliGroups& groups) {
  auto args = std::make_shared<VoArgs>();
  CLI::App* cmd = groups.root->add_subcommand(
      "vo",
      "Run the ROVO visual odometry on a dataset and write a run folder (trajectory.tum, frames.csv, "
      "extrinsics.csv, run.json). Starts at the ground-truth first pose; metric scale from inter-view "
      "triangulation.");
  AddVoRunOptions(cmd, args.get());
  cmd->add_option("--out", args->options.io.out_dir, "Run folder to write")->required();
  cmd->callback([cmd, args] {
    Finalise(cmd, args.get());
    const VoSummary s = RunVo(args->options);
    std::printf(
        "%d frames (%d ok, %d init, %d lost) in %.1f s (%.1f frames/s); mean inlier ratio %.1f%%, mean "
        "reprojection error %.3f deg -> %s\n",
        s.frames, s.frames_ok, s.frames_init, s.frames_lost, s.seconds, s.frames / std::max(s.seconds, 1e-9),
        100.0 * s.mean_inlier_ratio, s.mean_reproj_error_deg, args->options.io.out_dir.c_str());
    if (s.missing_images > 0) {
      std::printf("warning: %d image%s missing or unreadable in %d frame%s (frames.csv missing_cameras)\n",
                  s.missing_images, s.missing_images == 1 ? "" : "s", s.frames_with_missing_images,
                  s.frames_with_missing_images == 1 ? "" : "s");
    }
  });

  auto bench_args = std::make_shared<VoArgs>();
  CLI::App* bench = groups.bench->add_subcommand(
      "vo",
      "Time the whole pipeline on a dataset (full image size) and print a table of mean ms per frame by stage, "
      "with a machine reference taken before and after the run (full-size hybrid warps, one per core at once); "
      "compare speeds only between runs whose references agree");
  AddVoRunOptions(bench, bench_args.get());
  bench->add_option("--out", bench_args->options.io.out_dir, "Run folder to write (default: DATASET/../bench_vo_run)");
  bench->add_flag("--preload", bench_args->options.io.preload,
                  "Decode every frame's images before timing (a live rig delivers decoded images; PNG decoding costs "
                  "about 30 CPU-ms per full-size view). Keeps all frames in memory: use --frames");
  bench->callback([bench, bench_args] {
    Finalise(bench, bench_args.get());
    VoOptions options = bench_args->options;
    if (options.io.out_dir.empty()) options.io.out_dir = options.io.dataset_dir + "_bench_vo_run";
    const int cores = options.io.threads > 0 ? options.io.threads
                                             : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    const double reference_before_ms = MachineReferenceWarpMs(cores);
    const VoSummary s = RunVo(options);
    const double reference_after_ms = MachineReferenceWarpMs(cores);
    const VoStageTimes& t = s.stage_ms;
    std::printf("rovo bench vo: %s, mode %s, %d frames, threads %d\n", options.io.dataset_dir.c_str(),
                ExtrinsicsModeName(options.start.mode).c_str(), s.frames, options.io.threads);
    // CPU = process CPU time of all threads (FrontendFrame::cpu_ms_*); measured for the front-end only. It
    // includes the image decoder and an async BA running meanwhile: use --preload --sync-ba for the
    // front-end's own CPU time.
    std::printf(
        "| stage                     | ms/frame | CPU ms/frame |\n"
        "|---------------------------|---------:|-------------:|\n");
    const double frontend_wall = t.warp + t.detect + t.track + t.match;
    const double frontend_cpu = t.cpu_warp + t.cpu_detect + t.cpu_track + t.cpu_match;
    const struct {
      const char* name;
      double wall, cpu;  // cpu < 0: not measured
    } rows[] = {{"load images (wait)", t.load, -1},
                {"front-end: warp", t.warp, t.cpu_warp},
                {"front-end: detect", t.detect, t.cpu_detect},
                {"front-end: track", t.track, t.cpu_track},
                {"front-end: match", t.match, t.cpu_match},
                {"front-end: total", frontend_wall, frontend_cpu},
                {"back-end: RANSAC", t.ransac, -1},
                {"back-end: refine", t.refine, -1},
                {"back-end: triangulate", t.triangulate, -1},
                {"back-end: local BA solve", t.ba, -1},
                {"back-end: wait for BA", t.ba_wait, -1},
                {"back-end: in-line total", t.backend_total, -1},
                {"whole frame", t.total, -1}};
    for (const auto& row : rows) {
      if (row.cpu >= 0) {
        std::printf("| %-25s | %8.2f | %12.2f |\n", row.name, row.wall, row.cpu);
      } else {
        std::printf("| %-25s | %8.2f |            - |\n", row.name, row.wall);
      }
    }
    std::printf("RANSAC: %.2f us per hypothesis\n", t.ransac_us_per_hypothesis);
    std::printf("local BA: %s\n", options.backend.async_ba
                                      ? "solved on its own thread beside the next frame's front-end "
                                        "(in-line total = wait for it + the rest)"
                                      : "solved in line (--sync-ba)");
    std::printf("whole pipeline: %.2f frames/s (target 10 Hz)%s\n", t.total > 0 ? 1000.0 / t.total : 0.0,
                options.io.preload ? ", images decoded beforehand" : ", images decoded on a second thread");
    std::printf(
        "machine reference: one full-size hybrid warp per core on %d core%s at once: %.2f ms before the run, "
        "%.2f ms after\n",
        cores, cores == 1 ? "" : "s", reference_before_ms, reference_after_ms);
    const double reference_low_ms = std::min(reference_before_ms, reference_after_ms);
    if (std::abs(reference_after_ms - reference_before_ms) > 0.2 * reference_low_ms) {
      std::printf(
          "warning: the machine's speed changed by more than 20 %% during the run; repeat it before "
          "comparing\n");
    }
  });

  AddProjectionStudyCommand(groups);
}

}  // namespace rovo
