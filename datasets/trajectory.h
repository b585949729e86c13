#pragma once
// Time-stamped rig poses and the TUM trajectory text format
// (`timestamp tx ty tz qx qy qz qw`, one pose per line, holding world_from_rig).

#include "datasets/rigid3.h"

#include <string>
#include <vector>

namespace rovo {

struct StampedPose {
  double timestamp = 0.0;  // seconds
  Rigid3 world_from_rig;
};

using Trajectory = std::vector<StampedPose>;

// Throws std::runtime_error naming the file and line on malformed input.
Trajectory ReadTum(const std::string& path);
// Atomic write (temp file then rename), full double precision.
void WriteTum(const std::string& path, const Trajectory& trajectory);
// KITTI format: 12 numbers per line, row-major 3x4 world_from_rig.
void WriteKitti(const std::string& path, const Trajectory& trajectory);

// Pose at time t by interpolation (slerp + linear); clamps outside the range.
Rigid3 InterpolatePose(const Trajectory& trajectory, double t);
// Sum of distances between consecutive positions.
double PathLength(const Trajectory& trajectory);

}  // namespace rovo
