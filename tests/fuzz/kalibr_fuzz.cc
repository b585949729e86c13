// Fuzz target: Kalibr camchain.yaml (ReadKalibrCamchain).
#include "datasets/exchange/exchange.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("kalibr");
  const std::string path = scratch.Fresh("kalibr") + "/camchain.yaml";
  rovo::fuzz::WriteBytes(path, data, size);
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadKalibrCamchain(path); });
  return 0;
}
