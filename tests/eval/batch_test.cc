// The suite's plan of tasks, perturbation draws, and `rovo batch` (folder, status, resume plan)
// without Slurm; tests/eval/integration/slurm_batch_test.sh runs it on a real Slurm.
#include "eval/orchestration/batch.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "datasets/io.h"
#include "datasets/run.h"
#include "eval/orchestration/suite.h"
#include "scenes/city.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("rovo_batch_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

SuiteOptions SmallSuite(const fs::path& out) {
  SuiteOptions o;
  o.presets = {"cloudy_urban"};
  o.quick = true;
  o.frames = 16;
  o.noise_sets = 2;
  o.draws = 3;
  o.vo_threads = 1;
  o.out_dir = out.string();
  return o;
}

TEST(SuiteDraws, SeedsAreDeterministicDistinctAndApartFromTheStoredSets) {
  std::set<int64_t> seeds;
  for (uint64_t scene_seed : {0ull, 1ull, 7ull}) {
    for (int d = 0; d < 200; ++d) {
      const int64_t seed = SuiteDrawSeed(scene_seed, 0, d);
      EXPECT_GE(seed, 0);
      EXPECT_EQ(seed, SuiteDrawSeed(scene_seed, 0, d));
      seeds.insert(seed);
      for (int k = 0; k < 5; ++k) EXPECT_NE(static_cast<uint64_t>(seed), StoredNoiseSetSeed(scene_seed, k));
    }
  }
  EXPECT_EQ(seeds.size(), 600u);
  EXPECT_NE(SuiteDrawSeed(0, 0, 0), SuiteDrawSeed(0, 1, 0));  // the VO seed changes the draws too
}

TEST(SuiteDraws, ConvergenceCountsRunsBelowTheThreshold) {
  std::vector<RunMetrics> runs(3);
  for (RunMetrics& m : runs) {
    m.mode = "online";
    m.rmse_se3_m = 0.1;
    m.final_ext_rotation_deg = {0.05, 0.02, 0.01};
    m.max_final_ext_rotation_deg = 0.05;
  }
  runs[1].final_ext_rotation_deg = {2.0, 0.0, 0.0};
  runs[1].max_final_ext_rotation_deg = 2.0;
  runs[2].final_ext_rotation_deg.clear();  // no extrinsics: not converged
  runs[2].max_final_ext_rotation_deg = 0.0;
  PresetSummary p;
  p.preset = "cloudy_urban";
  p.modes.push_back(SummariseRuns("draws", runs));
  p.modes.back().draw_seeds = {11, 22, 33};
  const DrawConvergence c = ComputeDrawConvergence(p.modes.back());
  EXPECT_EQ(c.converged, 1);
  EXPECT_EQ(c.draws, 3);
  EXPECT_EQ(c.failed_seeds, (std::vector<int64_t>{22, 33}));
  const std::string md = DrawTableMarkdown({p}, 5.0);
  EXPECT_NE(md.find("| `cloudy_urban` | 3 | 0.100 ± 0.000 | 0.683 ± 1.141 | 33 % (1 of 3) | 22, 33 |"),
            std::string::npos)
      << md;
  SuiteOptions options;
  options.draws = 3;
  const nlohmann::json j = SuiteToJson({p}, options);
  EXPECT_EQ(j["presets"]["cloudy_urban"]["modes"]["draws"]["draw_seeds"], nlohmann::json({11, 22, 33}));
  EXPECT_EQ(j["presets"]["cloudy_urban"]["modes"]["draws"]["converged"]["count"], 1);
  EXPECT_EQ(DrawTableMarkdown({}, 5.0), "");
}

TEST(SuitePlan, ListsEveryRunOnceWithItsSettings) {
  const SuitePlan plan = PlanSuite(SmallSuite(TempDir("plan")));
  ASSERT_EQ(plan.frame_ends, std::vector<int>{16});
  std::vector<std::string> names;
  for (const SuiteRun& r : plan.runs) names.push_back(r.name);
  EXPECT_EQ(names, (std::vector<std::string>{"gt", "noisy_0", "online_0", "noisy_1", "online_1", "draw_0", "draw_1",
                                             "draw_2"}));
  EXPECT_EQ(plan.runs[5].settings.mode, ExtrinsicsMode::kOnline);
  EXPECT_EQ(plan.runs[5].settings.draw_seed, SuiteDrawSeed(0, 0, 0));
  EXPECT_EQ(plan.runs[4].settings.draw_seed, -1);
  EXPECT_EQ(plan.runs[4].settings.noise_set, 1);
  SuiteOptions bad = SmallSuite(TempDir("plan"));
  bad.draws = -1;
  EXPECT_THROW(PlanSuite(bad), std::invalid_argument);
  bad = SmallSuite(TempDir("plan"));
  bad.presets = {"atlantis"};
  EXPECT_THROW(PlanSuite(bad), std::invalid_argument);
}

