// `rovo study projection | calibration`: the paper's analyses (eval/studies/).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>

#include "eval/app/commands.h"
#include "eval/studies/calibration_study.h"
#include "eval/studies/image_statistics.h"
#include "eval/studies/projection_study.h"

namespace rovo {
namespace {

void AddProjectionStudyCommand(CLI::App* study) {
  auto options = std::make_shared<ProjectionStudyOptions>();
  CLI::App* cmd = study->add_subcommand(
      "projection",
      "Paper Table II on a dataset: ORB descriptor distance of tracked features (first frame vs later) and "
      "inter-view matching inlier ratio (verified with the dataset's depth; descriptors only, epipolar-consistent, "
      "and the front-end's filter chain), raw fisheye vs hybrid projection. Writes table.md, study.json and match "
      "drawings. Needs a dataset rendered with --depth.");
  cmd->add_option("dataset", options->dataset_dir, "Dataset folder (with depth/)")->required();
  cmd->add_option("--out", options->out_dir, "Output folder")->required();
  cmd->add_option("--frames", options->frames, "Frames to use from the start")
      ->capture_default_str()
      ->check(CLI::Range(2, 1000000));
  cmd->add_option("--features", options->features_per_view, "Tracker target features per view")
      ->capture_default_str()
      ->check(CLI::Range(10, 100000));
  cmd->add_option("--epipolar-deg", options->epipolar_deg, "Epipolar consistency threshold of part (b), degrees")
      ->capture_default_str();
  cmd->add_option("--inlier-px", options->inlier_px, "Ground-truth inlier tolerance, fisheye pixels")
      ->capture_default_str();
  InterviewMatchOptions& m = options->frontend_matching;
  cmd->add_option("--fe-max-ratio", m.max_ratio, "Front-end column: descriptor ratio test")->capture_default_str();
  cmd->add_option("--fe-min-zncc", m.min_zncc, "Front-end column: minimum ZNCC")->capture_default_str();
  cmd->add_option("--fe-epipolar-deg", m.max_epipolar_angle_deg, "Front-end column: epipolar threshold, degrees")
      ->capture_default_str();
  cmd->add_option("--fe-y-px", m.max_y_distance_px, "Front-end column: y-distance threshold, warped px")
      ->capture_default_str();
  cmd->add_option("--fe-uniqueness-margin", m.uniqueness_margin, "Front-end column: epipolar uniqueness margin")
      ->capture_default_str();
  cmd->add_option("--fe-uniqueness-deg", m.uniqueness_range_deg, "Front-end column: epipolar uniqueness half-range")
      ->capture_default_str();
  cmd->add_flag("!--fe-no-uniqueness", m.use_uniqueness, "Front-end column: no epipolar uniqueness scan");
  cmd->add_flag("!--oriented", options->upright_descriptors,
                "ORB descriptors at the intensity-centroid orientation in both arms instead of upright (angle 0, the "
                "front-end's default)");
  cmd->add_flag("--quiet", options->quiet, "No progress output");
  cmd->callback([options] {
    const ProjectionStudyResult r = RunProjectionStudy(*options);
    std::printf("descriptor distance (first vs later): fisheye %.2f, hybrid %.2f (%lld / %lld pairs)\n",
                r.hamming_fisheye, r.hamming_hybrid, static_cast<long long>(r.tracked_pairs_fisheye),
                static_cast<long long>(r.tracked_pairs_hybrid));
    std::printf("inter-view inlier ratio: fisheye %.2f%% (%lld), hybrid %.2f%% (%lld), front-end %.2f%% (%lld)\n",
                100.0 * r.InlierRatioFisheye(), static_cast<long long>(r.matches_fisheye),
                100.0 * r.InlierRatioHybrid(), static_cast<long long>(r.matches_hybrid),
                100.0 * r.InlierRatioFrontend(), static_cast<long long>(r.matches_frontend));
    std::printf("wrote %s/table.md\n", options->out_dir.c_str());
  });
}

void AddCalibrationStudyCommand(CLI::App* study) {
  auto options = std::make_shared<CalibrationStudyOptions>();
  CLI::App* cmd = study->add_subcommand(
      "calibration",
      "Convergence of OnlineExt's extrinsic calibration over fresh seeded perturbation draws: per draw the "
      "extrinsic rotation error before, after the start-up calibration, at frames 50 and 100 and at the end, and the "
      "translation error (mm) after the start-up and at the end; the rate; a CDF plot; the seeds of failures with the "
      "command that reproduces each");
  cmd->add_option("dataset", options->dataset_dir, "Dataset folder")->required();
  cmd->add_option("--out", options->out_dir, "Output folder (calibration.md/.csv/.json, cdf.png, runs/)")->required();
  cmd->add_option("--draws", options->draws, "Perturbation draws")->check(CLI::Range(1, 100000))->capture_default_str();
  cmd->add_option("--sigma", options->sigma_deg, "Sigma of roll, pitch and yaw per camera (degrees)")
      ->check(CLI::Range(0.0, 45.0))
      ->capture_default_str();
  cmd->add_option("--seed", options->first_seed, "Seed of the first draw; draw k has seed + k")->capture_default_str();
  cmd->add_option("--frames", options->frames, "OnlineExt runs over the first N frames (0: all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag(
      "--shot-only", options->shot_only,
      "Start-up calibration only, on one synchronous shot or --startup-shots pooled (no VO; no ground-truth poses "
      "needed)");
  cmd->add_option("--shot", options->shot, "The frame of --shot-only")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option(
         "--startup-shots", options->startup_shots,
         "Shots pooled by the start-up calibration, every --shot-spacing frames (rovo vo --online-startup-shots); "
         "default: 1 with --shot-only, else rovo vo's default")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--shot-spacing", options->shot_spacing, "Frames between two shots of --startup-shots")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--max-shots", options->max_shots,
                  "Shots where the first attempt's overlaps are poor (rovo vo --online-startup-max-shots); default: "
                  "--startup-shots with --shot-only (none added), else rovo vo's default")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--bound", options->bound_deg,
                  "A draw converged when its error ends below this (degrees; default 0.5 with --shot-only, else 0.1)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", options->threads, "Threads of each run (0: all cores)")->capture_default_str();
  cmd->add_option("--fit-frames", options->fit_frames,
                  "Frames whose own overlap matches judge the dataset's calibration against the converged start-up "
                  "results (inliers and residuals per ring pair)")
      ->delimiter(',');
  cmd->add_flag("--quiet", options->quiet, "No progress output");
  cmd->callback([options] {
    const CalibrationStudyResult result = RunCalibrationStudy(*options);
    std::printf("%s", CalibrationStudyTable(*options, result).c_str());
  });
}

