#pragma once
// Datasets for other systems and from them: EuRoC/ASL folders with Kalibr camchains or Basalt
// calibration files (docs/exchange.md has the layout, the frame conventions and the lens fits);
// ROS 2 bags are ros2_bag.h.
//
//   <out>/mav0/camK/data/<timestamp_ns>.png, data.csv, sensor.yaml   (EuRoC/ASL layout)
//   <out>/mav0/state_groundtruth_estimate0/data.csv                  (EuRoC ground-truth columns)
//   <out>/mav0/imu0/data.csv, sensor.yaml, rovo_exact.csv            (with an IMU, exchange_imu.h)
//   <out>/camchain.yaml, camchain-perturbed-N.yaml, imu.yaml         (--format kalibr)
//   <out>/calibration.json, calibration-perturbed-N.json             (--format basalt)
//   <out>/README.md, rovo_export.json                                (conventions, lens fit errors)
// Without an IMU the EuRoC body frame is the rovo rig frame (REP-103): T_BS = rig_from_cam, Kalibr's
// T_cam_imu = cam_from_rig, Basalt's T_imu_cam = rig_from_cam; T_cn_cnm1 = camN_from_cam(N-1). With
// an IMU (`rovo render ... --imu`) the body is the IMU: T_BS = imu_from_cam, T_cam_imu = cam_from_imu,
// T_imu_cam = imu_from_cam, the ground truth at the IMU rate with the IMU's pose and true biases.
// A quick dataset with its IMU, exported:
//   rovo render --preset cloudy_urban --quick --imu --out data/cloudy_imu
//   rovo dataset export data/cloudy_imu --format euroc|kalibr|basalt|ros2 --out DIR

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/exchange/lens_fit.h"

namespace rovo {

enum class ExchangeFormat { kEuroc, kKalibr, kBasalt };
ExchangeFormat ExchangeFormatFromName(const std::string& name);  // euroc | kalibr | basalt
std::string ExchangeFormatName(ExchangeFormat format);
// The lens models a format can carry (Kalibr's pinhole-equidistant cannot pass 180 degrees and
// Basalt has no omni), in order of preference on ties.
std::vector<ExchangeLensModel> ExchangeFormatModels(ExchangeFormat format);

// One camera as the exchange files describe it.
struct ExchangeCamera {
  std::string name;  // cam0, cam1, ...
  ExchangeLensModel model = ExchangeLensModel::kDoubleSphere;
  std::vector<double> params;  // lens_fit.h layout
  int width = 0;
  int height = 0;
  double max_fov_deg = 0.0;  // 0 when the file does not say
  Rigid3 cam_from_rig;       // cam_from_body: the rig, or the IMU when the dataset has one (exchange_imu.h)
};

// Kalibr's field values of a lens: camera_model, intrinsics, distortion_model, distortion_coeffs.
struct KalibrLensFields {
  std::string camera_model;
  std::vector<double> intrinsics;
  std::string distortion_model;
  std::vector<double> distortion_coeffs;
};
KalibrLensFields ToKalibrFields(ExchangeLensModel model, const std::vector<double>& params);
// Inverse of ToKalibrFields; throws std::runtime_error "<what>: <field>: ..." for lenses rovo cannot use.
void FromKalibrFields(const KalibrLensFields& fields, const std::string& what, ExchangeLensModel* model,
                      std::vector<double>* params);

// EuRoC (exchange_euroc.cc).
std::string EurocSensorYaml(const ExchangeCamera& camera, double rate_hz, const std::string& comment);
ExchangeCamera ReadEurocSensorYaml(const std::string& path, const std::string& name);
// state_groundtruth_estimate0/data.csv text: timestamp [ns], position, quaternion (w first),
// velocity in the world frame (central differences), zero gyro and accelerometer biases.
std::string EurocGroundTruthCsv(const Trajectory& world_from_rig);
int64_t SecondsToNs(double seconds);
// Image list of mav0/camK/data.csv: (timestamp ns, file name). Throws naming the file and line.
std::vector<std::pair<int64_t, std::string>> ReadEurocImageList(const std::string& path);

// The 8-bit grey value of an 8-bit sRGB pixel: the relative luminance Y = 0.2126 R + 0.7152 G +
// 0.0722 B (Rec. 709 / sRGB primaries, as rovo's grayscale sensor measures) of the linearised
// values, encoded again with the sRGB curve.
uint8_t GrayFromSrgb8(uint8_t r, uint8_t g, uint8_t b);
// Writes `from` (an 8-bit PNG, RGB or grey) as an 8-bit single-channel PNG at `to` (atomically;
// kept when `to` already holds a grey image). Throws naming the file.
void WriteGrayPng(const std::string& from, const std::string& to);

// Kalibr (exchange_kalibr.cc). `header` is written as # comment lines first.
std::string KalibrCamchainYaml(const std::vector<ExchangeCamera>& cameras, const std::string& header);
std::vector<ExchangeCamera> ReadKalibrCamchain(const std::string& path);

// Basalt (exchange_basalt.cc): the whole cereal object under "value0".
nlohmann::json BasaltCalibrationJson(const std::vector<ExchangeCamera>& cameras);
std::vector<ExchangeCamera> ReadBasaltCalibration(const std::string& path);

struct ExportOptions {
  ExchangeFormat format = ExchangeFormat::kEuroc;
  std::string out_dir;
  std::optional<ExchangeLensModel> model;  // default: the format's model with the smallest max error
  double max_fit_error_px = 5.0;           // refuse when a camera's fit is worse
  // The dataset's cameras to export, in this order, renumbered cam0, cam1, ... (empty: all);
  // rovo_export.json "cameras" names the source camera of each.
  std::vector<int> cameras;
  // 8-bit grey images (WriteGrayPng), as EuRoC's own data are and as Basalt reads them (it takes an
  // RGB PNG's first channel); false copies the rendered images as they are.
  bool grayscale = true;
};

struct ExportReport {
  ExchangeLensModel model = ExchangeLensModel::kDoubleSphere;
  std::vector<LensFit> fits;  // per camera, the exported model
  std::string fit_table;      // Markdown, every candidate model of the format per camera
  int frames = 0;
  bool ground_truth = false;
};

// Throws std::runtime_error naming the dataset, the camera and the bound when a fit is too poor.
ExportReport ExportDataset(const std::string& dataset_dir, const ExportOptions& options);

struct ImportOptions {
  ExchangeFormat format = ExchangeFormat::kKalibr;
  std::string calibration;  // default: <in>/camchain.yaml (kalibr), <in>/calibration.json (basalt)
  std::string out_dir;
};

struct ImportReport {
  int frames = 0;
  int cameras = 0;
  int perturbed_sets = 0;
  bool ground_truth = false;
  std::vector<ValidationIssue> issues;  // ValidateDataset of the result
};

// A EuRoC-style folder (<in>/mav0/camK/...) plus its calibration becomes a rovo dataset: frames
// where every camera has an image, ground truth interpolated at the image times when
// state_groundtruth_estimate0/data.csv exists, perturbed sets from camchain-perturbed-N.yaml /
// calibration-perturbed-N.json beside the calibration.
ImportReport ImportDataset(const std::string& in_dir, const ImportOptions& options);

// Full FOV cone of an imported lens that does not state it: twice the widest angle from the axis of
// any border pixel's bearing (within the model's valid set), so the whole image is usable.
double ImageFovDeg(const Camera& lens);

// Numbers for the YAML files of the exchange formats: full precision (%.17g), lists as [a, b, c].
std::string YamlNumber(double value);
std::string YamlList(const std::vector<double>& values);

}  // namespace rovo