// A system that needs the IMU makes the plan render with one, into a dataset folder of its own: the folder is
// the reuse key, so an IMU-less dataset of the same preset and seed is never taken for it.
TEST(SuitePlan, ASystemThatNeedsTheImuGetsDatasetsWithOne) {
  const fs::path out = TempDir("imu_plan");
  const SuitePlan plain = PlanSuite(SmallSuite(out));
  EXPECT_FALSE(plain.imu);
  const std::string description = (out / "vio.yaml").string();
  WriteFileAtomic(description,
                  "name: vio\ninput: euroc\ncommand: \"true\"\ntrajectory: \"{out}/t.txt\"\nneeds_imu: true\n");
  SuiteOptions options = SmallSuite(out);
  options.systems = {description};
  const SuitePlan with_imu = PlanSuite(options);
  EXPECT_TRUE(with_imu.imu);
  ASSERT_EQ(with_imu.dataset_dirs.size(), 1u);
  EXPECT_EQ(with_imu.dataset_dirs[0], plain.dataset_dirs[0] + "_imu");
  fs::remove_all(out);
}

// Preset entries with a render variant ("cloudy_urban+blur") plan their own dataset and runs; an unknown
// variant is an error naming the entry; --robustness lists every variant and the harder worlds.
// A variant's dataset made with other effects (an earlier definition of the variant) is not taken as
// complete: the render refuses the folder, naming the difference, instead of the suite reusing it.
TEST(SuitePlan, AVariantDatasetWithOtherEffectsIsNotReused) {
  const fs::path out = TempDir("variant_reuse");
  SuiteOptions options = SmallSuite(out);
  options.frames = 2;
  options.quiet = true;
  options.presets = {"cloudy_urban+trigger"};
  const SuitePlan trigger = PlanSuite(options);
  RenderSuiteDataset(trigger, 0, 0, 1, 2);
  RenderSuiteDataset(trigger, 0, 0, 1, 2);  // complete: not rendered again
  options.presets = {"cloudy_urban+rolling"};
  const SuitePlan rolling = PlanSuite(options);
  fs::create_directories(fs::path(rolling.dataset_dirs[0]).parent_path());
  fs::rename(trigger.dataset_dirs[0], rolling.dataset_dirs[0]);
  try {
    RenderSuiteDataset(rolling, 0, 0, 1, 2);
    ADD_FAILURE() << "a dataset rendered with trigger offsets was reused for the rolling-shutter variant";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(rolling.dataset_dirs[0]), std::string::npos) << e.what();
  }
  fs::remove_all(out);
}

TEST(SuitePlan, VariantEntriesAndTheRobustnessList) {
  EXPECT_EQ(ParseSuiteEntry("cloudy_urban").variant, "");
  const SuiteEntry blur = ParseSuiteEntry("cloudy_urban+blur");
  EXPECT_EQ(blur.preset, "cloudy_urban");
  EXPECT_EQ(blur.variant, "blur");
  try {
    ParseSuiteEntry("cloudy_urban+fog");
    FAIL() << "an unknown variant was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cloudy_urban+fog"), std::string::npos) << e.what();
  }
  SuiteOptions options = SmallSuite(TempDir("variant"));
  options.presets = {"cloudy_urban+realistic"};
  const SuitePlan plan = PlanSuite(options);
  ASSERT_EQ(plan.dataset_dirs.size(), 1u);
  EXPECT_NE(plan.dataset_dirs[0].find("cloudy_urban+realistic"), std::string::npos) << plan.dataset_dirs[0];
  EXPECT_NE(plan.runs[0].run_dir.find("cloudy_urban+realistic"), std::string::npos) << plan.runs[0].run_dir;
  options.presets = {"atlantis+blur"};
  EXPECT_THROW(PlanSuite(options), std::invalid_argument);

  const std::vector<std::string> entries = RobustnessEntries({});
  ASSERT_EQ(entries.size(), 1 + SuiteVariantNames().size() + 2 * HarderScenePresets().size());
  EXPECT_EQ(entries.front(), "cloudy_urban");
  EXPECT_EQ(entries[1], "cloudy_urban+" + SuiteVariantNames().front());
  EXPECT_EQ(entries[entries.size() - 2], HarderScenePresets().back().name);
  EXPECT_EQ(entries.back(), HarderScenePresets().back().name + "+realistic");
}

