// Fuzz target: gates.json checked against a suite.json (CheckGates, as `rovo gate` reads them) and
// its "suite" object (GateSuiteOptions, `rovo gate --run`). The
// input holds gates.json and suite.json separated by a marker line (fuzz_util.h PartMarker).
#include "datasets/io.h"
#include "eval/gate.h"
#include "eval/orchestration/suite.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("gate");
  const std::string dir = scratch.Fresh("gate");
  const std::vector<std::string> parts = rovo::fuzz::SplitParts(data, size, 2);
  const std::string gates_path = dir + "/gates.json", suite_path = dir + "/suite.json";
  rovo::fuzz::WriteText(gates_path, parts[0]);
  rovo::fuzz::WriteText(suite_path, parts[1]);
  rovo::fuzz::ExpectClearError({gates_path, suite_path}, [&] {
    const nlohmann::json gates = rovo::ReadJsonFile(gates_path);
    const nlohmann::json suite = rovo::ReadJsonFile(suite_path);
    rovo::GateTableMarkdown(rovo::CheckGates(gates, gates_path, suite));
  });
  rovo::fuzz::ExpectClearError({gates_path},
                               [&] { rovo::GateSuiteOptions(rovo::ReadJsonFile(gates_path), gates_path); });
  return 0;
}
