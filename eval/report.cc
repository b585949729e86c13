#include "eval/report.h"

#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "eval/foreign_run.h"
#include "eval/format.h"
#include "eval/plots.h"
#include "rovo/version.h"

namespace rovo {
namespace fs = std::filesystem;

namespace {

std::string FmtOpt(const char* format, const std::optional<double>& value) {
  return value ? Fmt(format, *value) : std::string("n/a");
}

nlohmann::json OptToJson(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

std::string Csv(std::initializer_list<std::string> fields) {
  std::string line;
  bool first = true;
  for (const std::string& f : fields) {
    if (!first) line += ',';
    line += f;
    first = false;
  }
  return line + "\n";
}

std::string Num(double value) { return Fmt("%.10g", value); }

// The keys of the association, alignment, RPE and body-aligned metrics (all optional when read back:
// metrics.json files written before them lack them).
void AddBodyFrameJson(const RunMetrics& m, nlohmann::json* out) {
  nlohmann::json& j = *out;
  j["association"] = m.association;
  j["align"] = m.align;
  j["sim3_scale"] = m.scale;
  j["rpe_delta_s"] = m.rpe.delta_s;
  j["rpe_pairs"] = m.rpe.num_pairs;
  j["rpe_translation_m"] = m.rpe.translation_rmse_m;
  j["rpe_translation_pct"] = m.rpe.translation_pct;
  j["rpe_rotation_deg"] = m.rpe.rotation_rmse_deg;
  const BodyAlignedMetrics& b = m.body;
  j["body_aligned_available"] = b.available;
  j["body_aligned_note"] = b.note;
  j["body_offset_rotation_deg"] = b.offset_rotation_deg;
  j["body_offset_translation_m"] = {b.offset_translation_m.x(), b.offset_translation_m.y(), b.offset_translation_m.z()};
  j["body_offset_translation_rank"] = b.offset_translation_rank;
  j["body_offset_rotation_residual_deg"] = b.offset_rotation_residual_deg;
  j["body_aligned_rmse_origin_m"] = OptToJson(b.rmse_origin_m);
  j["body_aligned_drift_translation_pct"] = b.drift.translation_pct;
  j["body_aligned_drift_rotation_deg_per_100m"] = b.drift.rotation_deg_per_100m;
  j["body_aligned_drift_segments"] = b.drift.num_segments;
  j["body_aligned_rpe_pairs"] = b.rpe.num_pairs;
  j["body_aligned_rpe_translation_m"] = b.rpe.translation_rmse_m;
  j["body_aligned_rpe_translation_pct"] = b.rpe.translation_pct;
  j["body_aligned_rpe_rotation_deg"] = b.rpe.rotation_rmse_deg;
}

template <typename T>
void ReadOptional(const nlohmann::json& j, const char* key, T* value) {
  if (j.contains(key) && !j.at(key).is_null()) *value = j.at(key).get<T>();
}

void ReadBodyFrameJson(const nlohmann::json& j, RunMetrics* m) {
  ReadOptional(j, "association", &m->association);
  ReadOptional(j, "align", &m->align);
  ReadOptional(j, "sim3_scale", &m->scale);
  ReadOptional(j, "rpe_delta_s", &m->rpe.delta_s);
  ReadOptional(j, "rpe_pairs", &m->rpe.num_pairs);
  ReadOptional(j, "rpe_translation_m", &m->rpe.translation_rmse_m);
  ReadOptional(j, "rpe_translation_pct", &m->rpe.translation_pct);
  ReadOptional(j, "rpe_rotation_deg", &m->rpe.rotation_rmse_deg);
  BodyAlignedMetrics& b = m->body;
  ReadOptional(j, "body_aligned_available", &b.available);
  ReadOptional(j, "body_aligned_note", &b.note);
  ReadOptional(j, "body_offset_rotation_deg", &b.offset_rotation_deg);
  if (j.contains("body_offset_translation_m")) {
    const auto t = j.at("body_offset_translation_m").get<std::vector<double>>();
    if (t.size() == 3) b.offset_translation_m = Eigen::Vector3d(t[0], t[1], t[2]);
  }
  ReadOptional(j, "body_offset_translation_rank", &b.offset_translation_rank);
  ReadOptional(j, "body_offset_rotation_residual_deg", &b.offset_rotation_residual_deg);
  if (j.contains("body_aligned_rmse_origin_m") && j.at("body_aligned_rmse_origin_m").is_number()) {
    b.rmse_origin_m = j.at("body_aligned_rmse_origin_m").get<double>();
  }
  ReadOptional(j, "body_aligned_drift_translation_pct", &b.drift.translation_pct);
  ReadOptional(j, "body_aligned_drift_rotation_deg_per_100m", &b.drift.rotation_deg_per_100m);
  ReadOptional(j, "body_aligned_drift_segments", &b.drift.num_segments);
  ReadOptional(j, "body_aligned_rpe_pairs", &b.rpe.num_pairs);
  ReadOptional(j, "body_aligned_rpe_translation_m", &b.rpe.translation_rmse_m);
  ReadOptional(j, "body_aligned_rpe_translation_pct", &b.rpe.translation_pct);
  ReadOptional(j, "body_aligned_rpe_rotation_deg", &b.rpe.rotation_rmse_deg);
}

// "raw → body-aligned" of one figure (n/a when the body offset could not be estimated).
std::string RawAndAligned(const char* format, double raw, bool available, double aligned) {
  return Fmt(format, raw) + " → " + (available ? Fmt(format, aligned) : std::string("n/a"));
}

}  // namespace

nlohmann::json MetricsToJson(const RunMetrics& m) {
  nlohmann::json j;
  j["label"] = m.label;
  j["mode"] = m.mode;
  j["noise_set"] = m.noise_set;
  j["gt_frames"] = m.gt_frames;
  j["estimated_frames"] = m.estimated_frames;
  j["associated_frames"] = m.associated_frames;
  j["missing_frames"] = m.missing_frames;
  j["lost_frames"] = m.lost_frames;
  j["path_length_m"] = m.path_length_m;
  j["rmse_se3_m"] = OptToJson(m.rmse_se3_m);
  j["rmse_origin_m"] = OptToJson(m.rmse_origin_m);
  j["relative_rmse_pct"] = OptToJson(m.relative_rmse_pct);
  j["drift_translation_pct"] = m.drift.translation_pct;
  j["drift_rotation_deg_per_100m"] = m.drift.rotation_deg_per_100m;
  j["drift_segments"] = m.drift.num_segments;
  j["drift_segment_lengths_m"] = m.drift.segment_lengths_m;
  AddBodyFrameJson(m, &j);
  j["mean_inlier_ratio"] = m.mean_inlier_ratio;
  j["mean_reproj_error_deg"] = m.mean_reproj_error_deg;
  j["mean_time_ms"] = m.mean_time_ms;
  j["final_ext_rotation_deg"] = m.final_ext_rotation_deg;
  j["final_ext_translation_m"] = m.final_ext_translation_m;
  j["mean_ext_rotation_deg"] = m.mean_ext_rotation_deg;
  j["mean_ext_translation_m"] = m.mean_ext_translation_m;
  j["max_final_ext_rotation_deg"] = m.max_final_ext_rotation_deg;
  j["max_final_ext_translation_m"] = m.max_final_ext_translation_m;
  j["alignment_note"] = m.alignment_note;
  return j;
}

RunMetrics MetricsFromJson(const nlohmann::json& j, const std::string& what) {
  RunMetrics m;
  auto field = [&](const char* key) -> const nlohmann::json& {
    if (!j.is_object() || !j.contains(key)) throw std::runtime_error(what + ": missing field \"" + key + "\"");
    return j.at(key);
  };
  auto opt = [&](const char* key) -> std::optional<double> {
    const nlohmann::json& v = field(key);
    if (v.is_null()) return std::nullopt;
    if (!v.is_number()) throw std::runtime_error(what + ": field \"" + key + "\" must be a number or null");
    return v.get<double>();
  };
  try {
    m.label = field("label").get<std::string>();
    m.mode = field("mode").get<std::string>();
    m.noise_set = field("noise_set").get<int>();
    m.gt_frames = field("gt_frames").get<int>();
    m.estimated_frames = field("estimated_frames").get<int>();
    m.associated_frames = field("associated_frames").get<int>();
    m.missing_frames = field("missing_frames").get<int>();
    m.lost_frames = field("lost_frames").get<int>();
    m.path_length_m = field("path_length_m").get<double>();
    m.rmse_se3_m = opt("rmse_se3_m");
    m.rmse_origin_m = opt("rmse_origin_m");
    m.relative_rmse_pct = opt("relative_rmse_pct");
    m.drift.translation_pct = field("drift_translation_pct").get<double>();
    m.drift.rotation_deg_per_100m = field("drift_rotation_deg_per_100m").get<double>();
    m.drift.num_segments = field("drift_segments").get<int>();
    m.drift.segment_lengths_m = field("drift_segment_lengths_m").get<std::vector<double>>();
    m.mean_inlier_ratio = field("mean_inlier_ratio").get<double>();
    m.mean_reproj_error_deg = field("mean_reproj_error_deg").get<double>();
    m.mean_time_ms = field("mean_time_ms").get<double>();
    m.final_ext_rotation_deg = field("final_ext_rotation_deg").get<std::vector<double>>();
    m.final_ext_translation_m = field("final_ext_translation_m").get<std::vector<double>>();
    m.mean_ext_rotation_deg = field("mean_ext_rotation_deg").get<std::vector<double>>();
    m.mean_ext_translation_m = field("mean_ext_translation_m").get<std::vector<double>>();
    m.max_final_ext_rotation_deg = field("max_final_ext_rotation_deg").get<double>();
    m.max_final_ext_translation_m = field("max_final_ext_translation_m").get<double>();
    m.alignment_note = field("alignment_note").get<std::string>();
    ReadBodyFrameJson(j, &m);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(what + ": bad metrics object: " + e.what());
  }
  return m;
}

std::string MetricsLegendMarkdown() {
  return "Metrics: **RMSE SE(3)** = translation RMSE [m] after least-squares SE(3) (Umeyama, no scale) alignment of "
         "the estimated to the ground-truth positions (primary); **rel.** = RMSE SE(3) / ground-truth path length "
         "[%]; **RMSE origin** = translation RMSE [m] with the first pose aligned only; **drift** = KITTI-style "
         "relative error averaged over segments of 10..80% of the path length (translation % and deg/100 m); "
         "**inliers** = mean inlier ratio of the multi-view P3P RANSAC over frames with status ok [%]; "
         "**reproj** = mean angular reprojection error of inliers after refinement over frames with status ok "
         "[deg]; **ext rot / ext trans** = largest error over cameras i >= 1 of cam_i_from_cam0 at the last frame "
         "[deg / m]; **ms/frame** = mean wall time per frame. Frames = associated / ground-truth frames. Mode "
         "external: a trajectory written by another system, without frames.csv/run.json/extrinsics.csv, so "
         "inliers, reproj, ext rot, ext trans and ms/frame are n/a. **RPE** = relative pose error over --rpe-delta "
         "(default 1 s) "
         "(translation % of the distance travelled, rotation RMS deg). Columns \"raw → body-aligned\": the raw "
         "figure compares the body the system reports (rovo: the rig with camera 0 as the gauge, so a perturbed "
         "camera 0 turns it; a VIO: its IMU) with the ground truth's rig, so a fixed body offset counts as error; "
         "body-aligned removes the offset that hand-eye calibration (AX = XB over the relative motions) finds "
         "first. **body offset** = that offset's rotation [deg] and translation [m] (the translation only along "
         "the directions the motion determines: planar motion leaves the vertical free). SE(3) and Sim(3) "
         "alignment remove a world offset, which no figure counts; with --align sim3 the estimate's positions are "
         "scaled first.\n";
}

std::string RunTableMarkdown(const std::vector<RunMetrics>& runs) {
  std::string md =
      "| run | mode | noise set | frames | RMSE SE(3) [m] | rel. [%] | RMSE origin [m] raw → body-aligned | drift "
      "[%] raw → body-aligned | drift [deg/100m] raw → body-aligned | RPE [%] raw → body-aligned | RPE "
      "[deg] raw → body-aligned | body offset [deg, m] | inliers [%] | reproj [deg] | ext rot [deg] | ext trans "
      "[m] | ms/frame |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const RunMetrics& m : runs) {
    const BodyAlignedMetrics& b = m.body;
    const std::string origin = FmtOpt("%.4f", m.rmse_origin_m) + " → " + FmtOpt("%.4f", b.rmse_origin_m);
    const std::string offset =
        b.available
            ? Fmt("%.3f", b.offset_rotation_deg) + ", " + Fmt("%.3f", b.offset_translation_m.norm()) +
                  (b.offset_translation_rank < 3 ? " (" + std::to_string(b.offset_translation_rank) + " of 3 axes)"
                                                 : std::string())
            : std::string("n/a");
    std::string sequence = m.label + " | " + m.mode;
    if (m.align == "sim3") sequence += " (sim3 ×" + Fmt("%.4g", m.scale) + ")";
    md += "| " + sequence + " | " + (m.noise_set >= 0 ? std::to_string(m.noise_set) : "-") + " | " +
          std::to_string(m.associated_frames) + "/" + std::to_string(m.gt_frames) + " | " +
          FmtOpt("%.4f", m.rmse_se3_m) + " | " + FmtOpt("%.4f", m.relative_rmse_pct) + " | " + origin + " | " +
          RawAndAligned("%.3f", m.drift.translation_pct, b.available, b.drift.translation_pct) + " | " +
          RawAndAligned("%.3f", m.drift.rotation_deg_per_100m, b.available, b.drift.rotation_deg_per_100m) + " | " +
          RawAndAligned("%.3f", m.rpe.translation_pct, b.available, b.rpe.translation_pct) + " | " +
          RawAndAligned("%.4f", m.rpe.rotation_rmse_deg, b.available, b.rpe.rotation_rmse_deg) + " | " + offset +
          " | " +
          (m.mode == "external"  // no frames.csv / extrinsics.csv
               ? std::string("n/a | n/a | n/a | n/a | n/a |\n")
               : Fmt("%.1f", 100.0 * m.mean_inlier_ratio) + " | " + Fmt("%.3f", m.mean_reproj_error_deg) + " | " +
                     Fmt("%.3f", m.max_final_ext_rotation_deg) + " | " + Fmt("%.4f", m.max_final_ext_translation_m) +
                     " | " + Fmt("%.1f", m.mean_time_ms) + " |\n");
  }
  return md;
}

// groundtruth.csv of a report: timestamp and world position of the rig per frame (for the plots).
static void WriteGroundTruthCsv(const std::string& path, const std::vector<StampedPose>& gt) {
  std::string csv = Csv({"timestamp", "x", "y", "z"});
  for (const StampedPose& p : gt) {
    csv += Csv({Num(p.timestamp), Num(p.world_from_rig.translation.x()), Num(p.world_from_rig.translation.y()),
                Num(p.world_from_rig.translation.z())});
  }
  WriteFileAtomic(path, csv);
}

// Folder name of a run in the report: the run folder's name, made unique with a suffix.
static std::string UniqueRunLabel(const std::string& run_dir, std::map<std::string, int>* label_count) {
  std::string label = fs::path(run_dir).lexically_normal().filename().string();
  if (label.empty() || label == ".") label = fs::path(run_dir).lexically_normal().parent_path().filename().string();
  if (label.empty()) label = "run";
  const int seen = (*label_count)[label]++;
  if (seen > 0) label += "_" + std::to_string(seen + 1);
  return label;
}

// errors.csv, frames.csv, extrinsic_errors.csv and (with --kitti) the KITTI pair of one run.
static void WriteRunFiles(const std::string& run_out, const RunEvaluation& evaluation, const RunData& run,
                          const Trajectory& gt, bool kitti) {
  std::string errors = Csv({"gt_index", "timestamp", "gt_x", "gt_y", "gt_z", "est_x", "est_y", "est_z", "error_m"});
  for (const FrameError& e : evaluation.frame_errors) {
    errors += Csv({std::to_string(e.gt_index), Num(e.timestamp), Num(e.gt_position.x()), Num(e.gt_position.y()),
                   Num(e.gt_position.z()), Num(e.aligned_position.x()), Num(e.aligned_position.y()),
                   Num(e.aligned_position.z()), Num(e.error_m)});
  }
  WriteFileAtomic((fs::path(run_out) / "errors.csv").string(), errors);
  WriteFramesCsv((fs::path(run_out) / "frames.csv").string(), run.frames);
  std::string ext = Csv({"frame", "timestamp", "camera", "rotation_error_deg", "translation_error_m", "roll_est_deg",
                         "pitch_est_deg", "yaw_est_deg", "roll_gt_deg", "pitch_gt_deg", "yaw_gt_deg"});
  for (const ExtrinsicError& e : evaluation.extrinsic_errors) {
    ext += Csv({std::to_string(e.frame), Num(e.timestamp), std::to_string(e.camera), Num(e.rotation_error_deg),
                Num(e.translation_error_m), Num(e.rpy_est_deg.x()), Num(e.rpy_est_deg.y()), Num(e.rpy_est_deg.z()),
                Num(e.rpy_gt_deg.x()), Num(e.rpy_gt_deg.y()), Num(e.rpy_gt_deg.z())});
  }
  WriteFileAtomic((fs::path(run_out) / "extrinsic_errors.csv").string(), ext);

  if (kitti) {
    // Line k of both files is the k-th associated frame; the estimate is mapped into the gt world.
    Trajectory est_aligned, gt_associated;
    for (const FrameError& e : evaluation.frame_errors) {
      gt_associated.push_back({e.timestamp, e.gt_world_from_rig});
      StampedPose est = run.trajectory[static_cast<size_t>(e.estimate_index)];
      est.world_from_rig.translation *= evaluation.metrics.scale;  // 1 unless --align sim3
      est_aligned.push_back({est.timestamp, evaluation.gt_from_est * est.world_from_rig});
    }
    WriteKitti((fs::path(run_out) / "kitti_estimate.txt").string(), est_aligned);
    WriteKitti((fs::path(run_out) / "kitti_groundtruth.txt").string(), gt_associated);
  }
}

// The run's object in metrics.json: its metrics, folder, seed and the gt_from_est alignment.
static nlohmann::json RunJson(const RunEvaluation& evaluation, const RunData& run, const std::string& run_dir) {
  nlohmann::json rj = MetricsToJson(evaluation.metrics);
  rj["run_dir"] = fs::absolute(run_dir).lexically_normal().string();
  rj["run_seed"] = run.info.value("seed", nlohmann::json(nullptr));
  rj["gt_from_est"] = {{"qx", evaluation.gt_from_est.rotation.x()},    {"qy", evaluation.gt_from_est.rotation.y()},
                       {"qz", evaluation.gt_from_est.rotation.z()},    {"qw", evaluation.gt_from_est.rotation.w()},
                       {"tx", evaluation.gt_from_est.translation.x()}, {"ty", evaluation.gt_from_est.translation.y()},
                       {"tz", evaluation.gt_from_est.translation.z()}};
  return rj;
}

static std::string SummaryHeader() {
  return Csv({"label",
              "mode",
              "noise_set",
              "run_seed",
              "gt_frames",
              "associated_frames",
              "missing_frames",
              "lost_frames",
              "path_length_m",
              "rmse_se3_m",
              "relative_rmse_pct",
              "rmse_origin_m",
              "drift_translation_pct",
              "drift_rotation_deg_per_100m",
              "mean_inlier_ratio",
              "mean_reproj_error_deg",
              "max_final_ext_rotation_deg",
              "max_final_ext_translation_m",
              "mean_time_ms",
              "align",
              "sim3_scale",
              "association",
              "rpe_translation_pct",
              "rpe_rotation_deg",
              "body_aligned_rmse_origin_m",
              "body_aligned_drift_translation_pct",
              "body_aligned_drift_rotation_deg_per_100m",
              "body_aligned_rpe_translation_pct",
              "body_aligned_rpe_rotation_deg",
              "body_offset_rotation_deg",
              "body_offset_translation_rank"});
}

// One summary.csv row; `run_seed` is the run's metrics.json seed as JSON text.
static std::string SummaryRow(const RunMetrics& m, const nlohmann::json& run_seed) {
  return Csv({m.label,
              m.mode,
              std::to_string(m.noise_set),
              run_seed.dump(),
              std::to_string(m.gt_frames),
              std::to_string(m.associated_frames),
              std::to_string(m.missing_frames),
              std::to_string(m.lost_frames),
              Num(m.path_length_m),
              m.rmse_se3_m ? Num(*m.rmse_se3_m) : "",
              m.relative_rmse_pct ? Num(*m.relative_rmse_pct) : "",
              m.rmse_origin_m ? Num(*m.rmse_origin_m) : "",
              Num(m.drift.translation_pct),
              Num(m.drift.rotation_deg_per_100m),
              Num(m.mean_inlier_ratio),
              Num(m.mean_reproj_error_deg),
              Num(m.max_final_ext_rotation_deg),
              Num(m.max_final_ext_translation_m),
              Num(m.mean_time_ms),
              m.align,
              Num(m.scale),
              m.association,
              Num(m.rpe.translation_pct),
              Num(m.rpe.rotation_rmse_deg),
              m.body.rmse_origin_m ? Num(*m.body.rmse_origin_m) : "",
              m.body.available ? Num(m.body.drift.translation_pct) : "",
              m.body.available ? Num(m.body.drift.rotation_deg_per_100m) : "",
              m.body.available ? Num(m.body.rpe.translation_pct) : "",
              m.body.available ? Num(m.body.rpe.rotation_rmse_deg) : "",
              m.body.available ? Num(m.body.offset_rotation_deg) : "",
              std::to_string(m.body.offset_translation_rank)});
}

// The dataset-wide files: groundtruth.csv, summary.csv, table.md, metrics.json and (with plots) report.html.
static void WriteReportFiles(const std::string& dataset_dir, const DatasetInfo& info, const Trajectory& gt,
                             const std::string& out_dir, const EvalReportOptions& options,
                             const std::vector<RunEvaluation>& evaluations, const std::string& summary,
                             const nlohmann::json& runs_json) {
  WriteGroundTruthCsv((fs::path(out_dir) / "groundtruth.csv").string(), gt);
  WriteFileAtomic((fs::path(out_dir) / "summary.csv").string(), summary);

  std::vector<RunMetrics> metrics;
  metrics.reserve(evaluations.size());
  for (const RunEvaluation& e : evaluations) metrics.push_back(e.metrics);
  const std::string title = "rovo eval: " + (info.preset.empty() ? dataset_dir : info.preset);
  const std::string table = RunTableMarkdown(metrics);
  WriteFileAtomic((fs::path(out_dir) / "table.md").string(), "# " + title + "\n\nDataset: `" + dataset_dir +
                                                                 "` (seed " + std::to_string(info.seed) + ")\n\n" +
                                                                 table + "\n" + MetricsLegendMarkdown());

  nlohmann::json report;
  report["generator"] = "rovo eval";
  report["generator_version"] = ROVO_VERSION;
  report["dataset"] = fs::absolute(dataset_dir).lexically_normal().string();
  report["dataset_seed"] = info.seed;
  report["preset"] = info.preset;
  report["gt_path_length_m"] = evaluations.front().metrics.path_length_m;
  report["metrics"] = MetricsLegendMarkdown();
  report["runs"] = runs_json;
  WriteJsonFileAtomic((fs::path(out_dir) / "metrics.json").string(), report);

  if (options.plots) {
    const std::vector<std::string> pngs = RunReportPlots(out_dir, options.quiet);
    WriteHtmlReport((fs::path(out_dir) / "report.html").string(), title, table + "\n" + MetricsLegendMarkdown(), pngs);
  }
}

std::vector<RunEvaluation> EvaluateAndReport(const std::string& dataset_dir, const std::vector<std::string>& run_dirs,
                                             const std::string& out_dir, const EvalReportOptions& options) {
  if (run_dirs.empty()) throw std::invalid_argument("rovo eval: no run folders given");
  const DatasetInfo info = ReadDatasetInfo(dataset_dir);
  if (!info.has_ground_truth) {
    throw std::runtime_error(DatasetJsonPath(dataset_dir) +
                             ": has_ground_truth is false: rovo eval scores runs "
                             "against ground-truth poses, which this dataset (a capture) does not have; rovo vo runs "
                             "on it, and rovo study calibration --shot-only measures against its own calibration");
  }
  const Trajectory gt = ReadTum(GroundTruthPath(dataset_dir));
  if (gt.empty()) throw std::runtime_error(GroundTruthPath(dataset_dir) + ": no poses");
  const std::vector<Rigid3> gt_cam_from_rig = info.rig.Extrinsics();
  EnsureWritableDir(out_dir);

  std::vector<RunEvaluation> evaluations;
  std::map<std::string, int> label_count;
  nlohmann::json runs_json = nlohmann::json::array();
  std::string summary = SummaryHeader();
  for (const std::string& run_dir : run_dirs) {
    std::string note;
    const size_t index = evaluations.size();
    RunData run = ReadRunOrTrajectory(run_dir, gt, options.trajectory_format, &note);
    if (options.frame_end > 0 && !run.info.contains("frames")) run.info["frames"] = {0, options.frame_end};
    if (!note.empty() && !options.quiet) std::printf("%s\n", note.c_str());
    const std::string label =
        UniqueRunLabel(index < options.labels.size() ? options.labels[index] : run_dir, &label_count);
    EvalOptions eval = options.eval;
    if (index < options.sim3.size() && options.sim3[index]) eval.align = "sim3";

    RunEvaluation evaluation = EvaluateRun(gt, gt_cam_from_rig, run, label, eval);
    const RunMetrics& m = evaluation.metrics;
    const std::string run_out = (fs::path(out_dir) / label).string();
    EnsureWritableDir(run_out);
    WriteRunFiles(run_out, evaluation, run, gt, options.kitti);

    const nlohmann::json rj = RunJson(evaluation, run, run_dir);
    runs_json.push_back(rj);
    summary += SummaryRow(m, rj["run_seed"]);
    if (!options.quiet && m.missing_frames > 0) {
      std::fprintf(stderr, "rovo eval: %s: %d of %d ground-truth frames have no estimate\n", label.c_str(),
                   m.missing_frames, m.gt_frames);
    }
    if (!options.quiet && !m.alignment_note.empty()) {
      std::fprintf(stderr, "rovo eval: %s: %s\n", label.c_str(), m.alignment_note.c_str());
    }
    evaluations.push_back(std::move(evaluation));
  }

  WriteReportFiles(dataset_dir, info, gt, out_dir, options, evaluations, summary, runs_json);
  return evaluations;
}

}  // namespace rovo
