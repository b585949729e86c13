#pragma once
// The options `rovo vo` and `rovo bench vo` share (defined in vo_commands.cc).

#include <string>

#include "vo/pipeline.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace rovo {

struct VoArgs {
  VoOptions options;
  std::string extrinsics = "gt";
  std::string frames;
  bool realtime = false;
  CLI::Option* warp_below = nullptr;  // given explicitly, it overrides --realtime
  CLI::Option* max_new_features = nullptr;
};

// The dataset argument and every run option of `rovo vo` except --out.
void AddVoRunOptions(CLI::App* cmd, VoArgs* args);
// After parsing: the mode from --extrinsics, the frame range, the --realtime profile.
void FinaliseVoArgs(VoArgs* args);

}  // namespace rovo
