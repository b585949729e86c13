// `rovo dataset export | import | lens-fit`: exchange with EuRoC, Kalibr and Basalt (datasets/exchange/exchange.h).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "datasets/exchange/exchange.h"
#include "datasets/exchange/ros2_bag.h"
#include "eval/app/commands.h"

namespace rovo {
namespace {

struct ExportArgs {
  std::string dataset, format = "euroc", out, model;
  double max_fit_error_px = 5.0;
  std::vector<int> cameras;
  bool keep_color = false;
};

void RunExportRos2(const ExportArgs& args) {
  if (!args.model.empty() && args.model != "kb4") {
    throw CLI::ValidationError("--model", "a ROS 2 bag carries the equidistant (kb4) lens only");
  }
  Ros2ExportOptions options;
  options.out_dir = args.out;
  options.max_fit_error_px = args.max_fit_error_px;
  const Ros2ExportReport report = ExportRos2Bag(args.dataset, options);
  double worst = 0.0;
  for (const LensFit& f : report.fits) worst = std::max(worst, f.max_error_px);
  std::printf("exported %d frames (%s ground truth, %s IMU) to %s, equidistant lens fit max error %.3f px\n",
              report.frames, report.ground_truth ? "with" : "without", report.imu ? "with" : "without",
              report.bag_path.c_str(), worst);
  for (const auto& [topic, count] : report.messages) {
    std::printf("  %-28s %llu messages\n", topic.c_str(), static_cast<unsigned long long>(count));
  }
}

void RunExport(const ExportArgs& args) {
  if (args.format == "ros2") {
    RunExportRos2(args);
    return;
  }
  ExportOptions options;
  options.format = ExchangeFormatFromName(args.format);
  options.out_dir = args.out;
  if (!args.model.empty()) options.model = ExchangeLensModelFromName(args.model);
  options.max_fit_error_px = args.max_fit_error_px;
  options.cameras = args.cameras;
  options.grayscale = !args.keep_color;
  const ExportReport report = ExportDataset(args.dataset, options);
  std::printf("Lens fits (every model the %s format carries):\n%s\n", args.format.c_str(), report.fit_table.c_str());
  double worst = 0.0, half_px = 1e9;
  for (const LensFit& f : report.fits) {
    worst = std::max(worst, f.max_error_px);
    half_px = std::min(half_px, f.half_px_angle_deg);
  }
  std::printf(
      "exported %d frames (%s ground truth) to %s as %s with the %s lens: max error %.3f px, < 0.5 px up to "
      "%.1f deg from the axis\n",
      report.frames, report.ground_truth ? "with" : "without", args.out.c_str(), args.format.c_str(),
      ExchangeLensModelName(report.model).c_str(), worst, half_px);
  const DatasetInfo info = ReadDatasetInfo(args.dataset);
  if (info.imu) {
    std::printf("with the IMU: %d samples at %g Hz in mav0/imu0 (the body frame of every file is the IMU)\n",
                info.imu->sample_count, info.imu->rate_hz);
  }
}

void RunImportRos2(const std::string& bag, const std::string& out_dir) {
  const Ros2ImportReport report = ImportRos2Bag(bag, out_dir);
  std::printf("imported %d frames x %d cameras, %s, %s to %s\n", report.frames, report.cameras,
              report.ground_truth ? "ground truth from the odometry" : "no ground truth (no nav_msgs/msg/Odometry)",
              report.imu ? "with the IMU" : "no IMU", out_dir.c_str());
  for (const ValidationIssue& issue : report.issues) {
    std::printf("  %s: %s: %s\n", issue.file.c_str(), issue.field.c_str(), issue.message.c_str());
  }
}

void RunImport(const std::string& in_dir, const ImportOptions& options) {
  const ImportReport report = ImportDataset(in_dir, options);
  std::printf("imported %d frames x %d cameras, %d perturbed set%s, %s to %s\n", report.frames, report.cameras,
              report.perturbed_sets, report.perturbed_sets == 1 ? "" : "s",
              report.ground_truth ? "ground truth interpolated at the image times"
                                  : "no ground truth (mav0/state_groundtruth_estimate0/data.csv absent)",
              options.out_dir.c_str());
  for (const ValidationIssue& issue : report.issues) {
    std::printf("  %s: %s: %s\n", issue.file.c_str(), issue.field.c_str(), issue.message.c_str());
  }
}

void RunLensFit(const std::string& source) {
  const Rig rig = std::filesystem::exists(source)
                      ? ReadRigJson(std::filesystem::is_directory(source) ? DatasetJsonPath(source) : source)
                      : MakeRigPreset(source);
  std::printf("| camera | model | max error [px] | RMS error [px] | < 0.5 px up to [deg] | FOV in image [deg] |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const RigCamera& rc : rig.cameras) {
    for (ExchangeLensModel model : ExchangeFormatModels(ExchangeFormat::kEuroc)) {
      const LensFit f = FitExchangeLens(rc.camera, model);
      std::printf("| %s | %s%s | %.3f | %.3f | %.1f | %.1f |\n", rc.name.c_str(), ExchangeLensModelName(model).c_str(),
                  f.exact ? " (exact)" : "", f.max_error_px, f.rms_error_px, f.half_px_angle_deg, f.max_angle_deg);
    }
  }
}

}  // namespace

void AddExchangeCommands(CommandTree& tree) {
  CLI::App* dataset = tree.dataset;
  auto args = std::make_shared<ExportArgs>();
  CLI::App* exp = dataset->add_subcommand(
      "export",
      "Write a dataset as a EuRoC/ASL folder (mav0/camK/data/<ns>.png, data.csv, sensor.yaml, ground truth in "
      "EuRoC's csv) plus a Kalibr camchain.yaml or Basalt calibration.json per extrinsic set, and a README with the "
      "frame conventions; or (--format ros2) a ROS 2 bag: metadata.yaml and one MCAP file with images, camera "
      "infos (equidistant lens), the IMU, /tf_static and the ground truth as nav_msgs/Odometry "
      "(docs/exchange.md). The ocam lens is fitted with the chosen model over its whole FOV; the fit error is "
      "printed and written to the README, and the export is refused above --max-fit-error.");
  exp->add_option("dataset", args->dataset, "rovo dataset folder")->required();
  exp->add_option("--format", args->format, "euroc | kalibr | basalt | ros2")
      ->capture_default_str()
      ->check(CLI::IsMember({"euroc", "kalibr", "basalt", "ros2"}));
  exp->add_option("--out", args->out, "Output folder")->required();
  exp->add_option("--model", args->model,
                  "Lens model: ds | eucm | kb4 | omni (default: the format's model with the smallest max error)")
      ->check(CLI::IsMember({"ds", "eucm", "kb4", "omni"}));
  exp->add_option("--max-fit-error", args->max_fit_error_px, "Refuse when a camera's fit errs by more (px)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  exp->add_option("--cameras", args->cameras,
                  "Export only these cameras of the dataset, in this order, as cam0, cam1, ... (e.g. 4,5 for the "
                  "forward stereo pair of the rovo4_stereo rig; rovo_export.json \"cameras\" names the source of "
                  "each). Basalt needs exactly two cameras that see the same scene (docs/systems.md)")
      ->delimiter(',');
  exp->add_flag("--keep-color", args->keep_color,
                "Copy the rendered colour images; by default the images are written as 8-bit grey (sRGB-encoded "
                "Rec. 709 relative luminance), as EuRoC's own are and as Basalt reads them");
  exp->callback([args] { RunExport(*args); });

  auto in_dir = std::make_shared<std::string>();
  auto format = std::make_shared<std::string>("kalibr");
  auto options = std::make_shared<ImportOptions>();
  CLI::App* imp = dataset->add_subcommand(
      "import",
      "Make a rovo dataset from a EuRoC-style multi-camera folder (mav0/camK/data.csv + PNGs) and its calibration: "
      "a Kalibr camchain.yaml (T_cam_imu as cam_from_rig, else camera 0 is the rig), a Basalt calibration.json, or "
      "the folder's own mav0/camK/sensor.yaml (--format euroc), or a ROS 2 bag folder or .mcap file (--format ros2). "
      "Ground truth from "
      "mav0/state_groundtruth_estimate0/data.csv when present; *-perturbed-N files become perturbed sets.");
  imp->add_option("dir", *in_dir, "EuRoC-style folder, or a ROS 2 bag (folder or .mcap)")
      ->required()
      ->check(CLI::ExistingPath);
  imp->add_option("--format", *format, "euroc | kalibr | basalt | ros2")
      ->capture_default_str()
      ->check(CLI::IsMember({"euroc", "kalibr", "basalt", "ros2"}));
  imp->add_option("--calib", options->calibration,
                  "Calibration file (default: DIR/camchain.yaml or DIR/calibration.json)");
  imp->add_option("--out", options->out_dir, "rovo dataset folder to write")->required();
  imp->callback([in_dir, format, options] {
    if (*format == "ros2") {
      RunImportRos2(*in_dir, options->out_dir);
      return;
    }
    options->format = ExchangeFormatFromName(*format);
    RunImport(*in_dir, *options);
  });

  auto source = std::make_shared<std::string>();
  CLI::App* fit = dataset->add_subcommand(
      "lens-fit", "Fit ds, eucm, kb4 and omni to each lens of a rig preset, rig.json or dataset; print the errors");
  fit->add_option("source", *source, "Rig preset name, rig.json or dataset folder")->required();
  fit->callback([source] { RunLensFit(*source); });
}

}  // namespace rovo
