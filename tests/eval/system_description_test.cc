// System descriptions (eval/orchestration/system_description.h) and the child runner
// (eval/orchestration/external_run.h).
#include "eval/orchestration/system_description.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "datasets/io.h"
#include "eval/orchestration/external_run.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

const char* kValid =
    "name: mine\ninput: euroc\ncommand: \"my_vo --data {input} --calib '{calibration}' --out {out} -j {threads} "
    "--seed {seed} --mode {mode}\"\ntrajectory: \"{out}/trajectory.txt\"\n";

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseSystemDescription(yaml, "sys.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(SystemDescription, ReadsKeysAndDefaults) {
  const SystemDescription s = ParseSystemDescription(
      std::string(kValid) +
          "online_calibration: true\ntimeout_s: 12.5\nalign: sim3\nenv: {OMP_NUM_THREADS: \"{threads}\"}\nlens: kb4\n",
      "sys.yaml");
  EXPECT_EQ(s.name, "mine");
  EXPECT_EQ(s.input, "euroc");
  EXPECT_TRUE(s.online_calibration);
  EXPECT_DOUBLE_EQ(s.timeout_s, 12.5);
  EXPECT_EQ(s.align, "sim3");
  ASSERT_EQ(s.env.size(), 1u);
  EXPECT_EQ(s.env[0].first, "OMP_NUM_THREADS");
  EXPECT_EQ(s.lens, "kb4");
  const SystemDescription d = ParseSystemDescription(kValid, "sys.yaml");
  EXPECT_FALSE(d.online_calibration);
  EXPECT_DOUBLE_EQ(d.timeout_s, 600.0);
  EXPECT_EQ(d.align, "se3");
  EXPECT_TRUE(d.cameras.empty());
}

TEST(SystemDescription, ErrorsNameTheFileAndTheField) {
  EXPECT_EQ(ErrorOf("input: euroc\ncommand: x\ntrajectory: t\n"),
            "sys.yaml: name: missing (docs/systems.md lists the keys)");
  EXPECT_NE(ErrorOf("name: a\ninput: euroc\ntrajectory: t\n").find("sys.yaml: command: missing"), std::string::npos);
  EXPECT_NE(ErrorOf("name: a\ninput: euroc\ncommand: x\n").find("sys.yaml: trajectory: missing"), std::string::npos);
  EXPECT_NE(ErrorOf("name: a\ninput: tum\ncommand: x\ntrajectory: t\n").find("sys.yaml: input: unknown \"tum\""),
            std::string::npos);
  EXPECT_EQ(ErrorOf("name: a\ninput: ros2\ncommand: x\ntrajectory: t\n"), "");  // ros2 bags: per-run /tf_static
  EXPECT_NE(ErrorOf("name: a\ninput: ros2\ncommand: x\ntrajectory: t\ncameras: [0]\n")
                .find("sys.yaml: cameras: input ros2: a bag holds every camera"),
            std::string::npos);
  EXPECT_NE(ErrorOf("name: a\ninput: ros2\ncommand: x\ntrajectory: t\nlens: ds\n").find("sys.yaml: lens: input ros2"),
            std::string::npos);
  EXPECT_NE(ErrorOf("name: a\ninput: euroc\ncommand: \"x {calib}\"\ntrajectory: t\n")
                .find("sys.yaml: command: unknown placeholder {calib}"),
            std::string::npos);
  EXPECT_NE(ErrorOf("name: a\ninput: euroc\ncommand: x\ntrajectory: \"{output}/t\"\n")
                .find("sys.yaml: trajectory: unknown placeholder {output}"),
            std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kValid) + "env: {A: \"{nope}\"}\n").find("sys.yaml: env.A: unknown placeholder"),
            std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kValid) + "align: affine\n").find("sys.yaml: align: expected se3 or sim3"),
            std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kValid) + "timeout_s: 0\n").find("sys.yaml: timeout_s:"), std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kValid) + "timeout: 3\n").find("sys.yaml: timeout: unknown key"), std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kValid) + "cameras: [0, 0]\n").find("sys.yaml: cameras: camera 0 is listed twice"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf("name: a\ninput: euroc\ncommand: \"x 'y\"\ntrajectory: t\n").find("sys.yaml: command: unterminated"),
      std::string::npos);
  EXPECT_NE(ErrorOf("name: rovo\ninput: euroc\ncommand: x\ntrajectory: t\n").find("sys.yaml: name:"),
            std::string::npos);
  EXPECT_NE(ErrorOf("[1, 2").find("sys.yaml: not YAML"), std::string::npos);
}

