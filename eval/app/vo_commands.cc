// `rovo vo`: run the pipeline on a dataset (vo/pipeline.h); its options are shared with `rovo bench vo`.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "eval/app/commands.h"
#include "eval/app/vo_args.h"
#include "vo/pipeline.h"

namespace rovo {
namespace {

// --realtime: the two front-end settings that trade some accuracy for speed (docs/design-notes.md: warp extents).
// Measured 2026-11-24 on full-size cloudy_urban (150 frames, idle, images in memory): front-end 63 -> 45.5-47 ms wall
// per frame, whole pipeline 14.8 -> 19.8-20.4 frames/s; first 300 frames relative RMSE GTExt cloudy_urban 0.012 ->
// 0.025 %, sunset_urban 0.020 -> 0.018 %, OnlineExt 0.012 -> 0.025 % and 0.014 -> 0.012 %.
constexpr double kRealtimeWarpBelowDeg = 25.0;
constexpr int kRealtimeMaxNewFeatures = 150;

}  // namespace

void AddVoRunOptions(CLI::App* cmd, VoArgs* args) {
  cmd->add_option("dataset", args->options.dataset_dir, "Dataset folder (datasets/FORMAT.md)")->required();
  cmd->add_option("--extrinsics", args->extrinsics,
                  "Extrinsics: gt (GTExt), noisy (NoisyExt: a perturbed set, fixed) or online (OnlineExt: a perturbed "
                  "set, calibrated online in the local BA)")
      ->check(CLI::IsMember({"gt", "noisy", "online"}))
      ->capture_default_str();
  cmd->add_option("--noise-set", args->options.noise_set, "Index of the perturbed extrinsic set in dataset.json")
      ->capture_default_str();
  cmd->add_option("--draw-seed", args->options.draw_seed,
                  "noisy/online: start from a fresh perturbation draw with this seed instead of a stored set "
                  "(sigma --draw-sigma on roll, pitch and yaw of every camera; recorded in run.json)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--draw-sigma", args->options.draw_sigma_deg, "Sigma of a --draw-seed draw in degrees")
      ->check(CLI::Range(0.0, 45.0))
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "RANSAC seed (recorded in run.json)")->capture_default_str();
  cmd->add_option("--frames", args->frames, "Frame range A:B (B exclusive; default: all frames)");
  cmd->add_option("--threads", args->options.threads, "Worker threads of the front-end (0: all cores)")
      ->capture_default_str();
  cmd->add_option("--sampling", args->options.sampling, "RANSAC view sampling: pps (paper) or uniform (ablation)")
      ->check(CLI::IsMember({"pps", "uniform"}))
      ->capture_default_str();
  cmd->add_option("--ransac", args->options.ransac,
                  "RANSAC scoring: multiview (paper: all views) or single-view (ablation: one view)")
      ->check(CLI::IsMember({"multiview", "single-view"}))
      ->capture_default_str();
  cmd->add_option("--online-prior", args->options.online_prior_deg,
                  "OnlineExt: bound on the starting extrinsics' rotation error in degrees, used only when the "
                  "start-up calibration's prior-free ring stage fails (its loose-filter refinement then starts this "
                  "loose); 0: no start-up calibration, BA only (an ablation, which does not correct errors of degrees)")
      ->check(CLI::Range(0.0, 45.0))
      ->capture_default_str();
  cmd->add_option("--online-startup-shots", args->options.online_startup_shots,
                  "OnlineExt: synchronous shots (every --online-startup-spacing frames from the first) pooled by the "
                  "start-up calibration")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--online-anchor", args->options.online_anchor_deg,
                  "OnlineExt: rotation sigma (degrees) with which every keyframe BA pulls the extrinsics towards a "
                  "converged start-up calibration's result; 0: none")
      ->check(CLI::Range(0.0, 45.0))
      ->capture_default_str();
  cmd->add_option("--online-anchor-mm", args->options.online_anchor_mm,
                  "OnlineExt: with --online-anchor, the camera centres' sigma (mm) towards the start-up's result; "
                  "0: the centres are not held")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option_function<std::string>(
         "--online-lens-scale", [args](const std::string& v) { args->options.online_apply_lens_scale = v == "apply"; },
         "OnlineExt: apply (default) | report. apply: when the start-up calibration converges with an angle scale of "
         "the lenses (a lens calibration that misjudges angles near the rim), the VO sees through lenses scaled by "
         "it; report: the dataset's lenses, the scale only in run.json")
      ->check(CLI::IsMember({"apply", "report"}));
  cmd->add_option("--online-startup-spacing", args->options.online_startup_spacing,
                  "OnlineExt: frames between two shots of --online-startup-shots")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--tau", args->options.ransac_tau_deg,
                  "RANSAC inlier threshold in degrees: the angle between observed and predicted bearing, the same "
                  "for every rig (recorded in run.json)")
      ->check(CLI::Range(0.01, 10.0))
      ->capture_default_str();
  cmd->add_option("--online-settle", args->options.online_settle_frames,
                  "OnlineExt: frames during which the calibration settles and observations up to 2 deg off are kept; "
                  "afterwards the RANSAC threshold rejects them, as in GTExt (default 50, recorded in run.json)")
      ->check(CLI::Range(0, 1000000));
  args->max_new_features =
      cmd->add_option("--max-new-features", args->options.max_new_features,
                      "New detections per view and frame at most, while the view has tracks (0: fill up to the target "
                      "count of 600). 150 makes the front-end about a fifth cheaper and the trajectories slightly less "
                      "accurate (docs/design-notes.md, docs/results.md)")
          ->check(CLI::Range(0, 100000))
          ->capture_default_str();
  args->warp_below =
      cmd->add_option(
             "--warp-below", args->options.warp_below_deg,
             "Degrees below the rig plane that the hybrid warp reaches; features are tracked and detected only "
             "inside it (recorded in run.json). 25 makes the full-size front-end about 18 % cheaper (the road "
             "beside the vehicle, where fresh features die at once) at neutral full-size accuracy, but costs "
             "accuracy at small image sizes (docs/design-notes.md: warp extents)")
          ->check(CLI::Range(1.0, 85.0))
          ->capture_default_str();
  cmd->add_option("--keyframe-distance", args->options.keyframe_distance_m,
                  "Rig travel in metres that makes a keyframe (and a local BA); 0: the default, recorded in run.json")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_flag(
      "--sync-ba", [args](int64_t) { args->options.async_ba = false; },
      "Run each keyframe BA before the next frame's front-end instead of beside it (same GTExt/NoisyExt "
      "result, slower; OnlineExt's front-end then sees the calibration one frame earlier)");
  cmd->add_flag("--realtime", args->realtime,
                "Real-time profile for full-size live rigs: --warp-below 25 --max-new-features 150 unless given "
                "(front-end about 28 % cheaper, trajectories slightly less accurate; docs/design-notes.md)");
  cmd->add_flag("--quiet", args->options.quiet, "No progress output");
}

