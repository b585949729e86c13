// Export of rovo datasets to EuRoC/Kalibr/Basalt files and import back (exchange.h).
#include "datasets/exchange/exchange.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "datasets/dataset_cameras.h"
#include "datasets/exchange/exchange_imu.h"
#include "datasets/io.h"

namespace rovo {
namespace fs = std::filesystem;
namespace {

std::string Fmt(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

std::string CamDir(const std::string& out_dir, const std::string& name) {
  return (fs::path(out_dir) / "mav0" / name).string();
}

// Copies a file unless the destination already holds as many bytes (resumable export).
void CopyFileAtomic(const std::string& from, const std::string& to) {
  std::error_code ec;
  if (fs::exists(to, ec) && fs::file_size(to, ec) == fs::file_size(from, ec)) return;
  fs::create_directories(fs::path(to).parent_path());
  const std::string tmp = TempPathFor(to);
  fs::copy_file(from, tmp, fs::copy_options::overwrite_existing, ec);
  if (ec) throw std::runtime_error(from + ": cannot copy to " + tmp + ": " + ec.message());
  CommitTempFile(tmp, to);
}

// Fits every model of the format to every distinct lens of the rig.
std::map<ExchangeLensModel, std::vector<LensFit>> FitAll(const Rig& rig, const std::vector<ExchangeLensModel>& models) {
  std::map<ExchangeLensModel, std::vector<LensFit>> fits;
  for (ExchangeLensModel model : models) {
    std::vector<LensFit>& per_camera = fits[model];
    for (size_t i = 0; i < rig.cameras.size(); ++i) {
      const Camera& camera = rig.cameras[i].camera;
      bool reused = false;
      for (size_t j = 0; j < i && !reused; ++j) {  // identical lenses share one fit
        const Camera& other = rig.cameras[j].camera;
        if (other.model == camera.model && other.params == camera.params && other.width == camera.width &&
            other.height == camera.height && other.max_fov_deg == camera.max_fov_deg) {
          per_camera.push_back(per_camera[j]);
          reused = true;
        }
      }
      if (!reused) per_camera.push_back(FitExchangeLens(camera, model));
    }
  }
  return fits;
}

double WorstError(const std::vector<LensFit>& fits) {
  double worst = 0.0;
  for (const LensFit& f : fits) worst = std::max(worst, f.max_error_px);
  return worst;
}

std::string FitTable(const Rig& rig, const std::map<ExchangeLensModel, std::vector<LensFit>>& fits) {
  std::string table =
      "| camera | model | max error [px] | RMS error [px] | < 0.5 px up to [deg from axis] | FOV in image [deg from "
      "axis] |\n"
      "|---|---|---|---|---|---|\n";
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    for (const auto& [model, per_camera] : fits) {
      const LensFit& f = per_camera[i];
      table += "| " + rig.cameras[i].name + " | " + ExchangeLensModelName(model) + (f.exact ? " (exact)" : "") + " | " +
               Fmt("%.3f", f.max_error_px) + " | " + Fmt("%.3f", f.rms_error_px) + " | " +
               Fmt("%.1f", f.half_px_angle_deg) + " | " + Fmt("%.1f", f.max_angle_deg) + " |\n";
    }
  }
  return table;
}

std::vector<ExchangeCamera> ExchangeCameras(const Rig& rig, ExchangeLensModel model, const std::vector<LensFit>& fits,
                                            const std::vector<Rigid3>& cam_from_rig) {
  std::vector<ExchangeCamera> out;
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    ExchangeCamera c;
    c.name = "cam" + std::to_string(i);
    c.model = model;
    c.params = fits[i].params;
    c.width = rig.cameras[i].camera.width;
    c.height = rig.cameras[i].camera.height;
    c.max_fov_deg = rig.cameras[i].camera.max_fov_deg;
    const Eigen::Quaterniond roll(Eigen::AngleAxisd(fits[i].roll_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
    c.cam_from_rig = Rigid3(roll, Eigen::Vector3d::Zero()) * cam_from_rig[i];
    out.push_back(c);
  }
  return out;
}

// The README's frame conventions: the body is the rig without an IMU, the IMU with one.
std::string RigReadmeLines() {
  return "- Body frame B = the rovo rig frame (REP-103: x forward, y left, z up). World frame W: z up (gravity -z).\n"
         "- Camera frames: x right, y down, z along the optical axis. Pixel centres at integer coordinates, the\n"
         "  top-left pixel's centre at (0, 0).\n"
         "- `mav0/camK/sensor.yaml` `T_BS`: body_from_camera (x_B = T_BS x_cam), row-major 4x4.\n"
         "- Kalibr `camchain*.yaml`: `T_cn_cnm1` = camN_from_cam(N-1); `T_cam_imu` = camN_from_body (the rig stands\n"
         "  in for the IMU; there is no IMU data).\n"
         "- Basalt `calibration*.json`: `T_imu_cam` = body_from_camera, quaternions normalised.\n"
         "- `mav0/state_groundtruth_estimate0/data.csv`: EuRoC columns, `p_RS_R` = rig position in the world,\n"
         "  `q_RS` = world_from_rig rotation (w, x, y, z), `v_RS_R` = world-frame velocity by central differences\n"
         "  of the positions, biases zero (no IMU). R = world, S = rig.\n";
}

std::string ImuReadmeLines(const ImuRecord& imu) {
  return "- Body frame B = the IMU (`mav0/imu0`, EuRoC's S; its mount on the rovo rig is `rovo_imu_from_rig` in\n"
         "  `mav0/imu0/sensor.yaml`). World frame W: z up (gravity -z, " +
         YamlNumber(imu.gravity_m_s2) +
         " m/s^2).\n"
         "- Camera frames: x right, y down, z along the optical axis. Pixel centres at integer coordinates, the\n"
         "  top-left pixel's centre at (0, 0).\n"
         "- `mav0/camK/sensor.yaml` `T_BS`: imu_from_camera (x_B = T_BS x_cam), row-major 4x4.\n"
         "- `mav0/imu0/data.csv`: angular rate (rad/s) and specific force (m/s^2) in the IMU frame at " +
         YamlNumber(imu.rate_hz) + " Hz,\n  stamped on the IMU clock: t_imu = t_cam + " +
         YamlNumber(imu.time_offset_s) +
         " s; `sensor.yaml` has the noise densities and random walks;\n"
         "  `rovo_exact.csv` the noise-free samples (rovo extension).\n"
         "- Kalibr `camchain*.yaml`: `T_cn_cnm1` = camN_from_cam(N-1); `T_cam_imu` = camN_from_imu,\n"
         "  `timeshift_cam_imu` = the IMU clock offset; `imu.yaml`: the IMU's noise and rate.\n"
         "- Basalt `calibration*.json`: `T_imu_cam` = imu_from_camera, quaternions normalised; the IMU's noise\n"
         "  densities and random walks, `imu_update_rate`, `cam_time_offset_ns`.\n"
         "- `mav0/state_groundtruth_estimate0/data.csv`: EuRoC columns at every IMU sample, `p_RS_R` = IMU position\n"
         "  in the world, `q_RS` = world_from_imu rotation (w, x, y, z), `v_RS_R` = the IMU's world-frame velocity,\n"
         "  `b_w_RS_S`, `b_a_RS_S` = the true biases; stamped at the sample's camera-clock time. R = world, S = IMU.\n";
}

std::string Readme(const std::string& dataset_dir, const DatasetInfo& info, const ExportOptions& options,
                   const ExportReport& report) {
  std::ostringstream out;
  out << "# rovo dataset exported for other systems\n\n"
      << "Source: `" << dataset_dir << "` (generator " << info.generator << " " << info.generator_version << ", seed "
      << info.seed << ", preset `" << info.preset << "`), " << report.frames << " frames of " << info.rig.NumCameras()
      << " synchronous cameras at " << info.frame_rate << " Hz. Format: " << ExchangeFormatName(options.format)
      << ", lens model: " << ExchangeLensModelName(report.model) << ".\n\n"
      << "## Frames and conventions\n\n"
      << (info.imu ? ImuReadmeLines(*info.imu) : RigReadmeLines())
      << "- An ocam lens whose affine turns the image axes is exported in a camera frame turned about the optical\n"
      << "  axis by `roll_deg` (rovo_export.json; 0 for ideal affines); the extrinsics above include that turn.\n"
      << "- Images: "
      << (options.grayscale ? "8-bit grey, the sRGB-encoded relative luminance (Rec. 709 weights 0.2126, 0.7152,\n"
                              "  0.0722 on the linearised sRGB values) of the rendered colour images.\n"
                            : "as rendered.\n")
      << "- Cameras: camK of this export is the dataset camera rovo_export.json `cameras[K]` names.\n"
      << "- Timestamps: integer nanoseconds = round(rovo time in seconds x 1e9); image file names are those.\n"
      << "- `camchain-perturbed-N.yaml` / `calibration-perturbed-N.json`: the dataset's perturbed extrinsic sets\n"
      << "  (NoisyExt / OnlineExt starting points; sigma and seed in the file's header / `rovo_perturbation`).\n\n"
      << "## Lens fit\n\n"
      << "The rovo lens was fitted with each model over its whole field of view (bearings every 0.5 deg from the\n"
      << "axis and every 5 deg of azimuth that land in the image); errors are pixel distances to the rovo lens's\n"
      << "projection. Exported: **" << ExchangeLensModelName(report.model) << "**; exports are refused above "
      << options.max_fit_error_px << " px.\n\n"
      << report.fit_table << "\n";
  return out.str();
}

nlohmann::json ExportJson(const DatasetInfo& info, const ExportOptions& options, const ExportReport& report) {
  nlohmann::json fits = nlohmann::json::array();
  for (size_t i = 0; i < report.fits.size(); ++i) {
    const LensFit& f = report.fits[i];
    fits.push_back({{"camera", info.rig.cameras[i].name},
                    {"model", ExchangeLensModelName(f.model)},
                    {"params", f.params},
                    {"exact", f.exact},
                    {"max_error_px", f.max_error_px},
                    {"rms_error_px", f.rms_error_px},
                    {"half_px_angle_deg", f.half_px_angle_deg},
                    {"max_angle_deg", f.max_angle_deg},
                    {"roll_deg", f.roll_deg}});
  }
  return {{"format", ExchangeFormatName(options.format)},
          {"model", ExchangeLensModelName(report.model)},
          {"frames", report.frames},
          {"ground_truth", report.ground_truth},
          {"max_fit_error_px", options.max_fit_error_px},
          {"fits", fits}};
}

std::string PerturbationHeader(const PerturbedExtrinsics& set) {
  return "rovo perturbed extrinsics: sigma_rotation_deg " + Fmt("%.17g", set.sigma_rotation_deg) +
         " sigma_translation_m " + Fmt("%.17g", set.sigma_translation_m) + " seed " + std::to_string(set.seed);
}

void WriteCalibrations(const ExportOptions& options, const DatasetInfo& info, const ExportReport& report) {
  if (options.format == ExchangeFormat::kEuroc) return;
  std::vector<std::pair<std::string, const PerturbedExtrinsics*>> sets = {{"", nullptr}};
  for (size_t k = 0; k < info.perturbed.size(); ++k) {
    sets.emplace_back("-perturbed-" + std::to_string(k), &info.perturbed[k]);
  }
  for (const auto& [suffix, set] : sets) {
    const std::vector<ExchangeCamera> cameras =
        ExchangeCameras(info.rig, report.model, report.fits,
                        ExchangeCamFromBody(info, set ? set->cam_from_rig : info.rig.Extrinsics()));
    if (options.format == ExchangeFormat::kKalibr) {
      const std::string header = set ? PerturbationHeader(*set) : "rovo ground-truth extrinsics";
      WriteFileAtomic((fs::path(options.out_dir) / ("camchain" + suffix + ".yaml")).string(),
                      WithKalibrTimeshift(KalibrCamchainYaml(cameras, header), info));
    } else {
      nlohmann::json json = BasaltCalibrationJson(cameras);
      if (info.imu) SetBasaltImu(*info.imu, &json);
      if (set) {
        json["rovo_perturbation"] = {{"sigma_rotation_deg", set->sigma_rotation_deg},
                                     {"sigma_translation_m", set->sigma_translation_m},
                                     {"seed", set->seed}};
      }
      WriteJsonFileAtomic((fs::path(options.out_dir) / ("calibration" + suffix + ".json")).string(), json);
    }
  }
}

// rovo_export.json "cameras": each exported camera's name and its source camera in the dataset.
nlohmann::json CameraMapJson(const DatasetInfo& full, const std::vector<int>& cameras) {
  nlohmann::json out = nlohmann::json::array();
  for (int k = 0; k < (cameras.empty() ? full.rig.NumCameras() : static_cast<int>(cameras.size())); ++k) {
    const int source = cameras.empty() ? k : cameras[static_cast<size_t>(k)];
    out.push_back({{"name", "cam" + std::to_string(k)},
                   {"source_index", source},
                   {"source_name", full.rig.cameras[static_cast<size_t>(source)].name}});
  }
  return out;
}

ExchangeLensModel ChooseModel(const ExportOptions& options,
                              const std::map<ExchangeLensModel, std::vector<LensFit>>& fits,
                              const std::vector<ExchangeLensModel>& candidates) {
  if (options.model) return *options.model;
  ExchangeLensModel best = candidates.front();
  for (ExchangeLensModel m : candidates) {
    if (WorstError(fits.at(m)) < WorstError(fits.at(best)) - 1e-9) best = m;
  }
  return best;
}

}  // namespace

ExchangeFormat ExchangeFormatFromName(const std::string& name) {
  if (name == "euroc") return ExchangeFormat::kEuroc;
  if (name == "kalibr") return ExchangeFormat::kKalibr;
  if (name == "basalt") return ExchangeFormat::kBasalt;
  throw std::invalid_argument("unknown exchange format '" + name + "' (known: euroc, kalibr, basalt)");
}

std::string ExchangeFormatName(ExchangeFormat format) {
  switch (format) {
    case ExchangeFormat::kEuroc:
      return "euroc";
    case ExchangeFormat::kKalibr:
      return "kalibr";
    case ExchangeFormat::kBasalt:
      return "basalt";
  }
  return "?";
}

std::vector<ExchangeLensModel> ExchangeFormatModels(ExchangeFormat format) {
  using M = ExchangeLensModel;
  switch (format) {
    case ExchangeFormat::kEuroc:
      return {M::kDoubleSphere, M::kExtendedUnified, M::kKannalaBrandt4, M::kOmniRadtan};
    case ExchangeFormat::kKalibr:
      return {M::kDoubleSphere, M::kExtendedUnified, M::kOmniRadtan};
    case ExchangeFormat::kBasalt:
      return {M::kDoubleSphere, M::kExtendedUnified, M::kKannalaBrandt4};
  }
  return {};
}

KalibrLensFields ToKalibrFields(ExchangeLensModel model, const std::vector<double>& p) {
  if (static_cast<int>(p.size()) != ExchangeLensNumParams(model)) {
    throw std::invalid_argument("lens " + ExchangeLensModelName(model) + ": wrong number of parameters");
  }
  switch (model) {
    case ExchangeLensModel::kDoubleSphere:
      return {"ds", {p[4], p[5], p[0], p[1], p[2], p[3]}, "none", {}};
    case ExchangeLensModel::kExtendedUnified:
      return {"eucm", {p[4], p[5], p[0], p[1], p[2], p[3]}, "none", {}};
    case ExchangeLensModel::kKannalaBrandt4:
      return {"pinhole", {p[0], p[1], p[2], p[3]}, "equidistant", {p[4], p[5], p[6], p[7]}};
    case ExchangeLensModel::kOmniRadtan:
      return {"omni", {p[4], p[0], p[1], p[2], p[3]}, "radtan", {p[5], p[6], p[7], p[8]}};
  }
  return {};
}

void FromKalibrFields(const KalibrLensFields& f, const std::string& what, ExchangeLensModel* model,
                      std::vector<double>* params) {
  const std::vector<double>& in = f.intrinsics;
  const std::vector<double>& d = f.distortion_coeffs;
  auto need = [&](size_t intrinsics, const std::string& distortion, size_t coeffs) {
    if (in.size() != intrinsics) {
      throw std::runtime_error(what + ": intrinsics: " + f.camera_model + " needs " + std::to_string(intrinsics) +
                               " numbers, got " + std::to_string(in.size()));
    }
    if (f.distortion_model != distortion || d.size() != coeffs) {
      throw std::runtime_error(what + ": distortion_model: " + f.camera_model + " is read with '" + distortion +
                               "' and " + std::to_string(coeffs) + " coefficients, got '" + f.distortion_model +
                               "' with " + std::to_string(d.size()));
    }
  };
  if (f.camera_model == "ds" || f.camera_model == "eucm") {
    need(6, "none", 0);
    *model = f.camera_model == "ds" ? ExchangeLensModel::kDoubleSphere : ExchangeLensModel::kExtendedUnified;
    *params = {in[2], in[3], in[4], in[5], in[0], in[1]};
  } else if (f.camera_model == "pinhole") {
    need(4, "equidistant", 4);
    *model = ExchangeLensModel::kKannalaBrandt4;
    *params = {in[0], in[1], in[2], in[3], d[0], d[1], d[2], d[3]};
  } else if (f.camera_model == "omni") {
    need(5, "radtan", 4);
    *model = ExchangeLensModel::kOmniRadtan;
    *params = {in[1], in[2], in[3], in[4], in[0], d[0], d[1], d[2], d[3]};
  } else {
    throw std::runtime_error(what + ": camera_model: unknown '" + f.camera_model +
                             "' (known: ds, eucm, pinhole, omni)");
  }
}

ExportReport ExportDataset(const std::string& dataset_dir, const ExportOptions& options) {
  const DatasetInfo full_info = ReadDatasetInfo(dataset_dir);
  const DatasetInfo info = options.cameras.empty()
                               ? full_info
                               : SelectDatasetCameras(full_info, options.cameras,
                                                      "--cameras (" + DatasetJsonPath(dataset_dir) + ": rig.cameras)");
  const std::vector<ExchangeLensModel> candidates = ExchangeFormatModels(options.format);
  if (options.model && std::find(candidates.begin(), candidates.end(), *options.model) == candidates.end()) {
    throw std::invalid_argument("--model " + ExchangeLensModelName(*options.model) + ": the " +
                                ExchangeFormatName(options.format) +
                                " format cannot carry it (Kalibr's pinhole-"
                                "equidistant stops at 180 deg, Basalt has no omni)");
  }
  const std::map<ExchangeLensModel, std::vector<LensFit>> fits =
      FitAll(info.rig, options.model ? std::vector<ExchangeLensModel>{*options.model} : candidates);
  ExportReport report;
  report.model = ChooseModel(options, fits, candidates);
  report.fits = fits.at(report.model);
  report.fit_table = FitTable(info.rig, fits);
  for (size_t i = 0; i < report.fits.size(); ++i) {
    if (!(report.fits[i].max_error_px <= options.max_fit_error_px)) {
      throw std::runtime_error(dataset_dir + ": " + info.rig.cameras[i].name + ": the " +
                               ExchangeLensModelName(report.model) + " fit of the lens errs by up to " +
                               Fmt("%.3f", report.fits[i].max_error_px) + " px, more than the bound of " +
                               Fmt("%.3g", options.max_fit_error_px) + " px (--max-fit-error)\n" + report.fit_table);
    }
  }
  EnsureWritableDir(options.out_dir);
  const std::string gt_path = GroundTruthPath(dataset_dir);
  Trajectory gt;
  if (fs::exists(gt_path)) gt = ReadTum(gt_path);
  report.ground_truth = !gt.empty();
  report.frames = info.frame_count;
  const std::vector<ExchangeCamera> cameras =
      ExchangeCameras(info.rig, report.model, report.fits, ExchangeCamFromBody(info, info.rig.Extrinsics()));
  for (size_t k = 0; k < cameras.size(); ++k) {
    const ExchangeCamera& camera = cameras[k];
    std::string list = "#timestamp [ns],filename\n";
    for (int f = 0; f < info.frame_count; ++f) {
      const double t = report.ground_truth ? gt[static_cast<size_t>(f)].timestamp : f / info.frame_rate;
      const std::string file = std::to_string(SecondsToNs(t)) + ".png";
      const std::string image = ImagePath(dataset_dir, info.rig.cameras[k].name, f);
      const std::string exported = CamDir(options.out_dir, camera.name) + "/data/" + file;
      if (options.grayscale) {
        WriteGrayPng(image, exported);
      } else {
        CopyFileAtomic(image, exported);
      }
      list += std::to_string(SecondsToNs(t)) + "," + file + "\n";
    }
    WriteFileAtomic(CamDir(options.out_dir, camera.name) + "/data.csv", list);
    const std::string comment = "rovo " + camera.name + ", " + ExchangeLensModelName(report.model) + " lens";
    WriteFileAtomic(CamDir(options.out_dir, camera.name) + "/sensor.yaml",
                    EurocSensorYaml(camera, info.frame_rate, comment));
  }
  if (report.ground_truth && !info.imu) {
    WriteFileAtomic(CamDir(options.out_dir, "state_groundtruth_estimate0") + "/data.csv", EurocGroundTruthCsv(gt));
  }
  WriteExchangeImu(dataset_dir, info, options.format == ExchangeFormat::kKalibr, options.out_dir);
  WriteCalibrations(options, info, report);
  WriteFileAtomic((fs::path(options.out_dir) / "README.md").string(), Readme(dataset_dir, info, options, report));
  nlohmann::json export_json = ExportJson(info, options, report);
  export_json["cameras"] = CameraMapJson(full_info, options.cameras);
  export_json["images"] = options.grayscale ? "8-bit grey: sRGB-encoded relative luminance Y = 0.2126 R + 0.7152 G + "
                                              "0.0722 B (Rec. 709) of the linearised rendered sRGB values"
                                            : "as rendered";
  WriteJsonFileAtomic((fs::path(options.out_dir) / "rovo_export.json").string(), export_json);
  return report;
}

std::string YamlNumber(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string YamlList(const std::vector<double>& values) {
  std::string out = "[";
  for (size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + YamlNumber(values[i]);
  return out + "]";
}

}  // namespace rovo