TEST(SystemDescription, ExpandsWordsAndResolvesPrograms) {
  const fs::path dir = fs::temp_directory_path() / ("rovo_sysdesc_" + std::to_string(::getpid()));
  fs::create_directories(dir / "bin");
  WriteFileAtomic((dir / "bin" / "tool.sh").string(), "#!/bin/sh\n");
  fs::permissions(dir / "bin" / "tool.sh", fs::perms::owner_all);
  SystemDescription s = ParseSystemDescription(
      "name: t\ninput: rovo\ncommand: \"./bin/tool.sh --in '{input}' {{x}} a\\\\ b\"\ntrajectory: t\n",
      (dir / "t.yaml").string());
  const std::vector<std::string> words = ExpandCommand(s, {"/my data", "c", "o", "2", "7", "noisy"});
  ASSERT_EQ(words.size(), 5u);
  EXPECT_EQ(words[0], (dir / "bin" / "tool.sh").string());
  EXPECT_EQ(words[2], "/my data");
  EXPECT_EQ(words[3], "{x}");
  EXPECT_EQ(words[4], "a b");
  s.command = "./bin/missing {input}";
  try {
    CheckSystemProgram(s);
    ADD_FAILURE() << "a missing program passed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "t.yaml").string() + ": command: program "), std::string::npos);
  }
  s.command = "rovo_no_such_program_on_path";
  EXPECT_THROW(CheckSystemProgram(s), std::runtime_error);
  s.command = "sh -c true";
  EXPECT_NO_THROW(CheckSystemProgram(s));
  fs::remove_all(dir);
}

class ChildTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rovo_child_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  ChildSpec Spec(const std::string& script, double timeout_s = 30.0) const {
    return {{"/bin/sh", "-c", script},
            {{"ROVO_CHILD_TEST", "v"}},
            (dir_ / "out.log").string(),
            (dir_ / "err.log").string(),
            dir_.string(),
            timeout_s};
  }
  fs::path dir_;
};

TEST_F(ChildTest, ExitStatusOutputAndEnvironment) {
  const ChildResult r = RunChild(Spec("echo out; echo \"err $ROVO_CHILD_TEST\" >&2; pwd > cwd.txt; exit 3"));
  EXPECT_TRUE(r.started);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.signal, 0);
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(ReadFile((dir_ / "out.log").string()), "out\n");
  EXPECT_EQ(FileTail((dir_ / "err.log").string(), 100), "err v\n");
  EXPECT_EQ(ReadFile((dir_ / "cwd.txt").string()), fs::canonical(dir_).string() + "\n");
}

TEST_F(ChildTest, CrashIsASignal) {
  const ChildResult r = RunChild(Spec("kill -SEGV $$"));
  EXPECT_EQ(r.signal, SIGSEGV);
  EXPECT_EQ(r.exit_code, -1);
}

TEST_F(ChildTest, TimeoutKillsTheWholeGroup) {
  const std::string pid_file = (dir_ / "grandchild.pid").string();
  const auto start = std::chrono::steady_clock::now();
  const ChildResult r = RunChild(Spec("sleep 60 & echo $! > " + pid_file + "; wait", 0.5));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(r.timed_out);
  EXPECT_NE(r.signal, 0);
  EXPECT_LT(seconds, 10.0);
  const pid_t grandchild = std::stoi(ReadFile(pid_file));
  // The grandchild was killed with the group (it may linger as a zombie of init for a moment).
  bool gone = false;
  for (int i = 0; i < 100 && !gone; ++i) {
    std::ifstream stat("/proc/" + std::to_string(grandchild) + "/stat");
    std::string line;
    gone = !std::getline(stat, line) || line.find(") Z") != std::string::npos;
    if (!gone) ::usleep(20000);
  }
  EXPECT_TRUE(gone);
}

TEST_F(ChildTest, MissingProgramDoesNotStart) {
  ChildSpec spec = Spec("");
  spec.argv = {(dir_ / "nothing").string()};
  const ChildResult r = RunChild(spec);
  EXPECT_FALSE(r.started);
  EXPECT_NE(r.start_error.find("nothing"), std::string::npos);
}

TEST_F(ChildTest, MeasuresCpuAndMemory) {
  // About 64 MB held by a child of the shell while it spins.
  const ChildResult r =
      RunChild(Spec("python3 -c \"b = bytearray(64 << 20); import time; t = time.time()\n"
                    "while time.time() - t < 0.5: b[0] = 1\""));
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_GT(r.user_cpu_s + r.system_cpu_s, 0.2);
  EXPECT_GT(r.peak_rss_mb, 60.0);
  EXPECT_LT(r.peak_rss_mb, 400.0);
}

TEST(ShellQuote, QuotesWhatAShellWouldSplit) {
  EXPECT_EQ(ShellQuoteWords({"/bin/x", "a b", "it's", "--k=v"}), "/bin/x 'a b' 'it'\\''s' --k=v");
}

}  // namespace
}  // namespace rovo
