#pragma once
// A VO run on disk (written by vo/, read by eval/):
//   <run>/trajectory.tum   world_from_rig per processed frame (TUM: t tx ty tz qx qy qz qw)
//   <run>/frames.csv       one row per frame, columns as FrameRecord
//   <run>/extrinsics.csv   one row per frame and camera: cam_from_rig estimate at that frame
//   <run>/run.json         configuration and summary (free-form object + required keys below)

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "datasets/rigid3.h"
#include "datasets/trajectory.h"

namespace rovo {

// A frame's outcome, "ok" | "init" | "lost" in frames.csv.
enum class FrameStatus {
  kOk,    // pose from RANSAC + refinement
  kInit,  // (re)initialised from inter-view triangulation
  kLost,  // no pose (too few correspondences, no consensus, unreadable/black image)
};
const char* FrameStatusName(FrameStatus status);
// Throws std::invalid_argument for a name other than "ok", "init", "lost".
FrameStatus FrameStatusFromName(const std::string& name);

struct FrameRecord {
  int frame = 0;
  double timestamp = 0.0;
  int num_correspondences = 0;  // 2D-3D correspondences offered to the RANSAC, all views
  int num_inliers = 0;
  double inlier_ratio = 0.0;           // num_inliers / num_correspondences
  double mean_reproj_error_deg = 0.0;  // mean angular error of inliers after refinement
  bool keyframe = false;
  FrameStatus status = FrameStatus::kOk;
  double time_ms = 0.0;         // wall time from the previous frame's end to this frame's (its back-end done)
  std::string missing_cameras;  // cameras whose image was missing or unreadable, "1;3"; "" when none
};

struct ExtrinsicsRecord {
  int frame = 0;
  double timestamp = 0.0;
  int camera = 0;
  Rigid3 cam_from_rig;
};

// NOLINTNEXTLINE(bugprone-exception-escape): its implicit move moves nlohmann::json, which does not throw.
struct RunData {
  Trajectory trajectory;
  std::vector<FrameRecord> frames;
  std::vector<ExtrinsicsRecord> extrinsics;
  nlohmann::json info;  // run.json: must hold "mode" ("gt"|"noisy"|"online"), "dataset", "seed"
};

std::string RunTrajectoryPath(const std::string& run_dir);
std::string RunFramesPath(const std::string& run_dir);
std::string RunExtrinsicsPath(const std::string& run_dir);
std::string RunInfoPath(const std::string& run_dir);

// Atomic writes of each file.
void WriteFramesCsv(const std::string& path, const std::vector<FrameRecord>& frames);
void WriteExtrinsicsCsv(const std::string& path, const std::vector<ExtrinsicsRecord>& extrinsics);
void WriteRun(const std::string& run_dir, const RunData& run);
// Reads and checks a run folder; throws std::runtime_error naming the file, line and column.
RunData ReadRun(const std::string& run_dir);

}  // namespace rovo
