#include "eval/studies/calibration_study.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "datasets/rig.h"
#include "datasets/run.h"
#include "eval/plots.h"
#include "rovo/version.h"
#include "vo/image_loader.h"
#include "vo/pipeline.h"
#include "vo/startup_calibration.h"

namespace rovo {
namespace fs = std::filesystem;
namespace {

Rigid3 Rigid3FromRunJson(const nlohmann::json& j) {
  const auto& q = j.at("rotation_xyzw");
  const auto& t = j.at("translation");
  return Rigid3(Eigen::Quaterniond(q[3].get<double>(), q[0].get<double>(), q[1].get<double>(), q[2].get<double>()),
                Eigen::Vector3d(t[0].get<double>(), t[1].get<double>(), t[2].get<double>()));
}

std::string RunDir(const CalibrationStudyOptions& o, uint64_t seed) {
  return (fs::path(o.out_dir) / "runs" / ("draw_" + std::to_string(seed))).string();
}

// Whether the run folder holds a finished OnlineExt run of this draw with these settings.
bool RunReusable(const std::string& dir, uint64_t seed, int frame_end, const CalibrationStudyOptions& o) {
  std::error_code ec;
  if (!fs::exists(RunInfoPath(dir), ec) || !fs::exists(RunExtrinsicsPath(dir), ec)) return false;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadFile(RunInfoPath(dir)));
    return j.value("draw_seed", int64_t{-1}) == static_cast<int64_t>(seed) && j.at("frames")[1] == frame_end &&
           j.value("online_startup_shots", -1) == o.startup_shots &&
           j.value("online_startup_spacing", -1) == o.shot_spacing &&
           j.value("online_startup_max_shots", -1) == o.max_shots &&
           j.value("online_startup_min_inliers", -1) == VoOptions{}.startup.min_pair_inliers &&
           j.value("online_anchor_deg", -1.0) == VoOptions{}.startup.anchor_deg &&
           j.value("online_anchor_mm", -1.0) == VoOptions{}.startup.anchor_mm &&
           j.value("version", "") == ROVO_VERSION && j.contains("startup_calibration");
  } catch (const std::exception&) {
    return false;
  }
}

// Error at a frame of the run (the last record at or before it); -1 when the run ends before it.
double ErrorAtFrame(const std::map<int, std::vector<Rigid3>>& by_frame, int frame, const std::vector<Rigid3>& truth) {
  if (by_frame.empty() || by_frame.rbegin()->first < frame) return -1.0;
  auto it = by_frame.upper_bound(frame);
  --it;
  return ExtrinsicErrorDeg(it->second, truth);
}

// The error below which a draw counts as converged.
double Bound(const CalibrationStudyOptions& o) {
  if (o.bound_deg > 0.0) return o.bound_deg;
  return o.shot_only ? o.shot_converged_deg : o.converged_deg;
}

