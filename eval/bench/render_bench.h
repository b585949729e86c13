#pragma once
// Render speed benchmark (`rovo bench render`).

#include <cstdint>
#include <string>

namespace rovo {

// `rovo bench render`: prints a table of render speed, raw ray-cast speed and memory.
struct RenderBenchOptions {
  std::string preset = "static_urban";
  std::string scene_dir;  // instead of the preset
  uint64_t seed = 0;
  int frames = 3;
  double scale = 1.0;
  int threads = 0;
  int spp = 0;                   // default-quality spp (0 = kDefaultSpp)
  std::string write_dir;         // if set, also time full dataset writing into this folder
  bool quality = false;          // also measure aliasing: error vs. a 32-spp reference and shimmer
  double blur_quality_ms = 0.0;  // > 0: the motion-blur sampling study at this shutter (RunBlurQualityStudy)
  bool breakdown = false;        // also time 1 spp without trilinear filtering and without textures
  std::string cycles_timing;     // timing.json of scenes/blender/time_cycles_vs_rovo.py: print the Cycles ratio
  std::string against;           // a preset: print this scene's default-quality CPU per frame over that preset's
};
void RunRenderBenchmark(const RenderBenchOptions& options);

}  // namespace rovo
