#pragma once
// A system description (docs/systems.md): a small YAML file that tells the suites how to run another
// odometry system on a rovo dataset and where it writes its trajectory.
//
//   name: colmap                # tables, folders and labels
//   input: euroc                # rovo | euroc | kalibr | basalt | ros2: what {input}, {calibration} are
//   command: "./run.sh {input} {calibration} {out} {threads}"
//   trajectory: "{out}/trajectory.txt"   # TUM (s or ns), EuRoC csv or KITTI (eval/foreign_run.h)
//   online_calibration: false   # true: it corrects its extrinsics itself (an OnlineExt column)
//   timeout_s: 600
//   align: sim3                 # se3 | sim3 (sim3 for monocular systems)
//   env: {OMP_NUM_THREADS: "{threads}"}
//   needs_imu: false
//   cameras: [0]                # the cameras the export writes (empty or absent: all)
//   lens: kb4                   # the export's lens model (ds | eucm | kb4 | omni; absent: best fit)
//
// Placeholders in command, trajectory and env values: {input} {calibration} {out} {threads} {seed}
// {mode}; "{{" and "}}" are literal braces. The command is split into words like a shell would
// (quotes and backslashes, no variables, pipes or globs); placeholders are expanded inside a word, so
// paths with spaces stay one argument. A program name with a '/' is relative to the description's
// folder; a bare name is looked up on PATH. rovo's own pipeline is the built-in system "rovo".

#include <string>
#include <utility>
#include <vector>

namespace rovo {

struct SystemDescription {
  std::string file;  // the YAML file it was read from
  std::string name;
  std::string input;  // rovo | euroc | kalibr | basalt | ros2
  std::string command;
  std::string trajectory;
  bool online_calibration = false;
  double timeout_s = 600.0;
  std::string align = "se3";  // se3 | sim3
  std::vector<std::pair<std::string, std::string>> env;
  bool needs_imu = false;
  std::vector<int> cameras;  // empty: every camera of the rig
  std::string lens;          // "" or an exchange lens model name (datasets/exchange/lens_fit.h)
};

// The name of rovo's own pipeline in tables, suite.json and gates.
inline constexpr const char* kBuiltInSystem = "rovo";

// Parses a description; `file` names it in errors ("<file>: <field>: <problem>"). Checks every key,
// the placeholders of command, trajectory and env, and that a ros2 input asks for no camera subset or lens
// other than kb4 (a bag holds every camera, with the equidistant fit).
SystemDescription ParseSystemDescription(const std::string& yaml_text, const std::string& file);
// Reads and parses a description file; throws std::runtime_error naming the file (and the field).
SystemDescription ReadSystemDescription(const std::string& path);

// The values of the placeholders of one run.
struct SystemPlaceholders {
  std::string input, calibration, out, threads, seed, mode;
};
// Expands `text`; an unknown placeholder or an unmatched brace throws std::runtime_error
// "<file>: <field>: ...".
std::string ExpandPlaceholders(const std::string& text, const SystemPlaceholders& values, const std::string& file,
                               const std::string& field);
// Splits a command into words (single and double quotes, backslash escapes); throws naming file and
// field on an unterminated quote or an empty command.
std::vector<std::string> SplitCommandWords(const std::string& command, const std::string& file,
                                           const std::string& field);
// The command's words with the placeholders expanded, the program resolved (ResolveProgram).
std::vector<std::string> ExpandCommand(const SystemDescription& system, const SystemPlaceholders& values);
// The program the command runs: a path relative to the description's folder when it holds a '/',
// else the first executable of that name on PATH. Throws "<file>: command: program ... not found"
// (or not executable).
std::string ResolveProgram(const SystemDescription& system, const std::string& program);
// Checks what can be checked before anything runs: the program exists and is executable.
void CheckSystemProgram(const SystemDescription& system);

}  // namespace rovo
