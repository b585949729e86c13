// System descriptions: parsing, placeholders, command words (system_description.h).
#include "eval/orchestration/system_description.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>

#include "datasets/exchange/exchange.h"
#include "datasets/exchange/lens_fit.h"
#include "datasets/io.h"

namespace rovo {
namespace fs = std::filesystem;
namespace {

[[noreturn]] void Fail(const std::string& file, const std::string& field, const std::string& what) {
  throw std::runtime_error(file + ": " + field + ": " + what);
}

const std::vector<std::string>& KnownKeys() {
  static const std::vector<std::string> keys = {"name",      "input", "command", "trajectory", "online_calibration",
                                                "timeout_s", "align", "env",     "needs_imu",  "cameras",
                                                "lens"};
  return keys;
}

const std::vector<std::string>& PlaceholderNames() {
  static const std::vector<std::string> names = {"input", "calibration", "out", "threads", "seed", "mode"};
  return names;
}

std::string Scalar(const YAML::Node& root, const char* key, const std::string& file, bool required) {
  const YAML::Node node = root[key];
  if (!node) {
    if (required) Fail(file, key, "missing (docs/systems.md lists the keys)");
    return "";
  }
  if (!node.IsScalar()) Fail(file, key, "expected a string");
  return node.Scalar();
}

bool Bool(const YAML::Node& root, const char* key, const std::string& file) {
  const YAML::Node node = root[key];
  if (!node) return false;
  bool value = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) Fail(file, key, "expected true or false");
  return value;
}

std::string CheckInput(const std::string& input, const std::string& file) {
  if (input == "rovo" || input == "euroc" || input == "kalibr" || input == "basalt" || input == "ros2") return input;
  Fail(file, "input", "unknown \"" + input + "\" (rovo, euroc, kalibr, basalt, ros2)");
}

// A ROS 2 bag (ros2_bag.h) holds every camera of the rig, with the equidistant (kb4) fit of its lens.
void CheckRos2Keys(const SystemDescription& s) {
  if (s.input != "ros2") return;
  if (!s.cameras.empty()) {
    Fail(s.file, "cameras", "input ros2: a bag holds every camera of the rig (no camera subset); use euroc");
  }
  if (!s.lens.empty() && s.lens != "kb4") {
    Fail(s.file, "lens", "input ros2: a bag's CameraInfo carries the equidistant fit only (kb4)");
  }
}

void CheckName(const std::string& name, const std::string& file) {
  const bool ok = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
  if (!ok || name[0] == '.') Fail(file, "name", "\"" + name + "\": expected letters, digits, '_', '-' or '.'");
  if (name == kBuiltInSystem) Fail(file, "name", "\"rovo\" is the built-in system");
}

void ReadOptionalKeys(const YAML::Node& root, const std::string& file, SystemDescription* s) {
  s->online_calibration = Bool(root, "online_calibration", file);
  s->needs_imu = Bool(root, "needs_imu", file);
  if (root["timeout_s"]) {
    double timeout = 0.0;
    if (!root["timeout_s"].IsScalar() || !YAML::convert<double>::decode(root["timeout_s"], timeout) ||
        !(timeout > 0.0 && timeout <= 7 * 86400.0)) {
      Fail(file, "timeout_s", "expected seconds in (0, 604800]");
    }
    s->timeout_s = timeout;
  }
  if (root["align"]) {
    s->align = Scalar(root, "align", file, false);
    if (s->align != "se3" && s->align != "sim3") Fail(file, "align", "expected se3 or sim3, got \"" + s->align + "\"");
  }
  if (const YAML::Node env = root["env"]) {
    if (!env.IsMap()) Fail(file, "env", "expected a map of variable: value");
    for (const auto& item : env) {
      const std::string key = item.first.IsScalar() ? item.first.Scalar() : "";
      if (key.empty() || key.find('=') != std::string::npos || !item.second.IsScalar()) {
        Fail(file, "env", "expected NAME: value pairs");
      }
      s->env.emplace_back(key, item.second.Scalar());
    }
  }
  if (const YAML::Node cameras = root["cameras"]) {
    if (!cameras.IsSequence()) Fail(file, "cameras", "expected a list of camera indices, e.g. [0, 1]");
    for (const YAML::Node& c : cameras) {
      int index = -1;
      if (!c.IsScalar() || !YAML::convert<int>::decode(c, index) || index < 0 || index > 63) {
        Fail(file, "cameras", "expected camera indices in [0, 63]");
      }
      if (std::find(s->cameras.begin(), s->cameras.end(), index) != s->cameras.end()) {
        Fail(file, "cameras", "camera " + std::to_string(index) + " is listed twice");
      }
      s->cameras.push_back(index);
    }
  }
  if (root["lens"]) {
    s->lens = Scalar(root, "lens", file, false);
    try {
      ExchangeLensModelFromName(s->lens);
    } catch (const std::invalid_argument& e) {
      Fail(file, "lens", e.what());
    }
  }
}

}  // namespace

