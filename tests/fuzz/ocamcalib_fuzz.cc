// Fuzz target: OCamCalib calib_results.txt (ReadOcamCalibTxt).
#include "datasets/exchange/ocamcalib.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("ocamcalib");
  const std::string path = scratch.Fresh("ocam") + "/calib_results.txt";
  rovo::fuzz::WriteBytes(path, data, size);
  double file_error = 0.0;
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadOcamCalibTxt(path, 220.0, &file_error); });
  return 0;
}
