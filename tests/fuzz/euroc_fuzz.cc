// Fuzz target: EuRoC/ASL camera files (ReadEurocSensorYaml on sensor.yaml, ReadEurocImageList on
// data.csv). The input holds sensor.yaml and data.csv separated by a marker line (fuzz_util.h).
#include "datasets/exchange/exchange.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("euroc");
  const std::string dir = scratch.Fresh("cam0");
  const std::vector<std::string> parts = rovo::fuzz::SplitParts(data, size, 2);
  const std::string sensor = dir + "/sensor.yaml", list = dir + "/data.csv";
  rovo::fuzz::WriteText(sensor, parts[0]);
  rovo::fuzz::WriteText(list, parts[1]);
  rovo::fuzz::ExpectClearError({sensor}, [&] { rovo::ReadEurocSensorYaml(sensor, "cam0"); });
  rovo::fuzz::ExpectClearError({list}, [&] { rovo::ReadEurocImageList(list); });
  return 0;
}
