#pragma once
// `rovo study calibration`: how often OnlineExt's extrinsic calibration converges, over fresh seeded
// perturbation draws (the paper's protocol, datasets/rig.h PerturbExtrinsics), not the dataset's
// stored noise sets.
//
// Per draw (seed = first_seed + index): the extrinsic error (the largest over
// cameras i >= 1 of the angle of est(cam_i_from_cam0) true(cam_i_from_cam0)^-1, against the
// dataset's rig) of the draw itself, after the start-up calibration, at frames 50 and 100 of the
// OnlineExt run and at its end. `shot_only` runs the start-up calibration alone on one synchronous
// shot (no VO: also for datasets without ground-truth poses, such as real captures, where the
// reference is the dataset's own calibration).

#include <cstdint>
#include <string>
#include <vector>

#include "datasets/rigid3.h"
#include "eval/studies/overlap_fit.h"

namespace rovo {

struct CalibrationStudyOptions {
  std::string dataset_dir;
  std::string out_dir;
  int draws = 20;
  double sigma_deg = 5.0;
  uint64_t first_seed = 1000;  // draw k has seed first_seed + k (rovo vo --draw-seed)
  int frames = 0;              // > 0: the OnlineExt runs cover the first N frames; 0: all
  bool shot_only = false;      // start-up calibration on one shot, no VO
  int shot = 0;                // the shot (first frame)
  int startup_shots = 0;       // shots pooled by the start-up calibration; 0: 1 with shot_only, else
                               // VoOptions::online_startup_shots' default
  int shot_spacing = 10;       // VoOptions::online_startup_spacing (frames between two shots)
  int max_shots = 0;           // shots where the first attempt's overlaps are poor
                               // (VoOptions::online_startup_max_shots); 0: startup_shots with
                               // shot_only (none added), else rovo vo's default
  int threads = 0;
  double converged_deg = 0.1;       // the run's final error below: converged
  double shot_converged_deg = 0.5;  // shot_only: the start-up error below: converged
  double bound_deg = -1.0;          // > 0: replaces converged_deg / shot_converged_deg
  bool quiet = false;
  // Frames whose own overlap matches judge the dataset's calibration against the converged start-up
  // results (eval/overlap_fit.h); empty: none.
  std::vector<int> fit_frames;
};

struct CalibrationDraw {
  uint64_t seed = 0;
  double before_deg = 0.0;
  double startup_deg = 0.0;
  double at50_deg = -1.0, at100_deg = -1.0, end_deg = -1.0;  // < 0: the run is shorter / shot only
  double startup_mm = 0.0, end_mm = -1.0;                    // ExtrinsicTranslationErrorM in mm; end < 0: shot only
  bool startup_converged = false;                            // the start-up calibration's own verdict
  std::string startup_status;
  double lens_angle_scale = 1.0;             // the start-up's estimate of the lenses' off-axis angle scale
  bool converged = false;                    // the study's verdict (error below the bound)
  std::vector<Rigid3> startup_cam_from_rig;  // the start-up calibration's result
};

struct CalibrationStudyResult {
  std::vector<CalibrationDraw> draws;
  int converged = 0;
  // Largest extrinsic difference (ExtrinsicErrorDeg) between the start-up results of two draws whose
  // start-up calibration converged by its own verdict; -1: fewer than two such draws.
  double startup_agreement_deg = -1.0;
  int startup_converged = 0;
  std::string reproduce;   // command template for one draw ("{seed}" replaced)
  OverlapFit overlap_fit;  // with fit_frames
};

// The extrinsic error in degrees (above) of `est` against `truth` (cam_from_rig per camera).
double ExtrinsicErrorDeg(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth);
// Largest over cameras i >= 1 of |t_est - t_true| of cam_i_from_cam0 (metres): camera 0's centre in
// camera i's frame, so a baseline turned in the cameras' frames counts as well as a moved centre.
double ExtrinsicTranslationErrorM(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth);

CalibrationStudyResult RunCalibrationStudy(const CalibrationStudyOptions& options);

// calibration.md: the per-draw table, the rates and the reproducing commands (also printed by the command).
std::string CalibrationStudyTable(const CalibrationStudyOptions& options, const CalibrationStudyResult& result);

}  // namespace rovo
