#pragma once
// The options `rovo vo` and `rovo bench vo` share (defined in vo_commands.cc).

#include "vo/vo_options.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace rovo {

struct VoArgs {
  VoOptions options;
  bool realtime = false;  // --realtime: the real-time front-end profile where its flags are not given
};

// The dataset argument and every run option of `rovo vo` except --out.
void AddVoRunOptions(CLI::App* cmd, VoArgs* args);
// After parsing `cmd`: the --realtime profile for the flags that were not given.
void FinaliseVoArgs(CLI::App* cmd, VoArgs* args);

}  // namespace rovo
