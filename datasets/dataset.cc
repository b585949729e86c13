#include "datasets/dataset.h"

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "datasets/dataset_internal.h"
#include "datasets/io.h"
#include "datasets/json_check.h"

namespace rovo {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string JoinPath(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

std::string FrameFileName(int frame, const char* extension) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06d.%s", frame, extension);
  return buf;
}

PerturbedExtrinsics ParsePerturbed(JsonChecker& check, const json& pj, const std::string& p, int num_cameras) {
  PerturbedExtrinsics set;
  if (!check.Object(pj, p)) return set;
  set.sigma_rotation_deg = check.Number(pj, p, "sigma_rotation_deg", 0.0, 0.0, 180.0);
  set.sigma_translation_m = check.Number(pj, p, "sigma_translation_m", 0.0, 0.0, 1e3);
  set.seed = check.Unsigned(pj, p, "seed");
  const json* list = check.Member(pj, p, "cam_from_rig");
  if (!list) return set;
  if (!list->is_array()) {
    check.Issue(p + "/cam_from_rig", "expected an array with one transform per camera");
    return set;
  }
  if (static_cast<int>(list->size()) != num_cameras) {
    check.Issue(p + "/cam_from_rig", "has " + std::to_string(list->size()) + " transforms but the rig has " +
                                         std::to_string(num_cameras) + " cameras");
  }
  for (size_t i = 0; i < list->size(); ++i) {
    // Wrap each element so Transform() can address it by key.
    const json wrapper = json{{std::to_string(i), (*list)[i]}};
    bool ok = false;
    set.cam_from_rig.push_back(check.Transform(wrapper, p + "/cam_from_rig", std::to_string(i), &ok));
  }
  return set;
}

// /sensor (datasets/FORMAT.md, "Sensor"): every field present, typed and in range.
SensorRecord ParseSensor(JsonChecker& check, const json& sj, const std::string& p, int num_cameras) {
  SensorRecord s;
  if (!check.Object(sj, p)) return s;
  constexpr double kBig = 1e12;
  s.profile = check.String(sj, p, "profile", true);
  s.auto_exposure = check.Bool(sj, p, "auto_exposure");
  s.exposure_ms = check.Number(sj, p, "exposure_ms", 1.0, 0.0, 1e6, /*lo_open=*/true);
  s.gain = check.Number(sj, p, "gain", 1.0, 1.0, 1e6);
  s.min_exposure_ms = check.Number(sj, p, "min_exposure_ms", 0.01, 0.0, 1e6, /*lo_open=*/true);
  s.max_exposure_ms = check.Number(sj, p, "max_exposure_ms", 20.0, 0.0, 1e6, /*lo_open=*/true);
  if (s.min_exposure_ms > s.max_exposure_ms)
    check.Issue(p + "/min_exposure_ms", "greater than max_exposure_ms " + JsonChecker::Format(s.max_exposure_ms));
  s.max_gain = check.Number(sj, p, "max_gain", 16.0, 1.0, 1e6);
  s.ae_target = check.Number(sj, p, "ae_target", 0.18, 0.0, 1.0, /*lo_open=*/true);
  s.ae_rate = check.Number(sj, p, "ae_rate", 0.25, 0.0, 1.0, /*lo_open=*/true);
  s.ae_max_step_stops = check.Number(sj, p, "ae_max_step_stops", 0.5, 0.0, 100.0, /*lo_open=*/true);
  s.meter_width = static_cast<int>(check.Integer(sj, p, "meter_width", 200, 1, 1 << 16));
  s.sensitivity_e_per_ms = check.Number(sj, p, "sensitivity_e_per_ms", 1.0, 0.0, kBig, /*lo_open=*/true);
  s.sensitivity_spread = check.Number(sj, p, "sensitivity_spread", 0.0, 0.0, 10.0);
  s.camera_sensitivity = check.Numbers(sj, p, "camera_sensitivity", num_cameras);
  for (size_t c = 0; c < s.camera_sensitivity.size(); ++c) {
    if (!(s.camera_sensitivity[c] > 0.0)) check.Issue(p + "/camera_sensitivity/" + std::to_string(c), "must be > 0");
  }
  s.full_well_e = check.Number(sj, p, "full_well_e", 1.0, 0.0, kBig, /*lo_open=*/true);
  s.shot_noise = check.Bool(sj, p, "shot_noise");
  s.read_noise_e = check.Number(sj, p, "read_noise_e", 0.0, 0.0, kBig);
  s.dark_current_e_per_s = check.Number(sj, p, "dark_current_e_per_s", 0.0, 0.0, kBig);
  s.adc_bits = static_cast<int>(check.Integer(sj, p, "adc_bits", 12, 8, 16));
  s.response = check.String(sj, p, "response", true);
  if (!s.response.empty() && s.response != "srgb" && s.response != "bt709" && s.response != "linear")
    check.Issue(p + "/response", "unknown response curve `" + s.response + "` (known: srgb, bt709, linear)");
  s.grayscale = check.Bool(sj, p, "grayscale");
  return s;
}

// /timing (datasets/FORMAT.md, "Timing"): every field present, typed and in range.
TimingRecord ParseTiming(JsonChecker& check, const json& tj, const std::string& p, int num_cameras, bool has_sensor) {
  TimingRecord t;
  if (!check.Object(tj, p)) return t;
  t.exposure = check.String(tj, p, "exposure", true);
  if (!t.exposure.empty() && t.exposure != "none" && t.exposure != "fixed" && t.exposure != "sensor")
    check.Issue(p + "/exposure", "unknown exposure `" + t.exposure + "` (known: none, fixed, sensor)");
  if (t.exposure == "sensor" && !has_sensor)
    check.Issue(p + "/exposure", "`sensor` needs the /sensor record (exposure.csv holds the exposure times)");
  t.shutter_ms = check.Number(tj, p, "shutter_ms", 0.0, 0.0, 1000.0);
  if (t.exposure == "fixed" && !(t.shutter_ms > 0.0))
    check.Issue(p + "/shutter_ms", "must be > 0 with exposure `fixed`");
  if (t.exposure != "fixed" && t.shutter_ms != 0.0)
    check.Issue(p + "/shutter_ms", "must be 0 unless exposure is `fixed`");
  t.rolling_shutter_ms = check.Number(tj, p, "rolling_shutter_ms", 0.0, 0.0, 1000.0);
  t.trigger_offset_std_ms = check.Number(tj, p, "trigger_offset_std_ms", 0.0, 0.0, 1000.0);
  t.trigger_offset_ms = check.Numbers(tj, p, "trigger_offset_ms", num_cameras);
  for (size_t c = 0; c < t.trigger_offset_ms.size(); ++c) {
    if (!(std::abs(t.trigger_offset_ms[c]) <= 1000.0))
      check.Issue(p + "/trigger_offset_ms/" + std::to_string(c), "must be in [-1000, 1000]");
  }
  if (tj.contains("sampling")) {
    const json& sj = tj["sampling"];
    const std::string sp = p + "/sampling";
    if (!check.Object(sj, sp)) return t;
    t.spp = static_cast<int>(check.Integer(sj, sp, "spp", 0, 1, 4096));
    t.min_spp = static_cast<int>(check.Integer(sj, sp, "min_spp", 0, 1, 4096));
    if (t.spp > 0 && t.min_spp > t.spp) check.Issue(sp + "/min_spp", "must be at most spp");
    t.threshold_codes = check.Number(sj, sp, "threshold_codes", 0.0, 0.0, 255.0);
  }
  return t;
}

json SensorJson(const SensorRecord& s) {
  return json{{"profile", s.profile},
              {"auto_exposure", s.auto_exposure},
              {"exposure_ms", s.exposure_ms},
              {"gain", s.gain},
              {"min_exposure_ms", s.min_exposure_ms},
              {"max_exposure_ms", s.max_exposure_ms},
              {"max_gain", s.max_gain},
              {"ae_target", s.ae_target},
              {"ae_rate", s.ae_rate},
              {"ae_max_step_stops", s.ae_max_step_stops},
              {"meter_width", s.meter_width},
              {"sensitivity_e_per_ms", s.sensitivity_e_per_ms},
              {"sensitivity_spread", s.sensitivity_spread},
              {"camera_sensitivity", s.camera_sensitivity},
              {"full_well_e", s.full_well_e},
              {"shot_noise", s.shot_noise},
              {"read_noise_e", s.read_noise_e},
              {"dark_current_e_per_s", s.dark_current_e_per_s},
              {"adc_bits", s.adc_bits},
              {"response", s.response},
              {"grayscale", s.grayscale}};
}

json TimingJson(const TimingRecord& t) {
  json j{{"exposure", t.exposure},
         {"shutter_ms", t.shutter_ms},
         {"rolling_shutter_ms", t.rolling_shutter_ms},
         {"trigger_offset_std_ms", t.trigger_offset_std_ms},
         {"trigger_offset_ms", t.trigger_offset_ms}};
  if (t.spp > 0) j["sampling"] = json{{"spp", t.spp}, {"min_spp", t.min_spp}, {"threshold_codes", t.threshold_codes}};
  return j;
}

}  // namespace

