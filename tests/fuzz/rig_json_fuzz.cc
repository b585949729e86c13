// Fuzz target: rig.json (ReadRigJson: a rig object, or the /rig of a dataset.json).
#include "datasets/rig_json.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("rig_json");
  const std::string path = scratch.Fresh("rig") + "/rig.json";
  rovo::fuzz::WriteBytes(path, data, size);
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadRigJson(path); });
  return 0;
}
