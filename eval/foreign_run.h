#pragma once
// Runs written by other systems: a trajectory file (or a folder holding one) without rovo's
// frames.csv / run.json / extrinsics.csv. Formats: TUM with timestamps in seconds or nanoseconds,
// EuRoC csv (`timestamp [ns], p xyz, q wxyz, ...`), KITTI poses (matched to the ground truth by line).
// Such a run gets mode "external"; the metrics that need frames.csv or extrinsics.csv (inlier ratio,
// reprojection error, extrinsic error, time per frame) are reported as n/a.

#include <string>

#include "datasets/run.h"

namespace rovo {

// `format`: auto | tum | euroc | kitti. auto: a folder with run.json is a rovo run; otherwise the
// trajectory file (the path itself, or in a folder the one file named trajectory.tum / .txt / .csv,
// trajectory_kitti.txt, stamped_traj_estimate.txt, f_*.txt, poses.txt or data.csv) by its extension and first data line
// (commas: EuRoC; 12 numbers: KITTI; 8 numbers: TUM). Estimate timestamps that do not overlap the
// ground truth's span at all (another start time) are shifted so that the first estimate falls on
// the first ground-truth time; `note` (optional) says what was read and done.
// Throws std::runtime_error naming the path.
RunData ReadRunOrTrajectory(const std::string& path, const Trajectory& gt, const std::string& format = "auto",
                            std::string* note = nullptr);

}  // namespace rovo