DatasetInfo ParseDatasetJson(JsonChecker& check, const json& root) {
  DatasetInfo info;
  if (!check.Object(root, "")) return info;
  info.schema_version = static_cast<int>(check.Integer(root, "", "schema_version", 0, 1, 1 << 20));
  if (info.schema_version > kDatasetSchemaVersion) {
    check.Issue("/schema_version", "version " + std::to_string(info.schema_version) + " is newer than this reader (" +
                                       std::to_string(kDatasetSchemaVersion) + ")");
  }
  info.generator = check.String(root, "", "generator", true);
  info.generator_version = check.String(root, "", "generator_version", false);
  info.seed = check.Unsigned(root, "", "seed");
  info.preset = check.String(root, "", "preset", false);
  info.scene_hash = check.String(root, "", "scene_hash", false);
  info.frame_rate = check.Number(root, "", "frame_rate", 10.0, 0.0, 1e6, /*lo_open=*/true);
  info.frame_count = static_cast<int>(check.Integer(root, "", "frame_count", 0, 1, 100000000));
  info.has_depth = check.Bool(root, "", "has_depth");
  info.has_masks = check.Bool(root, "", "has_masks");
  if (root.is_object() && root.contains("has_ground_truth"))
    info.has_ground_truth = check.Bool(root, "", "has_ground_truth");
  if (root.is_object() && root.contains("has_static_masks"))
    info.has_static_masks = check.Bool(root, "", "has_static_masks");
  if (const json* rig = check.Member(root, "", "rig")) info.rig = ParseRig(check, *rig, "/rig");
  if (root.is_object() && root.contains("sensor"))
    info.sensor = ParseSensor(check, root["sensor"], "/sensor", info.rig.NumCameras());
  if (root.is_object() && root.contains("timing"))
    info.timing = ParseTiming(check, root["timing"], "/timing", info.rig.NumCameras(), info.sensor.has_value());
  if (root.is_object() && root.contains("optics"))
    info.optics = ParseOpticsRecord(check, root["optics"], "/optics", info.rig.NumCameras());
  if (root.is_object() && root.contains("imu")) {
    info.imu = ParseImuRecord(check, root["imu"], "/imu");
    if (!info.rig.imu_from_rig) check.Issue("/rig/imu_from_rig", "missing field (dataset.json has /imu)");
  }
  if (const json* perturbed = check.Member(root, "", "perturbed")) {
    if (!perturbed->is_array()) {
      check.Issue("/perturbed", "expected an array of perturbed extrinsic sets, found " + TypeName(*perturbed));
    } else {
      for (size_t i = 0; i < perturbed->size(); ++i) {
        info.perturbed.push_back(
            ParsePerturbed(check, (*perturbed)[i], "/perturbed/" + std::to_string(i), info.rig.NumCameras()));
      }
    }
  }
  return info;
}

