#pragma once
// The whole ROVO pipeline over a dataset, writing a run folder (datasets/run.h). Entry point of
// `rovo vo`.

#include <cstdint>
#include <string>

namespace rovo {

enum class ExtrinsicsMode { kGroundTruth, kNoisy, kOnline };  // GTExt, NoisyExt, OnlineExt
// "gt" | "noisy" | "online"
ExtrinsicsMode ExtrinsicsModeFromName(const std::string& name);
std::string ExtrinsicsModeName(ExtrinsicsMode mode);

struct VoOptions {
  std::string dataset_dir;
  std::string out_dir;             // run folder
  ExtrinsicsMode mode = ExtrinsicsMode::kGroundTruth;
  int noise_set = 0;               // which perturbed set of dataset.json (noisy/online)
  uint64_t seed = 0;               // RANSAC seed
  int threads = 0;                 // 0 = all cores
  int frame_begin = 0;
  int frame_end = -1;              // -1 = to the end
  std::string sampling = "pps";    // "pps" | "uniform" (ablation)
  std::string ransac = "multiview";  // "multiview" | "single-view" (ablation)
  bool quiet = false;
};

struct VoSummary {
  int frames = 0;
  int frames_ok = 0;
  int frames_lost = 0;
  double seconds = 0.0;
};

VoSummary RunVo(const VoOptions& options);

}  // namespace rovo
