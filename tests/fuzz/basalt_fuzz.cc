// Fuzz target: Basalt calibration.json (ReadBasaltCalibration).
#include "datasets/exchange/exchange.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("basalt");
  const std::string path = scratch.Fresh("basalt") + "/calibration.json";
  rovo::fuzz::WriteBytes(path, data, size);
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadBasaltCalibration(path); });
  return 0;
}
