#pragma once
// Scratch folders for the scenes tests: one root per test process, removed after the last test.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace rovo::test {

inline std::filesystem::path ScratchRoot() {
  return std::filesystem::temp_directory_path() / ("rovo_scenes_test_" + std::to_string(::getpid()));
}

class RemoveScratchRoot : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(ScratchRoot(), ec);
  }
};
// Inline variable: registered once per test binary, whichever files include this header.
inline ::testing::Environment* const kRemoveScratchRoot = ::testing::AddGlobalTestEnvironment(new RemoveScratchRoot);

// An empty folder `name` under the scratch root.
inline std::string FreshDir(const std::string& name) {
  const std::filesystem::path dir = ScratchRoot() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace rovo::test
