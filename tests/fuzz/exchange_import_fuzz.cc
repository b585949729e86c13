// Fuzz target: importing a EuRoC-style folder with a Kalibr or Basalt calibration (ImportDataset,
// datasets/exchange_import.cc), one camera. The first byte picks the format (even: Kalibr, odd:
// Basalt); the rest holds, separated by marker lines (fuzz_util.h PartMarker), the calibration, its
// perturbed set -0, mav0/cam0/data.csv, mav0/state_groundtruth_estimate0/data.csv and
// mav0/cam0/sensor.yaml. Empty parts other than data.csv are absent files. mav0/cam0/data/ holds
// 0.png, 100000000.png and 200000000.png (not real images: the import copies them, the validator
// reports them).
#include "datasets/exchange/exchange.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("exchange_import");
  if (size < 1) return 0;
  const bool kalibr = data[0] % 2 == 0;
  const std::vector<std::string> parts = rovo::fuzz::SplitParts(data + 1, size - 1, 5);
  const std::string in = scratch.Fresh("in"), out = scratch.Fresh("out");
  const std::string calibration = in + (kalibr ? "/camchain.yaml" : "/calibration.json");
  const std::string perturbed = in + (kalibr ? "/camchain-perturbed-0.yaml" : "/calibration-perturbed-0.json");
  rovo::fuzz::WriteText(calibration, parts[0]);
  if (!parts[1].empty()) rovo::fuzz::WriteText(perturbed, parts[1]);
  rovo::fuzz::WriteText(in + "/mav0/cam0/data.csv", parts[2]);
  if (!parts[3].empty()) rovo::fuzz::WriteText(in + "/mav0/state_groundtruth_estimate0/data.csv", parts[3]);
  if (!parts[4].empty()) rovo::fuzz::WriteText(in + "/mav0/cam0/sensor.yaml", parts[4]);
  for (const char* name : {"0.png", "100000000.png", "200000000.png"}) {
    rovo::fuzz::WriteText(in + "/mav0/cam0/data/" + name, "not a png");
  }
  rovo::ImportOptions options;
  options.format = kalibr ? rovo::ExchangeFormat::kKalibr : rovo::ExchangeFormat::kBasalt;
  options.out_dir = out;
  rovo::fuzz::ExpectClearError({in, out}, [&] { rovo::ImportDataset(in, options); });
  return 0;
}
