// Fuzz target: a scene folder (LoadScene). The input holds scene.json, geometry.bin, motion.bin,
// trajectory.tum and textures/000.png separated by marker lines (fuzz_util.h PartMarker).
#include "scenes/scene.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("scene");
  static const char* const kFiles[] = {"scene.json", "geometry.bin", "motion.bin", "trajectory.tum",
                                       "textures/000.png"};
  const std::string dir = scratch.Fresh("scene");
  const std::vector<std::string> parts = rovo::fuzz::SplitParts(data, size, 5);
  for (size_t i = 0; i < parts.size(); ++i) rovo::fuzz::WriteText(dir + "/" + kFiles[i], parts[i]);
  rovo::fuzz::ExpectClearError({dir}, [&] { rovo::SceneHash(rovo::LoadScene(dir)); });
  return 0;
}
