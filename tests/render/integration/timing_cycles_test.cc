// Motion blur and rolling shutter against Cycles 3.4: runs scenes/blender/timing_cycles_check.py
// (a bar on a wall seen by a fisheye moving sideways; every case must agree with Cycles within its
// margins and every control, with a wrong shutter, readout or row order, must be caught).
// Needs `blender` (Debian package) on PATH; about 30 s.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace rovo {
namespace {

namespace fs = std::filesystem;

std::string Quote(const std::string& s) { return "'" + s + "'"; }

TEST(TimingCycles, MotionBlurAndRollingShutterAgreeWithCycles) {
  // Blender is a dependency (ci/install-deps.sh): without it the cross-check fails rather than pass unseen.
  ASSERT_EQ(std::system("blender --version > /dev/null 2>&1"), 0) << "blender (Debian package) is not on PATH";
  const fs::path work = fs::temp_directory_path() / ("rovo_timing_cycles_" + std::to_string(::getpid()));
  const std::string log =
      (fs::temp_directory_path() / ("rovo_timing_cycles_" + std::to_string(::getpid()) + ".txt")).string();
  const std::string command =
      "python3 " + Quote(std::string(ROVO_SOURCE_DIR) + "/scenes/blender/timing_cycles_check.py") + " --rovo " +
      Quote(ROVO_BINARY) + " --out " + Quote(work.string()) + " --samples 256 --spp 32 > " + Quote(log) + " 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(status, 0) << text.str();
  fs::remove_all(work);
  fs::remove(log);
}

}  // namespace
}  // namespace rovo