TEST(SuitePlan, OptionsRoundTripThroughJsonAndBadFieldsAreNamed) {
  const SuiteOptions o = SmallSuite(TempDir("json"));
  EXPECT_EQ(SuiteOptionsToJson(SuiteOptionsFromJson(SuiteOptionsToJson(o), "x")), SuiteOptionsToJson(o));
  nlohmann::json j = SuiteOptionsToJson(o);
  j["draws"] = "many";
  try {
    SuiteOptionsFromJson(j, "plan.json");
    FAIL() << "expected a throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("plan.json: field \"draws\""), std::string::npos) << e.what();
  }
}

TEST(SuiteResume, ARunFromAnotherDrawIsRedone) {
  const fs::path dir = TempDir("reuse");
  fs::create_directories(dir);
  for (const std::string& f :
       {RunTrajectoryPath(dir.string()), RunFramesPath(dir.string()), RunExtrinsicsPath(dir.string())}) {
    std::ofstream(f) << "\n";
  }
  const nlohmann::json info = {{"mode", "online"}, {"dataset", "/d"}, {"frames", {0, 16}},     {"noise_set", 0},
                               {"seed", 0},        {"draw_seed", 42}, {"draw_sigma_deg", 5.0}, {"max_new_features", 0}};
  std::ofstream(RunInfoPath(dir.string())) << info.dump();
  RunSettings want{ExtrinsicsMode::kOnline, 0, 42, 5.0, 16, 0, 0};
  std::string mismatch;
  EXPECT_TRUE(RunReusable(dir.string(), want, &mismatch)) << mismatch;
  want.draw_seed = 43;
  EXPECT_FALSE(RunReusable(dir.string(), want, &mismatch));
  EXPECT_EQ(mismatch, "draw_seed: 42 vs 43");
  want.draw_seed = 42;
  want.draw_sigma_deg = 2.0;
  EXPECT_FALSE(RunReusable(dir.string(), want, &mismatch));
  EXPECT_EQ(mismatch, "draw_sigma_deg: 5.0 vs 2.0");
  want.draw_seed = -1;  // a stored noise set wanted, a draw recorded
  EXPECT_FALSE(RunReusable(dir.string(), want, &mismatch));
  fs::remove_all(dir);
}

TEST(Batch, IndicesFormatAsSbatchTakesThem) {
  EXPECT_EQ(FormatIndices({0, 1, 2, 3, 7, 9, 10}), "0-3,7,9-10");
  EXPECT_EQ(FormatIndices({5}), "5");
  EXPECT_EQ(ParseIndices("0-3,7,9-10"), (std::vector<int>{0, 1, 2, 3, 7, 9, 10}));
  EXPECT_THROW(ParseIndices("3-1"), std::invalid_argument);
  EXPECT_THROW(ParseIndices("x"), std::invalid_argument);
}

