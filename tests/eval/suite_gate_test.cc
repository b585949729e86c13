#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "datasets/io.h"
#include "datasets/run.h"
#include "eval/gate.h"
#include "eval/orchestration/suite.h"

namespace rovo {
namespace {

RunMetrics Metrics(const std::string& mode, int noise_set, double rmse, double inliers) {
  RunMetrics m;
  m.label = mode + std::to_string(noise_set);
  m.mode = mode;
  m.noise_set = noise_set;
  m.path_length_m = 100.0;
  m.rmse_se3_m = rmse;
  m.relative_rmse_pct = rmse;  // path length 100 m
  m.rmse_origin_m = 2 * rmse;
  m.mean_inlier_ratio = inliers;
  m.mean_reproj_error_deg = 0.1;
  m.max_final_ext_rotation_deg = mode == "noisy" ? 5.0 : 0.05;
  return m;
}

TEST(Stat, MeanAndSampleStd) {
  const Stat s = ComputeStat({1.0, 2.0, 3.0, 4.0});
  EXPECT_EQ(s.n, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_NEAR(s.std, std::sqrt(5.0 / 3.0), 1e-15);
  EXPECT_EQ(ComputeStat({7.0}).std, 0.0);
  EXPECT_EQ(ComputeStat({}).n, 0);
}

// A complete run folder whose run.json records `info`.
std::string WriteRunFolder(const nlohmann::json& info) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rovo_suite_resume_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const std::string& file :
       {RunTrajectoryPath(dir.string()), RunFramesPath(dir.string()), RunExtrinsicsPath(dir.string())}) {
    std::ofstream(file) << "\n";
  }
  std::ofstream(RunInfoPath(dir.string())) << info.dump();
  return dir.string();
}

TEST(Suite, ReusesOnlyRunsMadeWithTheSameSettings) {
  nlohmann::json info = {{"mode", "online"}, {"dataset", "/data/x"},   {"frames", {0, 60}}, {"noise_set", 1},
                         {"seed", 0},        {"max_new_features", 150}};
  RunSettings want;
  want.mode = ExtrinsicsMode::kOnline;
  want.noise_set = 1;
  want.frame_end = 60;
  want.seed = 0;
  want.max_new_features = 150;
  std::string mismatch = "stale";
  const std::string dir = WriteRunFolder(info);
  EXPECT_TRUE(RunReusable(dir, want, &mismatch));
  EXPECT_EQ(mismatch, "");

  want.max_new_features = 0;
  EXPECT_FALSE(RunReusable(dir, want, &mismatch));
  EXPECT_EQ(mismatch, "max_new_features: 150 vs 0");
  // A run.json from before the limit was recorded counts as "no limit".
  info.erase("max_new_features");
  WriteRunFolder(info);
  EXPECT_TRUE(RunReusable(dir, want, &mismatch));

  want.seed = 3;
  EXPECT_FALSE(RunReusable(dir, want, &mismatch));
  EXPECT_EQ(mismatch, "seed: 0 vs 3");
  want.seed = 0;
  want.mode = ExtrinsicsMode::kNoisy;
  EXPECT_FALSE(RunReusable(dir, want, &mismatch));
  EXPECT_EQ(mismatch, "mode: \"online\" vs \"noisy\"");
  want.mode = ExtrinsicsMode::kOnline;
  // Other frames, or a missing output file, make the run incomplete: redone, but no mismatch.
  want.frame_end = 30;
  EXPECT_FALSE(RunReusable(dir, want, &mismatch));
  EXPECT_EQ(mismatch, "");
  want.frame_end = 60;
  std::filesystem::remove(RunExtrinsicsPath(dir));
  EXPECT_FALSE(RunReusable(dir, want, &mismatch));
  std::filesystem::remove_all(dir);
}

std::vector<PresetSummary> SamplePresets() {
  PresetSummary p;
  p.preset = "cloudy_urban";
  p.frames = 60;
  p.path_length_m = 100.0;
  p.modes = SummariseModes({Metrics("gt", -1, 0.1, 0.7), Metrics("noisy", 0, 3.0, 0.4), Metrics("noisy", 1, 5.0, 0.5),
                            Metrics("online", 0, 0.2, 0.6), Metrics("online", 1, 0.4, 0.62)});
  return {p};
}

TEST(Suite, SummariseModesAggregatesOverNoiseSets) {
  const std::vector<PresetSummary> presets = SamplePresets();
  const PresetSummary& p = presets[0];
  ASSERT_EQ(p.modes.size(), 3u);
  const ModeSummary* noisy = p.Find("noisy");
  ASSERT_NE(noisy, nullptr);
  EXPECT_EQ(noisy->runs.size(), 2u);
  const auto rmse = noisy->Find("rmse_se3_m");
  ASSERT_TRUE(rmse.has_value());
  EXPECT_DOUBLE_EQ(rmse->mean, 4.0);
  EXPECT_NEAR(rmse->std, std::sqrt(2.0), 1e-15);
  EXPECT_EQ(rmse->n, 2);
  EXPECT_NEAR(p.Find("online")->Find("mean_inlier_ratio")->mean, 0.61, 1e-15);
  EXPECT_EQ(p.Find("gt")->Find("rmse_se3_m")->n, 1);
}

TEST(Suite, TableShowsOursAndThePapersRelativeError) {
  const std::string md = SuiteTableMarkdown(SamplePresets(), true);
  EXPECT_NE(md.find("Cloudy Urban (`cloudy_urban`) quick"), std::string::npos) << md;
  EXPECT_NE(md.find("4.000 ± 1.414"), std::string::npos) << md;          // NoisyExt RMSE mean ± std
  EXPECT_NE(md.find("12.08 / 0.409 / 0.120"), std::string::npos) << md;  // paper: 42.28, 1.43, 0.42 of 350 m
  EXPECT_NE(md.find("4.00 / 0.300 / 0.100"), std::string::npos) << md;   // ours, relative
  EXPECT_NE(md.find("61.0 / 70.0"), std::string::npos) << md;            // inliers Online / GT
  EXPECT_NE(md.find("Umeyama"), std::string::npos) << md;
  ASSERT_TRUE(PaperRowForPreset("canyon_multifov").has_value());
  EXPECT_EQ(PaperRowForPreset("canyon_multifov")->length_m, 440.0);
  EXPECT_FALSE(PaperRowForPreset("nonexistent").has_value());
}

TEST(Suite, TableSaysWhenARunHasNoValue) {
  PresetSummary p;
  p.preset = "sunset_urban";
  p.frames = 60;
  p.path_length_m = 100.0;
  RunMetrics lost = Metrics("noisy", 2, 0.0, 0.0);  // lost on every frame: nothing to align
  lost.rmse_se3_m.reset();
  lost.relative_rmse_pct.reset();
  lost.rmse_origin_m.reset();
  p.modes = SummariseModes({Metrics("gt", -1, 0.1, 0.7), Metrics("noisy", 0, 3.0, 0.4), Metrics("noisy", 1, 5.0, 0.5),
                            lost, Metrics("online", 0, 0.2, 0.6)});
  const std::string md = SuiteTableMarkdown({p}, true);
  EXPECT_NE(md.find("4.000 ± 1.414 (2 of 3 runs)"), std::string::npos) << md;         // NoisyExt RMSE
  EXPECT_NE(md.find("4.00 (2 of 3 runs) / 0.200 / 0.100"), std::string::npos) << md;  // relative
  EXPECT_EQ(md.find("of 1 runs"), std::string::npos) << md;                           // complete modes carry no count
}

nlohmann::json SampleSuiteJson() {
  SuiteOptions options;
  options.quick = true;
  return SuiteToJson(SamplePresets(), options);
}

TEST(Gate, PassesAndFailsOnThresholds) {
  nlohmann::json gates = {
      {"gates",
       {{{"preset", "cloudy_urban"}, {"mode", "gt"}, {"metric", "relative_rmse_pct"}, {"max", 0.2}},
        {{"preset", "cloudy_urban"}, {"mode", "online"}, {"metric", "mean_inlier_ratio"}, {"min", 0.5}},
        {{"preset", "cloudy_urban"}, {"mode", "noisy"}, {"metric", "relative_rmse_pct"}, {"min", 1.0}}}}};
  const nlohmann::json suite = SampleSuiteJson();
  std::vector<GateCheck> checks = CheckGates(gates, "gates.json", suite);
  ASSERT_EQ(checks.size(), 3u);
  EXPECT_TRUE(AllGatesPass(checks)) << GateTableMarkdown(checks);
  EXPECT_NEAR(*checks[1].value, 0.61, 1e-12);

  // Tightened below the measured value: fails, and the table says so.
  gates["gates"][0]["max"] = 0.05;
  checks = CheckGates(gates, "gates.json", suite);
  EXPECT_FALSE(AllGatesPass(checks));
  EXPECT_FALSE(checks[0].pass);
  EXPECT_TRUE(checks[1].pass);
  EXPECT_NE(GateTableMarkdown(checks).find("**FAIL**"), std::string::npos);

  // A metric the suite lacks (preset not run) fails.
  gates["gates"][0] = {{"preset", "static_urban"}, {"mode", "gt"}, {"metric", "relative_rmse_pct"}, {"max", 100.0}};
  checks = CheckGates(gates, "gates.json", suite);
  EXPECT_FALSE(checks[0].pass);
  EXPECT_FALSE(checks[0].value.has_value());
  EXPECT_NE(GateTableMarkdown(checks).find("missing"), std::string::npos);
}

TEST(Gate, MalformedGateNamesTheEntry) {
  const nlohmann::json suite = SampleSuiteJson();
  auto error = [&](const nlohmann::json& gates) {
    try {
      CheckGates(gates, "ci/gates.json", suite);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error({{"nogates", 1}}).find("ci/gates.json: missing array field \"gates\""), std::string::npos);
  const nlohmann::json bad_metric = {{"gates", {{{"preset", "p"}, {"mode", "gt"}, {"metric", "speed"}, {"max", 1}}}}};
  EXPECT_NE(error(bad_metric).find("gates[0]: field \"metric\""), std::string::npos) << error(bad_metric);
  const nlohmann::json both = {
      {"gates", {{{"preset", "p"}, {"mode", "gt"}, {"metric", "rmse_se3_m"}, {"max", 1}, {"min", 0}}}}};
  EXPECT_NE(error(both).find("exactly one of"), std::string::npos);
  const nlohmann::json no_mode = {{"gates", {{{"preset", "p"}, {"metric", "rmse_se3_m"}, {"max", 1}}}}};
  EXPECT_NE(error(no_mode).find("gates[0]: missing string field \"mode\""), std::string::npos);
}

}  // namespace
}  // namespace rovo
