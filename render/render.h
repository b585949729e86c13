#pragma once
// Renders a dataset (datasets/FORMAT.md) from a scene and a rig. Entry point of `rovo render`.

#include <cstdint>
#include <string>

namespace rovo {

struct RenderOptions {
  std::string preset;          // scenes preset to generate and render, or ""
  bool quick = false;          // the preset's quick form (fewer frames, smaller images)
  std::string scene_dir;       // or a scene folder (scenes/FORMAT.md)
  std::string rig;             // rig preset name or rig .json path; "" = the scene's rig preset
  std::string out_dir;         // dataset folder
  int frame_begin = 0;         // [frame_begin, frame_end) of the trajectory; -1 = to the end
  int frame_end = -1;
  int shard_index = 0;         // render frames with (frame / chunk) % shard_count == shard_index
  int shard_count = 1;
  int spp = 0;                 // samples per pixel; 0 = the measured default
  int threads = 0;             // 0 = all cores
  uint64_t seed = 0;           // scene seed (preset) and sensor-noise seed
  bool depth = false;          // write depth/ (EXR ray length)
  bool masks = false;          // write masks/ (16-bit object ids)
  double scale = 0.0;          // image scale; 0 = 1.0, or the preset's quick scale with --quick
  bool quiet = false;          // no progress output
};

struct RenderSummary {
  int frames_total = 0;
  int frames_rendered = 0;
  int frames_skipped = 0;      // already complete on disk (resume)
  double seconds = 0.0;
};

RenderSummary RenderDataset(const RenderOptions& options);

}  // namespace rovo
