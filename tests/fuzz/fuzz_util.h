#pragma once
// Helpers shared by the fuzz targets (docs/fuzzing.md): a scratch folder per process, writing the
// fuzz input to files, splitting one input into several files, and the contract check on errors.
//
// Contract of every reader of outside input: bad input ends in std::runtime_error or
// std::invalid_argument whose message names the file (checked here) and the field. Anything else
// (a crash, a sanitizer report, another exception type, a message without the file) is a finding:
// the helpers abort so that libFuzzer and the replay tests report it. ROVO_FUZZ_VERBOSE=1 prints
// each error message (or that the read succeeded).

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rovo::fuzz {

// A folder under the system temp folder, unique to this process, removed when the process exits.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name)
      : root_(std::filesystem::temp_directory_path() / ("rovo_fuzz_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(root_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  // An empty sub-folder `name` (emptied on every call).
  std::string Fresh(const std::string& name) const {
    const std::filesystem::path dir = root_ / name;
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
    std::filesystem::create_directories(dir);
    return dir.string();
  }

 private:
  std::filesystem::path root_;
};

inline void WriteBytes(const std::string& path, const void* data, size_t size) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

inline void WriteText(const std::string& path, const std::string& text) { WriteBytes(path, text.data(), text.size()); }

// Marker line between the files of a multi-file input ("\n--8<--\n").
inline const std::string& PartMarker() {
  static const std::string marker = "\n--8<--\n";
  return marker;
}

// Splits the input at PartMarker() into exactly `count` parts (missing parts are empty, extra
// markers stay in the last part).
inline std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t count) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t start = 0;
  while (parts.size() + 1 < count) {
    const size_t at = input.find(PartMarker(), start);
    if (at == std::string::npos) break;
    parts.push_back(input.substr(start, at - start));
    start = at + PartMarker().size();
  }
  parts.push_back(start <= input.size() ? input.substr(start) : std::string());
  parts.resize(count);
  return parts;
}

[[noreturn]] inline void Finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz finding: %s: %s\n", what, detail.c_str());
  std::fflush(stderr);
  std::abort();
}

// Runs `read` on the current input. The documented error types must name one of `names` (the file
// or folder that was read); other exception types escape to libFuzzer as uncaught exceptions.
template <typename Read>
bool ExpectClearError(const std::vector<std::string>& names, Read&& read) {
  static const bool verbose = std::getenv("ROVO_FUZZ_VERBOSE") != nullptr;
  auto check = [&](const std::exception& e) {
    const std::string message = e.what();
    if (verbose) std::fprintf(stderr, "  clear error: %s\n", message.c_str());
    for (const std::string& name : names) {
      if (message.find(name) != std::string::npos) return;
    }
    Finding("error message does not name the file", message);
  };
  try {
    read();
    if (verbose) std::fprintf(stderr, "  read without error\n");
    return true;
  } catch (const std::invalid_argument& e) {
    check(e);
  } catch (const std::runtime_error& e) {
    check(e);
  }
  return false;
}

}  // namespace rovo::fuzz
