// `rovo vo --realtime` sets the real-time front-end settings unless they are given explicitly, and
// run.json records the values the run used.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "datasets/run.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;

int RunCommand(const std::string& command) { return std::system(command.c_str()); }

TEST(VoCli, RealtimeProfileSetsItsDefaultsAndYieldsToExplicitValues) {
  const fs::path root = fs::temp_directory_path() / "rovo_vo_realtime_test";
  fs::remove_all(root);
  const std::string dataset = (root / "dataset").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " render --preset cloudy_urban --quick --frames 0:4 --quiet --out " +
                       dataset),
            0);
  const auto run = [&](const std::string& name, const std::string& flags) {
    const std::string out = (root / name).string();
    EXPECT_EQ(
        RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --frames 0:4 --quiet " + flags + " --out " + out), 0)
        << flags;
    return ReadRun(out);
  };
  const RunData plain = run("plain", "");
  EXPECT_EQ(plain.info.at("warp_below_deg").get<double>(), 50.0);
  EXPECT_EQ(plain.info.at("max_new_features").get<int>(), 0);
  const RunData realtime = run("realtime", "--realtime");
  EXPECT_EQ(realtime.info.at("warp_below_deg").get<double>(), 25.0);
  EXPECT_EQ(realtime.info.at("max_new_features").get<int>(), 150);
  const RunData mixed = run("mixed", "--realtime --warp-below 40 --max-new-features 0");
  EXPECT_EQ(mixed.info.at("warp_below_deg").get<double>(), 40.0);
  EXPECT_EQ(mixed.info.at("max_new_features").get<int>(), 0);
  EXPECT_EQ(realtime.frames.size(), 4u);
  fs::remove_all(root);
}

}  // namespace
}  // namespace rovo