bool SensorRecord::operator==(const SensorRecord& o) const { return SensorJson(*this) == SensorJson(o); }

bool TimingRecord::operator==(const TimingRecord& o) const { return TimingJson(*this) == TimingJson(o); }

bool TimingRecord::SameExposure(const TimingRecord& o) const {
  TimingRecord a = *this, b = o;
  a.spp = b.spp = a.min_spp = b.min_spp = 0;
  a.threshold_codes = b.threshold_codes = 0.0;
  return a == b;
}

// ---- paths --------------------------------------------------------------------------------------

std::string DatasetJsonPath(const std::string& dir) { return JoinPath(dir, "dataset.json"); }
std::string GroundTruthPath(const std::string& dir) { return JoinPath(dir, "groundtruth.tum"); }
std::string StaticMaskPath(const std::string& dir, const std::string& camera_name) {
  return JoinPath(JoinPath(dir, "static_masks"), camera_name + ".png");
}
std::string ExposurePath(const std::string& dir) { return JoinPath(dir, "exposure.csv"); }
std::string ImagePath(const std::string& dir, const std::string& camera_name, int frame) {
  return (fs::path(dir) / camera_name / FrameFileName(frame, "png")).string();
}
std::string DepthPath(const std::string& dir, const std::string& camera_name, int frame) {
  return (fs::path(dir) / "depth" / camera_name / FrameFileName(frame, "exr")).string();
}
std::string MaskPath(const std::string& dir, const std::string& camera_name, int frame) {
  return (fs::path(dir) / "masks" / camera_name / FrameFileName(frame, "png")).string();
}