void FinaliseVoArgs(VoArgs* args) {
  args->options.mode = ExtrinsicsModeFromName(args->extrinsics);
  ParseFrameRange(args->frames, &args->options.frame_begin, &args->options.frame_end);
  if (args->realtime) {
    if (args->warp_below->count() == 0) args->options.warp_below_deg = kRealtimeWarpBelowDeg;
    if (args->max_new_features->count() == 0) args->options.max_new_features = kRealtimeMaxNewFeatures;
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
  cmd->add_option("--out", args->options.out_dir, "Run folder to write")->required();
  cmd->callback([args] {
    FinaliseVoArgs(args.get());
    const VoSummary s = RunVo(args->options);
    std::printf(
        "%d frames (%d ok, %d init, %d lost) in %.1f s (%.1f frames/s); mean inlier ratio %.1f%%, mean "
        "reprojection error %.3f deg -> %s\n",
        s.frames, s.frames_ok, s.frames_init, s.frames_lost, s.seconds, s.frames / std::max(s.seconds, 1e-9),
        100.0 * s.mean_inlier_ratio, s.mean_reproj_error_deg, args->options.out_dir.c_str());
    if (s.missing_images > 0) {
      std::printf("warning: %d image%s missing or unreadable in %d frame%s (frames.csv missing_cameras)\n",
                  s.missing_images, s.missing_images == 1 ? "" : "s", s.frames_with_missing_images,
                  s.frames_with_missing_images == 1 ? "" : "s");
    }
  });
}

}  // namespace rovo
