// Fuzz target: dataset.json (ReadDatasetInfo, and ValidateDataset on a folder holding only it).
#include "datasets/dataset.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("dataset_json");
  const std::string dir = scratch.Fresh("dataset");
  const std::string path = rovo::DatasetJsonPath(dir);
  rovo::fuzz::WriteBytes(path, data, size);
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadDatasetInfo(dir); });
  for (const rovo::ValidationIssue& issue : rovo::ValidateDataset(dir)) {
    if (issue.file.empty() || issue.field.empty() || issue.message.empty()) {
      rovo::fuzz::Finding("validation issue without file, field or message", issue.file + ": " + issue.field);
    }
  }
  return 0;
}