// ---- dataset.json -------------------------------------------------------------------------------

DatasetInfo ReadDatasetInfo(const std::string& dir) {
  const std::string path = DatasetJsonPath(dir);
  const json root = ReadJsonFile(path);
  std::vector<ValidationIssue> issues;
  JsonChecker check(path, &issues);
  DatasetInfo info = ParseDatasetJson(check, root);
  if (!issues.empty()) throw std::runtime_error(JoinIssues(issues));
  return info;
}

void WriteDatasetInfo(const std::string& dir, const DatasetInfo& info) {
  info.rig.Check(DatasetJsonPath(dir) + ": /rig");
  json root;
  root["schema_version"] = info.schema_version;
  root["generator"] = info.generator;
  root["generator_version"] = info.generator_version;
  root["seed"] = info.seed;
  root["preset"] = info.preset;
  root["scene_hash"] = info.scene_hash;
  root["frame_rate"] = info.frame_rate;
  root["frame_count"] = info.frame_count;
  root["has_depth"] = info.has_depth;
  root["has_masks"] = info.has_masks;
  root["has_ground_truth"] = info.has_ground_truth;
  root["has_static_masks"] = info.has_static_masks;
  root["rig"] = RigToJson(info.rig);
  json perturbed = json::array();
  for (const PerturbedExtrinsics& set : info.perturbed) {
    if (set.cam_from_rig.size() != info.rig.cameras.size()) {
      throw std::invalid_argument(DatasetJsonPath(dir) + ": /perturbed: set has " +
                                  std::to_string(set.cam_from_rig.size()) + " transforms for " +
                                  std::to_string(info.rig.cameras.size()) + " cameras");
    }
    json transforms = json::array();
    for (const Rigid3& cam_from_rig : set.cam_from_rig) transforms.push_back(Rigid3ToJson(cam_from_rig));
    perturbed.push_back(json{{"sigma_rotation_deg", set.sigma_rotation_deg},
                             {"sigma_translation_m", set.sigma_translation_m},
                             {"seed", set.seed},
                             {"cam_from_rig", transforms}});
  }
  root["perturbed"] = perturbed;
  if (info.sensor) root["sensor"] = SensorJson(*info.sensor);
  if (info.timing) root["timing"] = TimingJson(*info.timing);
  if (info.optics) root["optics"] = OpticsRecordJson(*info.optics);
  if (info.imu) {
    if (!info.rig.imu_from_rig)
      throw std::invalid_argument(DatasetJsonPath(dir) + ": /rig/imu_from_rig: missing (the dataset has an IMU)");
    root["imu"] = ImuRecordToJson(*info.imu);
  }
  EnsureWritableDir(dir);
  WriteJsonFileAtomic(DatasetJsonPath(dir), root);
}

}  // namespace rovo
