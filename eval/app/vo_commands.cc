// `rovo vo`: run the pipeline on a dataset (vo/pipeline.h); its options are shared with `rovo bench vo`.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "eval/app/commands.h"
#include "eval/app/vo_args.h"
#include "vo/pipeline.h"
#include "vo/vo_options.h"

namespace rovo {
namespace {

// --realtime: the two front-end settings that trade some accuracy for speed (docs/design-notes.md: warp extents,
// the real-time profile).
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

}  // namespace

// Every registry field as a flag (one place), and --realtime.
void AddVoRunOptions(CLI::App* cmd, VoArgs* args) {
  CliBinder binder{cmd};
  ForEachVoOption(args->options, binder);
  cmd->add_flag("--realtime", args->realtime,
                "Real-time profile for full-size live rigs: --warp-below 25 --max-new-features 150 unless given "
                "(front-end about 28 % cheaper, trajectories slightly less accurate; docs/design-notes.md)");
}

void FinaliseVoArgs(CLI::App* cmd, VoArgs* args) {
  if (args->realtime) {
    FrontendOptions& frontend = args->options.frontend;
    if (cmd->get_option("--warp-below")->count() == 0)
      frontend.projection.vertical_fov_below_deg = kRealtimeWarpBelowDeg;
    if (cmd->get_option("--max-new-features")->count() == 0)
      frontend.max_new_features_per_view = kRealtimeMaxNewFeatures;
  }
}

void AddVoCommands(CommandTree& tree) {
  auto args = std::make_shared<VoArgs>();
  CLI::App* cmd = tree.root->add_subcommand(
      "vo",
      "Run the ROVO visual odometry on a dataset and write a run folder (trajectory.tum, frames.csv, "
      "extrinsics.csv, run.json). Starts at the ground-truth first pose; metric scale from inter-view "
      "triangulation.");
  AddVoRunOptions(cmd, args.get());
  cmd->add_option("--out", args->options.io.out_dir, "Run folder to write")->required();
  cmd->callback([cmd, args] {
    FinaliseVoArgs(cmd, args.get());
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
}

}  // namespace rovo
