// Fuzz target: a run folder (ReadRun). The input holds run.json, trajectory.tum, frames.csv and
// extrinsics.csv separated by marker lines (fuzz_util.h PartMarker).
#include "datasets/run.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("run_folder");
  const std::string dir = scratch.Fresh("run");
  const std::vector<std::string> parts = rovo::fuzz::SplitParts(data, size, 4);
  rovo::fuzz::WriteText(rovo::RunInfoPath(dir), parts[0]);
  rovo::fuzz::WriteText(rovo::RunTrajectoryPath(dir), parts[1]);
  rovo::fuzz::WriteText(rovo::RunFramesPath(dir), parts[2]);
  rovo::fuzz::WriteText(rovo::RunExtrinsicsPath(dir), parts[3]);
  rovo::fuzz::ExpectClearError({dir}, [&] { rovo::ReadRun(dir); });
  return 0;
}
