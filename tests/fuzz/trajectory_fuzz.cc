// Fuzz target: trajectory files (groundtruth.tum, trajectories of other systems): ReadTum,
// ReadTumAnyUnit, ParseTumText collecting errors, ReadEurocCsv and ReadKittiPoses on the same bytes.
#include "datasets/io.h"
#include "datasets/trajectory.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("trajectory");
  const std::string path = scratch.Fresh("trajectory") + "/groundtruth.tum";
  rovo::fuzz::WriteBytes(path, data, size);
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadTum(path); });
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadTumAnyUnit(path); });
  std::vector<std::string> errors;
  rovo::ParseTumText(rovo::ReadFile(path), path, &errors);
  for (const std::string& e : errors) {
    if (e.rfind(path + ": line ", 0) != 0) rovo::fuzz::Finding("TUM error without file and line", e);
  }
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadEurocCsv(path); });
  const std::vector<double> stamps = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7};
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadKittiPoses(path, stamps); });
  return 0;
}
