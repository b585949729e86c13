// Import of EuRoC-style folders with Kalibr, Basalt or EuRoC sensor.yaml calibrations (exchange.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "datasets/camera_models.h"
#include "datasets/exchange/exchange.h"
#include "datasets/exchange/exchange_imu.h"
#include "datasets/io.h"

namespace rovo {
namespace fs = std::filesystem;
namespace {

// Cameras mav0/cam0, cam1, ... (consecutive from 0).
std::vector<std::string> CameraFolders(const std::string& in_dir) {
  std::vector<std::string> names;
  for (int k = 0; fs::is_directory(fs::path(in_dir) / "mav0" / ("cam" + std::to_string(k))); ++k) {
    names.push_back("cam" + std::to_string(k));
  }
  if (names.empty()) throw std::runtime_error(in_dir + ": mav0/cam0: missing (not a EuRoC-style folder)");
  return names;
}

Rig RigFromExchange(const std::vector<ExchangeCamera>& cameras, const std::string& what) {
  Rig rig;
  for (const ExchangeCamera& c : cameras) {
    RigCamera rc;
    rc.name = c.name;
    rc.camera = CameraFromExchangeLens(c.model, c.params, c.width, c.height, 360.0, what + ": " + c.name);
    rc.camera.max_fov_deg = c.max_fov_deg > 0 ? c.max_fov_deg : ImageFovDeg(rc.camera);
    rc.cam_from_rig = c.cam_from_rig;
    rig.cameras.push_back(rc);
  }
  rig.Check(what);
  return rig;
}

std::vector<ExchangeCamera> ReadCalibration(ExchangeFormat format, const std::string& path,
                                            const std::vector<std::string>& folders, const std::string& in_dir) {
  switch (format) {
    case ExchangeFormat::kKalibr:
      return ReadKalibrCamchain(path);
    case ExchangeFormat::kBasalt:
      return ReadBasaltCalibration(path);
    case ExchangeFormat::kEuroc: {
      std::vector<ExchangeCamera> cameras;
      cameras.reserve(folders.size());
      for (const std::string& name : folders) {
        cameras.push_back(ReadEurocSensorYaml((fs::path(in_dir) / "mav0" / name / "sensor.yaml").string(), name));
      }
      return cameras;
    }
  }
  return {};
}

// sigma/seed of a perturbed set from the Kalibr header line or Basalt's rovo_perturbation.
PerturbedExtrinsics PerturbationInfo(const std::string& path, ExchangeFormat format) {
  PerturbedExtrinsics set;
  if (format == ExchangeFormat::kBasalt) {
    const nlohmann::json json = ReadJsonFile(path);
    if (json.contains("rovo_perturbation")) {
      const nlohmann::json& p = json["rovo_perturbation"];
      try {
        set.sigma_rotation_deg = p.value("sigma_rotation_deg", 0.0);
        set.sigma_translation_m = p.value("sigma_translation_m", 0.0);
        set.seed = p.value("seed", uint64_t{0});
      } catch (const nlohmann::json::exception&) {  // not an object, or a field of another type
        throw std::runtime_error(path +
                                 ": /rovo_perturbation: expected {sigma_rotation_deg, sigma_translation_m, seed} "
                                 "numbers");
      }
    }
    return set;
  }
  // "... sigma_rotation_deg S sigma_translation_m T seed N" (the header KalibrCamchainYaml gets).
  const std::string text = ReadFile(path);
  const size_t at = text.find("sigma_rotation_deg ");
  if (at != std::string::npos) {
    std::istringstream in(text.substr(at, text.find('\n', at) - at));
    std::string key_rotation, key_translation, key_seed;
    in >> key_rotation >> set.sigma_rotation_deg >> key_translation >> set.sigma_translation_m >> key_seed >> set.seed;
    if (!in || key_translation != "sigma_translation_m" || key_seed != "seed") {
      throw std::runtime_error(path + ": header: expected `sigma_rotation_deg S sigma_translation_m T seed N`");
    }
  }
  return set;
}

std::vector<PerturbedExtrinsics> ReadPerturbedSets(ExchangeFormat format, const std::string& calibration, int cameras) {
  std::vector<PerturbedExtrinsics> sets;
  if (format == ExchangeFormat::kEuroc) return sets;
  const fs::path base(calibration);
  const std::string stem = base.stem().string(), ext = base.extension().string();
  for (int k = 0;; ++k) {
    const fs::path path = base.parent_path() / (stem + "-perturbed-" + std::to_string(k) + ext);
    if (!fs::exists(path)) break;
    const std::vector<ExchangeCamera> set_cameras =
        format == ExchangeFormat::kKalibr ? ReadKalibrCamchain(path.string()) : ReadBasaltCalibration(path.string());
    if (static_cast<int>(set_cameras.size()) != cameras) {
      throw std::runtime_error(path.string() + ": has " + std::to_string(set_cameras.size()) + " cameras, the rig " +
                               std::to_string(cameras));
    }
    PerturbedExtrinsics set = PerturbationInfo(path.string(), format);
    for (const ExchangeCamera& c : set_cameras) set.cam_from_rig.push_back(c.cam_from_rig);
    sets.push_back(set);
  }
  return sets;
}

// Timestamps at which every camera has an image, with each camera's file for it.
std::vector<std::pair<int64_t, std::vector<std::string>>> SynchronousFrames(const std::string& in_dir,
                                                                            const std::vector<std::string>& folders) {
  std::map<int64_t, std::vector<std::string>> by_time;
  for (size_t k = 0; k < folders.size(); ++k) {
    const std::string list = (fs::path(in_dir) / "mav0" / folders[k] / "data.csv").string();
    for (const auto& [stamp, file] : ReadEurocImageList(list)) {
      std::vector<std::string>& files = by_time[stamp];
      if (files.size() == k) files.push_back(file);
    }
  }
  std::vector<std::pair<int64_t, std::vector<std::string>>> frames;
  for (auto& [stamp, files] : by_time) {
    if (files.size() == folders.size()) frames.emplace_back(stamp, files);
  }
  if (frames.empty())
    throw std::runtime_error(in_dir + ": mav0/cam*/data.csv: no timestamp has an image of every camera");
  return frames;
}

// Ground truth from state_groundtruth_estimate0/data.csv at the image times (slerp + linear
// interpolation); empty when the file is absent. Throws when an image lies outside its time span.
Trajectory GroundTruthAt(const std::string& in_dir, const std::vector<int64_t>& stamps) {
  const std::string path = (fs::path(in_dir) / "mav0" / "state_groundtruth_estimate0" / "data.csv").string();
  if (!fs::exists(path)) return {};
  const Trajectory source = ReadEurocCsv(path);
  if (source.empty()) throw std::runtime_error(path + ": no poses");
  const double tolerance = 1e-6;
  Trajectory out;
  for (int64_t stamp : stamps) {
    const double t = static_cast<double>(stamp) * 1e-9;
    if (t < source.front().timestamp - tolerance || t > source.back().timestamp + tolerance) {
      throw std::runtime_error(path + ": image time " + std::to_string(stamp) + " ns lies outside the ground truth");
    }
    out.push_back({t, InterpolatePose(source, t)});
  }
  return out;
}

double MedianRate(const std::vector<int64_t>& stamps) {
  if (stamps.size() < 2) return 10.0;
  std::vector<int64_t> dt;
  for (size_t i = 1; i < stamps.size(); ++i) dt.push_back(stamps[i] - stamps[i - 1]);
  std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
  return 1e9 / static_cast<double>(dt[dt.size() / 2]);
}

}  // namespace

double ImageFovDeg(const Camera& lens) {
  Camera wide = lens;
  wide.max_fov_deg = 360.0;
  double max_angle = 0.0;
  auto visit = [&](double u, double v) {
    const std::optional<Eigen::Vector3d> bearing = wide.Unproject(Eigen::Vector2d(u, v));
    if (bearing) max_angle = std::max(max_angle, std::atan2(bearing->head<2>().norm(), bearing->z()));
  };
  for (int u = 0; u < lens.width; ++u) {
    visit(u, 0);
    visit(u, lens.height - 1);
  }
  for (int v = 0; v < lens.height; ++v) {
    visit(0, v);
    visit(lens.width - 1, v);
  }
  return std::min(359.0, 2.0 * max_angle / kDegToRad - 0.01);
}

ImportReport ImportDataset(const std::string& in_dir, const ImportOptions& options) {
  const std::vector<std::string> folders = CameraFolders(in_dir);
  std::string calibration = options.calibration;
  if (calibration.empty() && options.format == ExchangeFormat::kKalibr) calibration = in_dir + "/camchain.yaml";
  if (calibration.empty() && options.format == ExchangeFormat::kBasalt) calibration = in_dir + "/calibration.json";
  std::vector<ExchangeCamera> cameras = ReadCalibration(options.format, calibration, folders, in_dir);
  if (cameras.size() != folders.size()) {
    throw std::runtime_error((calibration.empty() ? in_dir : calibration) + ": " + std::to_string(cameras.size()) +
                             " cameras, but " + in_dir + "/mav0 has " + std::to_string(folders.size()));
  }
  // A sensor.yaml beside the images may state the FOV cone (rovo's exports do).
  for (size_t k = 0; k < cameras.size(); ++k) {
    const fs::path sensor = fs::path(in_dir) / "mav0" / folders[k] / "sensor.yaml";
    if (cameras[k].max_fov_deg <= 0 && fs::exists(sensor)) {
      try {
        cameras[k].max_fov_deg = ReadEurocSensorYaml(sensor.string(), folders[k]).max_fov_deg;
      } catch (const std::runtime_error&) {  // another system's sensor.yaml: the FOV comes from the image
      }
    }
    cameras[k].name = folders[k];
  }
  DatasetInfo info;
  info.generator = "rovo dataset import";
  info.preset = "";
  info.rig = RigFromExchange(cameras, calibration.empty() ? in_dir : calibration);
  info.perturbed = ReadPerturbedSets(options.format, calibration, info.rig.NumCameras());

  const auto frames = SynchronousFrames(in_dir, folders);
  std::vector<int64_t> stamps;
  stamps.reserve(frames.size());
  for (const auto& frame : frames) stamps.push_back(frame.first);
  info.frame_rate = MedianRate(stamps);
  info.frame_count = static_cast<int>(frames.size());
  info.scene_hash = "import " + ExchangeFormatName(options.format);

  EnsureWritableDir(options.out_dir);
  for (size_t f = 0; f < frames.size(); ++f) {
    for (size_t k = 0; k < folders.size(); ++k) {
      const fs::path from = fs::path(in_dir) / "mav0" / folders[k] / "data" / frames[f].second[k];
      const std::string to = ImagePath(options.out_dir, folders[k], static_cast<int>(f));
      if (from.extension() != ".png") throw std::runtime_error(from.string() + ": only PNG images are imported");
      if (!fs::exists(from)) throw std::runtime_error(from.string() + ": image listed in data.csv is missing");
      fs::create_directories(fs::path(to).parent_path());
      const std::string tmp = TempPathFor(to);
      fs::copy_file(from, tmp, fs::copy_options::overwrite_existing);
      CommitTempFile(tmp, to);
    }
  }
  Trajectory gt = GroundTruthAt(in_dir, stamps);
  ApplyExchangeImu(in_dir, options.out_dir, &info, &gt);  // the body is the IMU when mav0/imu0 exists
  ImportReport report;
  if (!gt.empty()) WriteTum(GroundTruthPath(options.out_dir), gt);
  info.has_ground_truth = !gt.empty();
  WriteDatasetInfo(options.out_dir, info);
  report.frames = info.frame_count;
  report.cameras = info.rig.NumCameras();
  report.perturbed_sets = static_cast<int>(info.perturbed.size());
  report.ground_truth = !gt.empty();
  report.issues = ValidateDataset(options.out_dir);
  return report;
}

}  // namespace rovo