void AddImageStatisticsCommand(CLI::App* study) {
  auto options = std::make_shared<ImageStatisticsOptions>();
  auto inputs = std::make_shared<std::vector<std::string>>();
  CLI::App* cmd = study->add_subcommand(
      "images",
      "Image-quality statistics of fisheye frames (eval/studies/image_statistics.h): share of spectral power above "
      "1/4 Nyquist and spectrum slope of a Hann-windowed central crop, Immerkaer's noise sigma over the valid "
      "circle, rim/centre brightness; a Markdown table, one row per image and the mean, min and max");
  cmd->add_option("inputs", *inputs, "Image files or folders (searched recursively for .png/.jpg)")->required();
  cmd->add_option("--crop", options->crop, "Side of the central crop of the spectrum, pixels")->capture_default_str();
  cmd->add_option("--circle", options->circle_fraction,
                  "Valid circle of the noise estimate, fraction of the short side")
      ->capture_default_str();
  cmd->add_option("--ring-inner", options->ring_inner, "Rim ring, inner radius, fraction of the short side")
      ->capture_default_str();
  cmd->add_option("--ring-outer", options->ring_outer, "Rim ring, outer radius, fraction of the short side")
      ->capture_default_str();
  cmd->add_option("--centre", options->centre_fraction, "Central disc radius, fraction of the short side")
      ->capture_default_str();
  cmd->callback([options, inputs] {
    std::vector<std::string> files;
    for (const std::string& in : *inputs) {
      const std::vector<std::string> found = ListImageFiles(in);
      files.insert(files.end(), found.begin(), found.end());
    }
    std::printf("%s", ImageStatisticsTable(files, ComputeImageFileStatistics(files, *options)).c_str());
  });
}

}  // namespace

void AddStudyCommands(CommandTree& tree) {
  AddProjectionStudyCommand(tree.study);
  AddCalibrationStudyCommand(tree.study);
  AddImageStatisticsCommand(tree.study);
}

}  // namespace rovo