SystemDescription ParseSystemDescription(const std::string& yaml_text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(file + ": not YAML: " + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error(file + ": expected a YAML map of keys (docs/systems.md)");
  for (const auto& item : root) {
    const std::string key = item.first.IsScalar() ? item.first.Scalar() : "?";
    if (std::find(KnownKeys().begin(), KnownKeys().end(), key) == KnownKeys().end()) {
      Fail(file, key,
           "unknown key (known: name, input, command, trajectory, online_calibration, timeout_s, align, "
           "env, needs_imu, cameras, lens)");
    }
  }
  SystemDescription s;
  s.file = file;
  s.name = Scalar(root, "name", file, true);
  CheckName(s.name, file);
  s.input = CheckInput(Scalar(root, "input", file, true), file);
  s.command = Scalar(root, "command", file, true);
  s.trajectory = Scalar(root, "trajectory", file, true);
  if (s.trajectory.empty()) Fail(file, "trajectory", "empty");
  ReadOptionalKeys(root, file, &s);
  CheckRos2Keys(s);
  // Placeholders and quoting are checked now, with dummy values.
  const SystemPlaceholders dummy{"i", "c", "o", "1", "0", "gt"};
  for (const std::string& word : SplitCommandWords(s.command, file, "command")) {
    ExpandPlaceholders(word, dummy, file, "command");
  }
  ExpandPlaceholders(s.trajectory, dummy, file, "trajectory");
  for (const auto& [key, value] : s.env) ExpandPlaceholders(value, dummy, file, "env." + key);
  return s;
}

SystemDescription ReadSystemDescription(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw std::runtime_error(path + ": no such system description file");
  return ParseSystemDescription(ReadFile(path), path);
}

std::string ExpandPlaceholders(const std::string& text, const SystemPlaceholders& values, const std::string& file,
                               const std::string& field) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if ((c == '{' || c == '}') && i + 1 < text.size() && text[i + 1] == c) {
      out += c;
      ++i;
      continue;
    }
    if (c == '}') Fail(file, field, "unmatched '}' in \"" + text + "\" (write \"}}\" for a literal brace)");
    if (c != '{') {
      out += c;
      continue;
    }
    const size_t close = text.find('}', i);
    if (close == std::string::npos) Fail(file, field, "unmatched '{' in \"" + text + "\"");
    const std::string name = text.substr(i + 1, close - i - 1);
    const std::vector<std::string>& names = PlaceholderNames();
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      Fail(file, field,
           "unknown placeholder {" + name + "} (known: {input} {calibration} {out} {threads} {seed} {mode})");
    }
    const std::string* value[] = {&values.input,   &values.calibration, &values.out,
                                  &values.threads, &values.seed,        &values.mode};
    out += *value[it - names.begin()];
    i = close;
  }
  return out;
}

std::vector<std::string> SplitCommandWords(const std::string& command, const std::string& file,
                                           const std::string& field) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (size_t i = 0; i < command.size(); ++i) {
    const char c = command[i];
    if (quote) {
      if (c == quote) {
        quote = 0;
      } else if (c == '\\' && quote == '"' && i + 1 < command.size()) {
        word += command[++i];
      } else {
        word += c;
      }
    } else if (c == '\'' || c == '"') {
      quote = c;
      in_word = true;
    } else if (c == '\\' && i + 1 < command.size()) {
      word += command[++i];
      in_word = true;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      if (in_word) words.push_back(word);
      word.clear();
      in_word = false;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (quote) Fail(file, field, std::string("unterminated ") + quote + " quote");
  if (in_word) words.push_back(word);
  if (words.empty()) Fail(file, field, "empty command");
  return words;
}

std::string ResolveProgram(const SystemDescription& system, const std::string& program) {
  const auto executable = [](const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
  };
  if (program.find('/') != std::string::npos) {
    fs::path p(program);
    if (p.is_relative()) p = fs::absolute(fs::path(system.file)).parent_path() / p;
    p = p.lexically_normal();
    std::error_code ec;
    if (!fs::exists(p, ec)) Fail(system.file, "command", "program " + p.string() + " does not exist");
    if (!executable(p)) Fail(system.file, "command", "program " + p.string() + " is not an executable file");
    return p.string();
  }
  const char* path_env = std::getenv("PATH");
  std::stringstream dirs(path_env ? path_env : "/usr/local/bin:/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (dir.empty()) continue;
    const fs::path p = fs::path(dir) / program;
    if (executable(p)) return p.string();
  }
  Fail(system.file, "command", "program \"" + program + "\" not found on PATH");
}

std::vector<std::string> ExpandCommand(const SystemDescription& system, const SystemPlaceholders& values) {
  std::vector<std::string> words = SplitCommandWords(system.command, system.file, "command");
  for (std::string& word : words) word = ExpandPlaceholders(word, values, system.file, "command");
  words[0] = ResolveProgram(system, words[0]);
  return words;
}

void CheckSystemProgram(const SystemDescription& system) {
  const std::vector<std::string> words = SplitCommandWords(system.command, system.file, "command");
  if (words[0].find('{') != std::string::npos) {
    Fail(system.file, "command", "the program name cannot hold a placeholder: \"" + words[0] + "\"");
  }
  ResolveProgram(system, words[0]);
}

}  // namespace rovo
