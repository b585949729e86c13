#pragma once
// Time-stamped rig poses and the TUM trajectory text format
// (`timestamp tx ty tz qx qy qz qw`, one pose per line, holding world_from_rig).

#include <string>
#include <vector>

#include "datasets/rigid3.h"

namespace rovo {

struct StampedPose {
  double timestamp = 0.0;  // seconds
  Rigid3 world_from_rig;
};

using Trajectory = std::vector<StampedPose>;

// Throws std::runtime_error naming the file and line on malformed input: not 8 numbers, NaN/Inf,
// quaternion norm off 1 by more than 1e-3 (it is normalised otherwise), timestamps not increasing.
Trajectory ReadTum(const std::string& path);
// Atomic write (temp file then rename), full double precision.
void WriteTum(const std::string& path, const Trajectory& trajectory);
// KITTI format: 12 numbers per line, row-major 3x4 world_from_rig.
void WriteKitti(const std::string& path, const Trajectory& trajectory);

// Trajectories written by other systems (timestamps converted to seconds):
// TUM whose timestamps may be nanoseconds: taken as ns when the median interval exceeds 1000 or a
// timestamp exceeds 1e12 (no sequence is sampled once in 17 minutes or lasts 30000 years);
// `nanoseconds` (optional) says which.
Trajectory ReadTumAnyUnit(const std::string& path, bool* nanoseconds = nullptr);
// EuRoC csv (`#timestamp [ns], p x, p y, p z, q w, q x, q y, q z[, more columns]`, commas, the
// state_groundtruth_estimate0/data.csv layout), holding world_from_body.
Trajectory ReadEurocCsv(const std::string& path);
// KITTI poses (12 numbers per line, row-major 3x4 world_from_rig), which carry no time: line i is
// given timestamps[i]; more lines than timestamps throws.
Trajectory ReadKittiPoses(const std::string& path, const std::vector<double>& timestamps);

// One data line of a TUM file before any interpretation (for validators that report every fault).
struct TumLine {
  int line_number = 0;                          // 1-based line in the file
  double values[8] = {0, 0, 0, 0, 0, 0, 0, 0};  // timestamp tx ty tz qx qy qz qw, all finite
};
// Splits TUM text into data lines (skips blank lines and `#` comments). A malformed line (not 8
// numbers, NaN/Inf) throws std::runtime_error "<path>: line N: ..." when `errors` is null, else is
// appended to `errors` and skipped.
std::vector<TumLine> ParseTumText(const std::string& text, const std::string& path,
                                  std::vector<std::string>* errors = nullptr);
// The TUM text WriteTum writes (a `#` header line, then `%.17g` numbers).
std::string FormatTum(const Trajectory& trajectory);

// Pose at time t by interpolation (slerp + linear); clamps outside the range.
Rigid3 InterpolatePose(const Trajectory& trajectory, double t);
// Sum of distances between consecutive positions.
double PathLength(const Trajectory& trajectory);

}  // namespace rovo
