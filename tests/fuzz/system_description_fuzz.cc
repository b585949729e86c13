// Fuzz target: a system description (ReadSystemDescription, eval/orchestration/system_description.h,
// as `rovo suite --system FILE` reads it), then its command and trajectory expanded.
#include "eval/orchestration/system_description.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("system_description");
  const std::string path = scratch.Fresh("system") + "/system.yaml";
  rovo::fuzz::WriteBytes(path, data, size);
  rovo::fuzz::ExpectClearError({path}, [&] {
    const rovo::SystemDescription system = rovo::ReadSystemDescription(path);
    const rovo::SystemPlaceholders values{"/data", "/data/calibration.yaml", "/out", "2", "0", "gt"};
    rovo::ExpandPlaceholders(system.trajectory, values, system.file, "trajectory");
    for (const std::string& word : rovo::SplitCommandWords(system.command, system.file, "command")) {
      rovo::ExpandPlaceholders(word, values, system.file, "command");
    }
  });
  return 0;
}
