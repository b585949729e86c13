#pragma once
// What the scene folder's saver and loader share (internal to scenes/): the format version and the
// fixed file names of scenes/FORMAT.md.

#include <Eigen/Core>
#include <cstdint>
#include <cstring>

namespace rovo::scene_io_internal {

inline constexpr int kFormatVersion = 1;
inline constexpr const char* kGeometryFile = "geometry.bin";
inline constexpr const char* kMotionFile = "motion.bin";
inline constexpr const char* kTrajectoryFile = "trajectory.tum";

static_assert(sizeof(Eigen::Vector3f) == 12 && sizeof(Eigen::Vector2f) == 8 && sizeof(Eigen::Vector3i) == 12,
              "mesh arrays are copied as packed float32/int32 records");

// The binary buffers are little-endian; both directions refuse other hosts.
inline bool HostIsLittleEndian() {
  const uint32_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

}  // namespace rovo::scene_io_internal