CalibrationDraw RunDraw(const CalibrationStudyOptions& o, const DatasetInfo& info, uint64_t seed) {
  CalibrationDraw d;
  d.seed = seed;
  const std::vector<Rigid3> truth = info.rig.Extrinsics();
  const std::vector<Rigid3> drawn = PerturbExtrinsics(info.rig, o.sigma_deg, 0.0, seed).cam_from_rig;
  d.before_deg = ExtrinsicErrorDeg(drawn, truth);
  if (o.shot_only) {
    StartupCalibrationOptions sopt;
    sopt.shots = o.startup_shots;
    sopt.shot_spacing = o.shot_spacing;
    sopt.max_shots = o.max_shots;
    auto load = [&](int frame) { return LoadFrameImages(o.dataset_dir, info.rig, frame); };
    const int end =
        std::min(info.frame_count, o.shot + (std::max(o.startup_shots, o.max_shots) - 1) * o.shot_spacing + 1);
    const StartupCalibrationReport r =
        CalibrateAtStartup(info.rig, drawn, load, o.shot, end,
                           LoadStaticMasks(o.dataset_dir, info.rig, info.has_static_masks), sopt, true);
    d.startup_cam_from_rig = r.cam_from_rig;
    d.startup_deg = ExtrinsicErrorDeg(r.cam_from_rig, truth);
    d.startup_mm = 1000.0 * ExtrinsicTranslationErrorM(r.cam_from_rig, truth);
    d.startup_converged = r.converged;
    d.startup_status = r.status;
    d.lens_angle_scale = r.ring.angle_scale;
    d.converged = d.startup_deg < Bound(o);
    return d;
  }
  const int frame_end = o.frames > 0 ? std::min(o.frames, info.frame_count) : info.frame_count;
  const std::string dir = RunDir(o, seed);
  if (!RunReusable(dir, seed, frame_end, o)) {
    VoOptions v;
    v.io.dataset_dir = o.dataset_dir;
    v.io.out_dir = dir;
    v.start.mode = ExtrinsicsMode::kOnline;
    v.start.draw_seed = static_cast<int64_t>(seed);
    v.start.draw_sigma_deg = o.sigma_deg;
    v.io.frames.end = frame_end;
    v.io.threads = o.threads;
    v.startup.shots = o.startup_shots;
    v.startup.spacing = o.shot_spacing;
    v.startup.max_shots = o.max_shots;
    v.io.quiet = true;
    RunVo(v);
  }
  const RunData run = ReadRun(dir);
  const nlohmann::json& startup = run.info.at("startup_calibration");
  std::vector<Rigid3> after;
  for (const auto& x : startup.at("cam_from_rig")) after.push_back(Rigid3FromRunJson(x));
  d.startup_cam_from_rig = after;
  d.startup_deg = ExtrinsicErrorDeg(after, truth);
  d.startup_mm = 1000.0 * ExtrinsicTranslationErrorM(after, truth);
  d.startup_converged = startup.at("converged").get<bool>();
  d.startup_status = startup.at("status").get<std::string>();
  d.lens_angle_scale = startup.at("ring").value("angle_scale", 1.0);
  std::map<int, std::vector<Rigid3>> by_frame;
  for (const ExtrinsicsRecord& r : run.extrinsics) {
    auto& v = by_frame[r.frame];
    if (static_cast<int>(v.size()) <= r.camera) v.resize(r.camera + 1);
    v[r.camera] = r.cam_from_rig;
  }
  d.at50_deg = ErrorAtFrame(by_frame, 50, truth);
  d.at100_deg = ErrorAtFrame(by_frame, 100, truth);
  d.end_deg = ErrorAtFrame(by_frame, by_frame.empty() ? 0 : by_frame.rbegin()->first, truth);
  if (!by_frame.empty()) d.end_mm = 1000.0 * ExtrinsicTranslationErrorM(by_frame.rbegin()->second, truth);
  d.converged = d.end_deg >= 0.0 && d.end_deg < Bound(o);
  return d;
}

