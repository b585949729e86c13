// `rovo dataset validate | info | rig | import-omnimvs` (export, import, lens-fit: exchange_commands.cc).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "datasets/dataset.h"
#include "datasets/exchange/exchange.h"
#include "datasets/exchange/omnimvs.h"
#include "eval/app/commands.h"

namespace rovo {
namespace {

void RunValidate(const std::string& dir) {
  const std::vector<ValidationIssue> issues = ValidateDataset(dir);
  if (!issues.empty()) {
    for (const ValidationIssue& issue : issues) {
      std::printf("%s: %s: %s\n", issue.file.c_str(), issue.field.c_str(), issue.message.c_str());
    }
    std::fflush(stdout);
    std::fprintf(stderr, "rovo: %s: %zu problem%s\n", dir.c_str(), issues.size(), issues.size() == 1 ? "" : "s");
    throw CLI::RuntimeError(1);
  }
  const DatasetInfo info = ReadDatasetInfo(dir);
  const std::string imu = info.imu ? ", IMU " + std::to_string(info.imu->sample_count) + " samples" : "";
  std::printf("OK: %s: %d frames x %d cameras, %zu perturbed set%s%s%s%s\n", dir.c_str(), info.frame_count,
              info.rig.NumCameras(), info.perturbed.size(), info.perturbed.size() == 1 ? "" : "s",
              info.has_depth ? ", depth" : "", info.has_masks ? ", masks" : "", imu.c_str());
}

// The IMU of a dataset (dataset.json /imu and the rig's imu_from_rig).
void PrintImu(const DatasetInfo& info) {
  if (!info.imu) {
    std::printf("\nimu        none\n");
    return;
  }
  const ImuRecord& r = *info.imu;
  const ImuNoise& n = r.noise;
  std::printf(
      "\nimu        %d samples at %.6g Hz from %.9g s (IMU clock), time offset %.6g ms (t_imu = t_cam + "
      "offset), gravity %.6g m/s^2, seed %llu\n",
      r.sample_count, r.rate_hz, r.first_timestamp, r.time_offset_s * 1000.0, r.gravity_m_s2,
      static_cast<unsigned long long>(r.seed));
  std::printf(
      "  noise    %s: gyroscope %.5g rad/s/sqrt(Hz), walk %.5g rad/s^2/sqrt(Hz); accelerometer %.5g "
      "m/s^2/sqrt(Hz), walk %.5g m/s^3/sqrt(Hz)\n",
      r.noise_profile.c_str(), n.gyroscope_noise_density, n.gyroscope_random_walk, n.accelerometer_noise_density,
      n.accelerometer_random_walk);
  std::printf("  biases   initial gyroscope (%+.5f, %+.5f, %+.5f) rad/s, accelerometer (%+.5f, %+.5f, %+.5f) m/s^2\n",
              n.gyroscope_initial_bias.x(), n.gyroscope_initial_bias.y(), n.gyroscope_initial_bias.z(),
              n.accelerometer_initial_bias.x(), n.accelerometer_initial_bias.y(), n.accelerometer_initial_bias.z());
  if (info.rig.imu_from_rig) {
    const Rigid3 rig_from_imu = info.rig.imu_from_rig->Inverse();
    const Eigen::Vector3d rpy = RollPitchYawDegFromQuaternion(rig_from_imu.rotation);
    std::printf(
        "  mount    at (%+.3f, %+.3f, %+.3f) m in the rig, roll/pitch/yaw (%.2f, %.2f, %.2f) deg (rig_from_imu)\n",
        rig_from_imu.translation.x(), rig_from_imu.translation.y(), rig_from_imu.translation.z(), rpy.x(), rpy.y(),
        rpy.z());
  }
}

void RunDatasetInfo(const std::string& dir) {
  const DatasetInfo info = ReadDatasetInfo(dir);
  std::printf("dataset    %s\n", dir.c_str());
  std::printf("generator  %s %s (schema %d)\n", info.generator.c_str(), info.generator_version.c_str(),
              info.schema_version);
  std::printf("seed       %llu\n", static_cast<unsigned long long>(info.seed));
  std::printf("preset     %s\n", info.preset.empty() ? "(custom scene)" : info.preset.c_str());
  std::printf("scene hash %s\n", info.scene_hash.c_str());
  std::printf("frames     %d at %.6g Hz (%.2f s)\n", info.frame_count, info.frame_rate,
              info.frame_count / info.frame_rate);
  const std::string gt_path = GroundTruthPath(dir);
  if (std::filesystem::exists(gt_path)) {
    const Trajectory gt = ReadTum(gt_path);
    if (!gt.empty()) {
      std::printf("trajectory %zu poses, %.3f s, path length %.3f m\n", gt.size(),
                  gt.back().timestamp - gt.front().timestamp, PathLength(gt));
    }
  } else {
    std::printf("trajectory (groundtruth.tum missing)\n");
  }
  std::printf("depth      %s\nmasks      %s\n", info.has_depth ? "yes" : "no", info.has_masks ? "yes" : "no");
  std::printf("\n%-8s %-14s %-11s %7s  %-26s %8s %8s\n", "camera", "model", "size", "FOV", "position in rig (m)", "yaw",
              "pitch");
  for (const RigCamera& rc : info.rig.cameras) {
    // Rounded to the printed millimetre, without "-0.000".
    const Eigen::Vector3d position =
        CameraPositionInRig(rc.cam_from_rig).unaryExpr([](double v) { return std::abs(v) < 5e-4 ? 0.0 : v; });
    char size[32], pos[64];
    std::snprintf(size, sizeof(size), "%dx%d", rc.camera.width, rc.camera.height);
    std::snprintf(pos, sizeof(pos), "(%+.3f, %+.3f, %+.3f)", position.x(), position.y(), position.z());
    std::printf("%-8s %-14s %-11s %6.1f°  %-26s %7.2f° %7.2f°\n", rc.name.c_str(),
                CameraModelName(rc.camera.model).c_str(), size, rc.camera.max_fov_deg, pos,
                CameraYawDeg(rc.cam_from_rig), CameraPitchDeg(rc.cam_from_rig));
  }
  PrintImu(info);
  std::printf("\nperturbed extrinsic sets: %zu\n", info.perturbed.size());
  for (size_t i = 0; i < info.perturbed.size(); ++i) {
    const PerturbedExtrinsics& set = info.perturbed[i];
    double max_deg = 0.0;
    for (size_t c = 0; c < set.cam_from_rig.size() && c < info.rig.cameras.size(); ++c) {
      max_deg = std::max(max_deg,
                         RotationDistanceDeg(set.cam_from_rig[c].rotation, info.rig.cameras[c].cam_from_rig.rotation));
    }
    std::printf("  [%zu] sigma %.3g deg, %.3g m, seed %llu, largest rotation error %.2f deg\n", i,
                set.sigma_rotation_deg, set.sigma_translation_m, static_cast<unsigned long long>(set.seed), max_deg);
  }
}

}  // namespace

void AddDatasetCommands(CommandTree& tree) {
  CLI::App* dataset = tree.dataset;

  auto validate_dir = std::make_shared<std::string>();
  CLI::App* validate = dataset->add_subcommand(
      "validate",
      "Check every field and file of a dataset (dataset.json, groundtruth.tum, image headers). Prints each "
      "problem as `file: field: message` and exits 1 if there is any; prints OK and a summary otherwise.");
  validate->add_option("dir", *validate_dir, "Dataset folder")->required();
  validate->callback([validate_dir] { RunValidate(*validate_dir); });

  auto info_dir = std::make_shared<std::string>();
  CLI::App* info = dataset->add_subcommand(
      "info",
      "Summary of a dataset: generator, seed, preset, frames, duration, path length, rig table, IMU, perturbed "
      "sets");
  info->add_option("dir", *info_dir, "Dataset folder")->required();
  info->callback([info_dir] { RunDatasetInfo(*info_dir); });

  struct RigOptions {
    std::string name, out;
    double scale = 1.0;
  };
  auto rig_options = std::make_shared<RigOptions>();
  std::string preset_list;
  for (const std::string& n : RigPresetNames()) preset_list += (preset_list.empty() ? "" : ", ") + n;
  CLI::App* rig = dataset->add_subcommand("rig", "Write a rig preset as rig.json (for `--rig rig.json`)");
  rig->add_option("name", rig_options->name, "Preset name: " + preset_list)->required();
  rig->add_option("--out,-o", rig_options->out, "Output rig.json")->required();
  rig->add_option("--scale", rig_options->scale, "Scale the image size (intrinsics follow), e.g. 0.5")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  rig->callback([rig_options] {
    Rig preset = MakeRigPreset(rig_options->name);
    std::string source = "preset " + rig_options->name;
    if (rig_options->scale != 1.0) {
      preset = preset.Scaled(rig_options->scale);
      source += " scaled " + std::to_string(rig_options->scale);
    }
    WriteRigJson(rig_options->out, preset, source);
    std::printf("wrote %s (%d cameras, %s)\n", rig_options->out.c_str(), preset.NumCameras(), source.c_str());
  });

  struct ImportOptions {
    std::string yaml, out, images, masks;
  };
  auto import_options = std::make_shared<ImportOptions>();
  CLI::App* import = dataset->add_subcommand(
      "import-omnimvs",
      "Convert an OmniMVS config.yaml rig calibration to rig.json (frame change to REP-103, inverse polynomials "
      "refitted; prints how far the file's own inverse polynomials were off)");
  import->add_option("yaml", import_options->yaml, "OmniMVS config.yaml")->required()->check(CLI::ExistingFile);
  import->add_option("--out,-o", import_options->out, "Output rig.json, or with --images the dataset folder")
      ->required();
  import
      ->add_option("--images", import_options->images,
                   "Import the whole capture: the folder the config's dataset.img_fmt is relative to (a dataset "
                   "without ground-truth poses)")
      ->check(CLI::ExistingDirectory);
  import
      ->add_option("--masks", import_options->masks,
                   "With --images: a folder of static masks cam<i>.png (0 = invalid: rig body, operator)")
      ->check(CLI::ExistingDirectory);
  import->callback([import_options] {
    if (!import_options->images.empty()) {
      std::printf("%s", ImportOmniMvsCapture(import_options->yaml, import_options->images, import_options->masks,
                                             import_options->out).c_str());
  return;
}
std::string report;
const Rig imported = ReadOmniMvsConfig(import_options->yaml, &report);
std::printf("%s", report.c_str());
WriteRigJson(import_options->out, imported, "omnimvs " + import_options->yaml);
std::printf("wrote %s (%d cameras)\n", import_options->out.c_str(), imported.NumCameras());
}  // namespace rovo
);
}

}  // namespace rovo
