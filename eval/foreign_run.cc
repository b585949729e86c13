#include "eval/foreign_run.h"

#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "datasets/io.h"

namespace rovo {
namespace fs = std::filesystem;
namespace {

std::string FindTrajectoryFile(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file()) continue;
    if (name == "trajectory.tum" || name == "trajectory.txt" || name == "trajectory.csv" ||
        name == "trajectory_kitti.txt" || name == "stamped_traj_estimate.txt" || name == "poses.txt" ||
        name == "data.csv" || (name.rfind("f_", 0) == 0 && entry.path().extension() == ".txt")) {
      found.push_back(entry.path().string());
    }
  }
  if (found.size() != 1) {
    throw std::runtime_error(dir +
                             ": expected one trajectory file (trajectory.tum/.txt/.csv, "
                             "stamped_traj_estimate.txt, f_*.txt, poses.txt or data.csv), found " +
                             std::to_string(found.size()));
  }
  return found.front();
}

// The format of a trajectory file from its extension and first data line.
std::string DetectFormat(const std::string& path) {
  if (fs::path(path).extension() == ".csv") return "euroc";
  std::istringstream in(ReadFile(path));
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (line.find(',') != std::string::npos) return "euroc";
    std::istringstream numbers(line);
    int count = 0;
    for (double v; numbers >> v;) ++count;
    if (count == 12) return "kitti";
    if (count == 8) return "tum";
    throw std::runtime_error(path + ": first data line has " + std::to_string(count) +
                             " numbers: neither TUM (8) nor KITTI (12); pass --format");
  }
  throw std::runtime_error(path + ": no poses");
}

}  // namespace

RunData ReadRunOrTrajectory(const std::string& path, const Trajectory& gt, const std::string& format,
                            std::string* note) {
  if (fs::is_directory(path) && fs::exists(RunInfoPath(path)) && (format == "auto")) return ReadRun(path);
  if (!fs::exists(path)) throw std::runtime_error(path + ": no such run folder or trajectory file");
  const std::string file = fs::is_directory(path) ? FindTrajectoryFile(path) : path;
  const std::string kind = format == "auto" ? DetectFormat(file) : format;
  RunData run;
  std::string text;
  if (kind == "tum") {
    bool ns = false;
    run.trajectory = ReadTumAnyUnit(file, &ns);
    text = std::string("TUM, timestamps in ") + (ns ? "nanoseconds" : "seconds");
  } else if (kind == "euroc") {
    run.trajectory = ReadEurocCsv(file);
    text = "EuRoC csv";
  } else if (kind == "kitti") {
    std::vector<double> stamps;
    for (const StampedPose& p : gt) stamps.push_back(p.timestamp);
    run.trajectory = ReadKittiPoses(file, stamps);
    text = "KITTI poses, line i = ground-truth frame i";
  } else {
    throw std::runtime_error("--format " + format + ": unknown (auto, tum, euroc, kitti)");
  }
  if (run.trajectory.empty()) throw std::runtime_error(file + ": no poses");
  if (!gt.empty() && (run.trajectory.front().timestamp > gt.back().timestamp ||
                      run.trajectory.back().timestamp < gt.front().timestamp)) {
    const double shift = gt.front().timestamp - run.trajectory.front().timestamp;
    for (StampedPose& p : run.trajectory) p.timestamp += shift;
    text += "; no overlap with the ground truth's times: shifted by " + std::to_string(shift) + " s";
  }
  run.info = {
      {"mode", "external"}, {"dataset", ""}, {"seed", 0}, {"trajectory_file", file}, {"trajectory_format", text}};
  if (note) *note = file + ": " + text;
  return run;
}

}  // namespace rovo
