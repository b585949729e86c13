// Fuzz target: trajectories of other systems (ReadRunOrTrajectory). The first byte picks the file
// name in the run folder (and so the detected format); the rest is the file.
#include "eval/foreign_run.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("foreign_run");
  static const char* const kNames[] = {"trajectory.tum", "trajectory.txt", "trajectory.csv",           "data.csv",
                                       "poses.txt",      "f_kitti.txt",    "stamped_traj_estimate.txt"};
  static const char* const kFormats[] = {"auto", "tum", "euroc", "kitti"};
  if (size < 1) return 0;
  const std::string dir = scratch.Fresh("run");
  const std::string file = dir + "/" + kNames[data[0] % 7];
  rovo::fuzz::WriteBytes(file, data + 1, size - 1);
  rovo::Trajectory gt;
  for (int i = 0; i < 5; ++i) gt.push_back({0.1 * i, rovo::Rigid3()});
  for (const char* format : kFormats) {
    std::string note;
    rovo::fuzz::ExpectClearError({file}, [&] { rovo::ReadRunOrTrajectory(file, gt, format, &note); });
  }
  std::string note;
  rovo::fuzz::ExpectClearError({dir}, [&] { rovo::ReadRunOrTrajectory(dir, gt, "auto", &note); });
  return 0;
}