TEST(Batch, FolderHoldsOneScriptPerStageChainedBySubmit) {
  const fs::path out = TempDir("folder");
  BatchOptions options;
  options.shards = 2;
  options.vo.mem = "1G";
  options.rovo = "/opt/rovo/bin/rovo";
  const BatchLayout layout = PlanBatch(SmallSuite(out), options);
  EXPECT_EQ(layout.Tasks("render"), 2);
  EXPECT_EQ(layout.Tasks("vo"), 8);
  EXPECT_EQ(layout.Tasks("merge"), 1);
  EXPECT_EQ(layout.options.vo.cpus, 1);  // --vo-threads 1
  EXPECT_EQ(layout.options.vo.mem, "1G");
  EXPECT_FALSE(layout.options.render.time.empty());
  WriteBatchFolder(layout);
  const fs::path dir = out / "batch";
  const std::string vo = ReadFile((dir / "vo.sbatch").string());
  for (const std::string& line : std::vector<std::string>{
           "#SBATCH --array=0-7", "#SBATCH --cpus-per-task=1", "#SBATCH --mem=1G",
           "#SBATCH --output=" + dir.string() + "/logs/vo_%a.log", "#SBATCH --kill-on-invalid-dep=yes",
           "exec '/opt/rovo/bin/rovo' batch task '" + dir.string() + "' vo"}) {
    EXPECT_NE(vo.find(line), std::string::npos) << line << "\n" << vo;
  }
  const std::string submit = ReadFile((dir / "submit.sh").string());
  EXPECT_NE(submit.find("vo=$(sbatch --parsable --array=0-7 --dependency=afterok:$render vo.sbatch)"),
            std::string::npos)
      << submit;
  EXPECT_NE(submit.find("--dependency=afterok:$vo merge.sbatch"), std::string::npos) << submit;

  const BatchLayout loaded = LoadBatchFolder(dir.string());
  EXPECT_EQ(loaded.shards, 2);
  EXPECT_EQ(loaded.suite.runs.size(), 8u);
  EXPECT_EQ(loaded.suite.options.out_dir, fs::absolute(out).lexically_normal().string());
  // Another plan in the same folder is refused.
  SuiteOptions other = SmallSuite(out);
  other.draws = 1;
  EXPECT_THROW(WriteBatchFolder(PlanBatch(other, options)), std::runtime_error);
  fs::remove_all(out);
}

TEST(Batch, StatusAndResumeFollowMarkersAndTheQueue) {
  const fs::path out = TempDir("status");
  BatchOptions options;
  options.shards = 1;
  options.rovo = "/bin/rovo";
  const BatchLayout layout = PlanBatch(SmallSuite(out), options);
  WriteBatchFolder(layout);
  const std::string dir = (out / "batch").string();
  std::ofstream(dir + "/jobs.tsv") << "render\t10\t0\nvo\t11\t0-7\nmerge\t12\t0\n";
  std::ofstream(dir + "/state/render_0.done") << "{}";
  for (int i : {0, 1, 2, 3, 5}) std::ofstream(dir + "/state/vo_" + std::to_string(i) + ".done") << "{}";
  std::ofstream(dir + "/state/vo_4.failed") << R"({"error": "dataset.json: bad"})";
  std::ofstream(dir + "/logs/vo_4.log") << "line 1\nrovo: dataset.json: bad\n";
  const std::string queue = "11_6 RUNNING\n12_0 PENDING\n";
  BatchStatus status = ReadBatchStatus(dir, &queue);
  ASSERT_EQ(status.tasks.size(), 10u);
  auto state = [&](const std::string& stage, int index) {
    for (const TaskStatus& t : status.tasks) {
      if (t.stage == stage && t.index == index) return t.state;
    }
    return TaskState::kNotSubmitted;
  };
  EXPECT_EQ(state("render", 0), TaskState::kDone);
  EXPECT_EQ(state("vo", 4), TaskState::kFailed);
  EXPECT_EQ(state("vo", 6), TaskState::kRunning);
  EXPECT_EQ(state("vo", 7), TaskState::kLost);  // submitted, not queued, no marker
  EXPECT_EQ(state("merge", 0), TaskState::kPending);
  const std::string text = FormatBatchStatus(layout, status);
  EXPECT_NE(text.find("vo[4] failed"), std::string::npos) << text;
  EXPECT_NE(text.find("rovo: dataset.json: bad"), std::string::npos) << text;  // the log's tail
  EXPECT_NE(text.find("vo[7] lost"), std::string::npos) << text;
  EXPECT_NE(text.find("sacct is not used"), std::string::npos) << text;
  EXPECT_THROW(PlanSubmission(layout, &status), std::runtime_error);  // tasks still queued

  const std::string empty_queue;
  status = ReadBatchStatus(dir, &empty_queue);
  const std::vector<SubmitCall> calls = PlanSubmission(layout, &status);
  ASSERT_EQ(calls.size(), 2u);
  EXPECT_EQ(calls[0].stage, "vo");
  EXPECT_EQ(calls[0].indices, (std::vector<int>{4, 6, 7}));
  EXPECT_EQ(calls[0].depends_on, "");
  EXPECT_EQ(calls[1].stage, "merge");
  EXPECT_EQ(calls[1].depends_on, "vo");
  fs::remove_all(out);
}

}  // namespace
}  // namespace rovo