std::string Deg(double v) {
  if (v < 0.0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

std::string Millimetres(double v) {
  if (v < 0.0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string Scale(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

std::string ReproduceCommand(const CalibrationStudyOptions& o) {
  std::ostringstream s;
  if (o.shot_only) {
    s << "rovo study calibration " << o.dataset_dir << " --shot-only --shot " << o.shot;
    if (o.startup_shots != 1) s << " --startup-shots " << o.startup_shots << " --shot-spacing " << o.shot_spacing;
    if (o.max_shots != o.startup_shots) s << " --max-shots " << o.max_shots;
    s << " --draws 1 --seed {seed} --out study_{seed}";
  } else {
    s << "rovo vo " << o.dataset_dir << " --extrinsics online --draw-seed {seed} --draw-sigma " << o.sigma_deg;
    if (o.frames > 0) s << " --frames 0:" << o.frames;
    if (o.startup_shots != VoOptions{}.startup.shots || o.shot_spacing != VoOptions{}.startup.spacing) {
      s << " --online-startup-shots " << o.startup_shots << " --online-startup-spacing " << o.shot_spacing;
    }
    if (o.max_shots != VoOptions{}.startup.max_shots) s << " --online-startup-max-shots " << o.max_shots;
    s << " --out run_{seed}";
  }
  return s.str();
}

nlohmann::json StartupExtrinsicsJson(const std::vector<Rigid3>& cam_from_rig) {
  nlohmann::json out = nlohmann::json::array();
  for (const Rigid3& t : cam_from_rig) out.push_back(Rigid3ToJson(t));
  return out;
}

nlohmann::json FitScoreJson(const FitScore& s) { return {{"inliers", s.inliers}, {"median_deg", s.median_deg}}; }

nlohmann::json OverlapFitJson(const OverlapFit& fit) {
  nlohmann::json rows = nlohmann::json::array();
  for (const OverlapFitRow& r : fit.rows) {
    rows.push_back({{"frame", r.frame},
                    {"camera_a", r.camera_a},
                    {"camera_b", r.camera_b},
                    {"matches", r.matches},
                    {"given", FitScoreJson(r.given)},
                    {"given_scaled", FitScoreJson(r.given_scaled)},
                    {"results", FitScoreJson(r.results)}});
  }
  return {{"results", fit.results}, {"angle_scale", fit.angle_scale}, {"rows", rows}};
}

void WriteOutputs(const CalibrationStudyOptions& o, const DatasetInfo& info, const CalibrationStudyResult& result) {
  std::ostringstream csv;
  csv << "seed,before_deg,startup_deg,at50_deg,at100_deg,end_deg,startup_converged,converged,lens_angle_scale,"
         "startup_mm,end_mm\n";
  nlohmann::json rows = nlohmann::json::array();
  std::vector<uint64_t> failures;
  for (const CalibrationDraw& d : result.draws) {
    csv << d.seed << ',' << d.before_deg << ',' << d.startup_deg << ',' << d.at50_deg << ',' << d.at100_deg << ','
        << d.end_deg << ',' << (d.startup_converged ? 1 : 0) << ',' << (d.converged ? 1 : 0) << ','
        << d.lens_angle_scale << ',' << d.startup_mm << ',' << d.end_mm << '\n';
    rows.push_back({{"seed", d.seed},
                    {"before_deg", d.before_deg},
                    {"startup_deg", d.startup_deg},
                    {"at50_deg", d.at50_deg},
                    {"at100_deg", d.at100_deg},
                    {"end_deg", d.end_deg},
                    {"startup_converged", d.startup_converged},
                    {"startup_status", d.startup_status},
                    {"lens_angle_scale", d.lens_angle_scale},
                    {"converged", d.converged},
                    {"startup_mm", d.startup_mm},
                    {"end_mm", d.end_mm},
                    {"startup_cam_from_rig", StartupExtrinsicsJson(d.startup_cam_from_rig)}});
    if (!d.converged) failures.push_back(d.seed);
  }
  const double bound = Bound(o);
  const nlohmann::json j = {
      {"generator", "rovo study calibration"},
      {"version", ROVO_VERSION},
      {"dataset", o.dataset_dir},
      {"dataset_seed", info.seed},
      {"sigma_deg", o.sigma_deg},
      {"first_seed", o.first_seed},
      {"draws", o.draws},
      {"frames", o.frames},
      {"shot_only", o.shot_only},
      {"shot", o.shot},
      {"startup_shots", o.startup_shots},
      {"shot_spacing", o.shot_spacing},
      {"max_shots", o.max_shots},
      {"startup_converged", result.startup_converged},
      {"startup_agreement_deg", result.startup_agreement_deg},
      {"converged_below_deg", bound},
      {"converged", result.converged},
      {"rate", result.draws.empty() ? 0.0 : static_cast<double>(result.converged) / result.draws.size()},
      {"failed_seeds", failures},
      {"reproduce", result.reproduce},
      {"per_draw", rows},
      {"overlap_fit", OverlapFitJson(result.overlap_fit)}};
  WriteFileAtomic((fs::path(o.out_dir) / "calibration.csv").string(), csv.str());
  WriteJsonFileAtomic((fs::path(o.out_dir) / "calibration.json").string(), j);
}

}  // namespace

std::string CalibrationStudyTable(const CalibrationStudyOptions& o, const CalibrationStudyResult& result) {
  std::ostringstream s;
  s << "| draw seed | before | after start-up | frame 50 | frame 100 | end | start-up / end (mm) | lens angle scale | "
       "start-up verdict |\n"
    << "|---|---|---|---|---|---|---|---|---|\n";
  for (const CalibrationDraw& d : result.draws) {
    s << "| " << d.seed << " | " << Deg(d.before_deg) << " | " << Deg(d.startup_deg) << " | " << Deg(d.at50_deg)
      << " | " << Deg(d.at100_deg) << " | " << Deg(d.end_deg) << " | " << Millimetres(d.startup_mm) << " / "
      << Millimetres(d.end_mm) << " | " << Scale(d.lens_angle_scale) << " | "
      << (d.startup_converged ? "converged" : d.startup_status) << " |\n";
  }
  s << "\nExtrinsic error: largest over cameras i >= 1 of the rotation angle of est(cam_i_from_cam0) "
       "true(cam_i_from_cam0)^-1, degrees; in mm, largest |t_est - t_true| of cam_i_from_cam0. Lens angle scale: "
       "the start-up's estimate of every lens's off-axis angle scale (1: the lenses as given).\n";
  s << "Converged (" << (o.shot_only ? "start-up" : "end of run") << " < " << Bound(o) << " deg): " << result.converged
    << " of " << result.draws.size() << ".\n";
  s << "Start-up calibration converged by its own verdict: " << result.startup_converged << " of "
    << result.draws.size() << "; largest difference between two of those results: " << Deg(result.startup_agreement_deg)
    << " deg.\n";
  if (result.converged < static_cast<int>(result.draws.size())) {
    s << "Reproduce a failure: `" << result.reproduce << "` with {seed} one of:";
    for (const CalibrationDraw& d : result.draws) {
      if (!d.converged) s << " " << d.seed;
    }
    s << "\n";
  }
  if (!result.overlap_fit.rows.empty()) s << "\n" << OverlapFitTable(result.overlap_fit);
  return s.str();
}

namespace {

// Largest over cameras i >= 1 of `error(est cam_i_from_cam0, true cam_i_from_cam0)`.
template <typename Error>
double WorstRelativeError(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth, const char* what,
                          Error error) {
  if (est.size() != truth.size() || est.empty())
    throw std::invalid_argument(std::string(what) + ": camera counts differ");
  const Rigid3 est_rig_from_cam0 = est[0].Inverse(), true_rig_from_cam0 = truth[0].Inverse();
  double worst = 0.0;
  for (size_t i = 1; i < est.size(); ++i) {
    worst = std::max(worst, error(est[i] * est_rig_from_cam0, truth[i] * true_rig_from_cam0));
  }
  return worst;
}

}  // namespace

double ExtrinsicErrorDeg(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth) {
  return WorstRelativeError(est, truth, "ExtrinsicErrorDeg", [](const Rigid3& e, const Rigid3& t) {
    return RotationDistanceDeg(e.rotation, t.rotation);
  });
}

double ExtrinsicTranslationErrorM(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth) {
  return WorstRelativeError(est, truth, "ExtrinsicTranslationErrorM",
                            [](const Rigid3& e, const Rigid3& t) { return (e.translation - t.translation).norm(); });
}

CalibrationStudyResult RunCalibrationStudy(const CalibrationStudyOptions& options) {
  CalibrationStudyOptions o = options;
  if (o.startup_shots == 0) o.startup_shots = o.shot_only ? 1 : VoOptions{}.startup.shots;
  if (o.max_shots == 0) o.max_shots = o.shot_only ? o.startup_shots : VoOptions{}.startup.max_shots;
  if (o.draws < 1) throw std::invalid_argument("study calibration: --draws must be at least 1");
  if (!(o.sigma_deg >= 0.0)) throw std::invalid_argument("study calibration: --sigma must be non-negative");
  const DatasetInfo info = ReadDatasetInfo(o.dataset_dir);
  if (o.shot < 0 || o.shot >= info.frame_count) {
    throw std::invalid_argument("study calibration: --shot " + std::to_string(o.shot) + " is not a frame of " +
                                DatasetJsonPath(o.dataset_dir) + " (frame_count " + std::to_string(info.frame_count) +
                                ")");
  }
  const int last_shot = o.shot + (o.startup_shots - 1) * o.shot_spacing;
  if (o.shot_only && last_shot >= info.frame_count) {
    throw std::invalid_argument("study calibration: --startup-shots " + std::to_string(o.startup_shots) +
                                " every --shot-spacing " + std::to_string(o.shot_spacing) + " from --shot " +
                                std::to_string(o.shot) + " reach frame " + std::to_string(last_shot) + ", beyond " +
                                DatasetJsonPath(o.dataset_dir) + "'s frame_count " + std::to_string(info.frame_count));
  }
  if (!o.shot_only && info.frame_count > 0 && !fs::exists(GroundTruthPath(o.dataset_dir))) {
    // The OnlineExt runs need no ground truth, but say what the numbers are measured against.
    if (!o.quiet)
      std::fprintf(stderr, "study calibration: no ground-truth poses; errors are against dataset.json's rig\n");
  }
  EnsureWritableDir(o.out_dir);
  CalibrationStudyResult result;
  result.reproduce = ReproduceCommand(o);
  Progress progress("study calibration", o.draws, "draws", o.quiet);
  for (int k = 0; k < o.draws; ++k) {
    result.draws.push_back(RunDraw(o, info, o.first_seed + static_cast<uint64_t>(k)));
    result.converged += result.draws.back().converged ? 1 : 0;
    progress.Add();
  }
  progress.Finish();
  std::vector<const CalibrationDraw*> agreeing;
  for (const CalibrationDraw& d : result.draws) {
    if (d.startup_converged) agreeing.push_back(&d);
  }
  result.startup_converged = static_cast<int>(agreeing.size());
  for (size_t i = 0; i < agreeing.size(); ++i) {
    for (size_t j = i + 1; j < agreeing.size(); ++j) {
      result.startup_agreement_deg =
          std::max(result.startup_agreement_deg,
                   ExtrinsicErrorDeg(agreeing[i]->startup_cam_from_rig, agreeing[j]->startup_cam_from_rig));
    }
  }
  if (!o.fit_frames.empty()) {
    std::vector<FitCalibration> converged;
    converged.reserve(agreeing.size());
    for (const CalibrationDraw* d : agreeing) converged.push_back({d->startup_cam_from_rig, d->lens_angle_scale});
    result.overlap_fit = FitOverlaps(o.dataset_dir, info, o.fit_frames, converged);
  }
  WriteOutputs(o, info, result);
  const std::string table = CalibrationStudyTable(o, result);
  WriteFileAtomic((fs::path(o.out_dir) / "calibration.md").string(), table);
  RunPlotScript("plot_calibration.py", o.out_dir, o.quiet);
  return result;
}

}  // namespace rovo
