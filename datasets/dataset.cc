#include "datasets/dataset.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "datasets/camera_models.h"
#include "datasets/io.h"
#include "datasets/ocam.h"

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

std::string TypeName(const json& j) { return j.type_name(); }

// Messages from helpers that already name the file or field: drop that prefix.
std::string StripPrefix(const std::string& message, const std::string& prefix) {
  return message.compare(0, prefix.size(), prefix) == 0 ? message.substr(prefix.size()) : message;
}

// Reads typed fields of a JSON document and records every problem as (file, JSON pointer,
// message) instead of stopping at the first one. Getters return a default when the field is bad.
class JsonChecker {
 public:
  JsonChecker(std::string file, std::vector<ValidationIssue>* issues) : file_(std::move(file)), issues_(issues) {}

  void Issue(const std::string& pointer, const std::string& message) {
    issues_->push_back({file_, pointer.empty() ? "/" : pointer, message});
  }
  size_t NumIssues() const { return issues_->size(); }

  // Member `key` of object `obj` at `pointer`; nullptr (and an issue unless optional) if absent.
  const json* Member(const json& obj, const std::string& pointer, const std::string& key, bool optional = false) {
    if (!obj.is_object()) return nullptr;  // reported by the caller's type check
    const auto it = obj.find(key);
    if (it == obj.end()) {
      if (!optional) Issue(pointer + "/" + key, "missing field");
      return nullptr;
    }
    return &*it;
  }

  bool Object(const json& j, const std::string& pointer) {
    if (j.is_object()) return true;
    Issue(pointer, "expected an object, found " + TypeName(j));
    return false;
  }

  // Finite number in [lo, hi] (open at the ends when lo_open / hi_open).
  double Number(const json& obj, const std::string& pointer, const std::string& key, double fallback, double lo,
                double hi, bool lo_open = false, bool optional = false) {
    const json* j = Member(obj, pointer, key, optional);
    if (!j) return fallback;
    return NumberValue(*j, pointer + "/" + key, fallback, lo, hi, lo_open);
  }

  double NumberValue(const json& j, const std::string& pointer, double fallback,
                     double lo = -std::numeric_limits<double>::infinity(),
                     double hi = std::numeric_limits<double>::infinity(), bool lo_open = false) {
    if (j.is_null()) {
      Issue(pointer, "null (NaN or Inf written as JSON null?), expected a finite number");
      return fallback;
    }
    if (!j.is_number()) {
      Issue(pointer, "expected a number, found " + TypeName(j));
      return fallback;
    }
    const double v = j.get<double>();
    if (!std::isfinite(v)) {
      Issue(pointer, "NaN or Inf, expected a finite number");
      return fallback;
    }
    if (v < lo || v > hi || (lo_open && v == lo)) {
      Issue(pointer,
            "value " + Format(v) + " out of range " + (lo_open ? "(" : "[") + Format(lo) + ", " + Format(hi) + "]");
      return fallback;
    }
    return v;
  }

  int64_t Integer(const json& obj, const std::string& pointer, const std::string& key, int64_t fallback, int64_t lo,
                  int64_t hi) {
    const json* j = Member(obj, pointer, key);
    if (!j) return fallback;
    if (!j->is_number_integer()) {
      Issue(pointer + "/" + key, "expected an integer, found " + TypeName(*j));
      return fallback;
    }
    if (j->is_number_unsigned() && j->get<uint64_t>() > static_cast<uint64_t>(hi)) {
      Issue(pointer + "/" + key, "value out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      return fallback;
    }
    const int64_t v = j->get<int64_t>();
    if (v < lo || v > hi) {
      Issue(pointer + "/" + key,
            "value " + std::to_string(v) + " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      return fallback;
    }
    return v;
  }

  uint64_t Unsigned(const json& obj, const std::string& pointer, const std::string& key) {
    const json* j = Member(obj, pointer, key);
    if (!j) return 0;
    if (j->is_number_unsigned()) return j->get<uint64_t>();
    Issue(pointer + "/" + key, "expected a non-negative integer, found " +
                                   (j->is_number_integer() ? std::string("a negative integer") : TypeName(*j)));
    return 0;
  }

  std::string String(const json& obj, const std::string& pointer, const std::string& key, bool non_empty) {
    const json* j = Member(obj, pointer, key);
    if (!j) return "";
    if (!j->is_string()) {
      Issue(pointer + "/" + key, "expected a string, found " + TypeName(*j));
      return "";
    }
    std::string v = j->get<std::string>();
    if (non_empty && v.empty()) Issue(pointer + "/" + key, "empty string");
    return v;
  }

  bool Bool(const json& obj, const std::string& pointer, const std::string& key) {
    const json* j = Member(obj, pointer, key);
    if (!j) return false;
    if (!j->is_boolean()) {
      Issue(pointer + "/" + key, "expected true or false, found " + TypeName(*j));
      return false;
    }
    return j->get<bool>();
  }

  // Array of finite numbers; size checked when expected_size >= 0.
  std::vector<double> Numbers(const json& obj, const std::string& pointer, const std::string& key, int expected_size) {
    const json* j = Member(obj, pointer, key);
    if (!j) return {};
    const std::string p = pointer + "/" + key;
    if (!j->is_array()) {
      Issue(p, "expected an array of numbers, found " + TypeName(*j));
      return {};
    }
    if (expected_size >= 0 && static_cast<int>(j->size()) != expected_size) {
      Issue(p, "expected " + std::to_string(expected_size) + " numbers, found " + std::to_string(j->size()));
      return {};
    }
    std::vector<double> out;
    bool ok = true;
    for (size_t i = 0; i < j->size(); ++i) {
      const size_t before = NumIssues();
      out.push_back(NumberValue((*j)[i], p + "/" + std::to_string(i), 0.0));
      ok = ok && NumIssues() == before;
    }
    return ok ? out : std::vector<double>{};
  }

  // {"rotation_xyzw": [4], "translation": [3]}; the quaternion must be unit within 1e-6.
  Rigid3 Transform(const json& obj, const std::string& pointer, const std::string& key, bool* ok) {
    const size_t before = NumIssues();
    const json* j = Member(obj, pointer, key);
    if (!j) {
      *ok = false;
      return Rigid3();
    }
    const std::string p = pointer + "/" + key;
    if (!Object(*j, p)) {
      *ok = false;
      return Rigid3();
    }
    const std::vector<double> q = Numbers(*j, p, "rotation_xyzw", 4);
    const std::vector<double> t = Numbers(*j, p, "translation", 3);
    if (q.size() == 4) {
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(std::abs(norm - 1.0) <= 1e-6)) {
        Issue(p + "/rotation_xyzw", "quaternion norm " + Format(norm) + " is not 1 (tolerance 1e-6)");
      }
    }
    *ok = NumIssues() == before;
    if (!*ok) return Rigid3();
    return Rigid3(Eigen::Quaterniond(q[3], q[0], q[1], q[2]), Eigen::Vector3d(t[0], t[1], t[2]));
  }

  static std::string Format(double v) {
    char buf[40];
    std::snprintf(buf, sizeof(buf), "%.9g", v);
    return buf;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::vector<ValidationIssue>* issues_;
};

// Problem with the projection's monotonicity over the field of view, or "" when fine.
// A lens model must map larger angles from the optical axis to larger image radii, or pixels
// would have two bearings and the inverse would be ambiguous.
std::string ProjectionProblem(const Camera& camera) {
  const double half_fov = 0.5 * camera.max_fov_deg * M_PI / 180.0;
  const std::vector<double>& p = camera.params;
  char buf[160];
  if (camera.model == CameraModelId::kEquidistant) {
    // r(theta) = theta + k1 theta^3 + ... increasing on [0, half_fov].
    double previous = 0.0;
    for (int i = 1; i <= 2000; ++i) {
      const double theta = half_fov * i / 2000.0;
      const double r = EquidistantModel::Distort(p.data(), theta);
      if (!(r > previous)) {
        std::snprintf(buf, sizeof(buf), "r(theta) is not increasing at theta = %.2f deg (k1..k4 fold the image)",
                      theta * 180.0 / M_PI);
        return buf;
      }
      previous = r;
    }
  }
  if (camera.model == CameraModelId::kOcam) {
    // The elevation of the ray must increase with the sensor radius until the FOV edge.
    std::string problem;
    if (!OcamForwardMonotonic(p, camera.max_fov_deg, nullptr, &problem)) return "forward polynomial: " + problem;
    const double inverse_error = OcamInverseMaxErrorPx(p, camera.max_fov_deg);
    if (!(inverse_error <= 0.1)) {
      std::snprintf(buf, sizeof(buf),
                    "the inverse polynomial disagrees with the forward polynomial by %.3g px (tolerance 0.1 px)",
                    inverse_error);
      return buf;
    }
  }
  // Every model: along 8 azimuths the image radius grows with the angle from the axis.
  const auto centre = camera.Project(Eigen::Vector3d(0, 0, 1));
  if (!centre) return "the optical axis does not project";
  for (int a = 0; a < 8; ++a) {
    const double azimuth = a * M_PI / 4.0;
    double previous = 0.0;
    for (int i = 1; i <= 400; ++i) {
      const double theta = half_fov * i / 400.0 * (1.0 - 1e-6);
      const Eigen::Vector3d bearing(std::sin(theta) * std::cos(azimuth), std::sin(theta) * std::sin(azimuth),
                                    std::cos(theta));
      const auto uv = camera.Project(bearing);
      if (!uv) {
        std::snprintf(buf, sizeof(buf), "no projection at %.2f deg from the axis (azimuth %.0f deg)",
                      theta * 180.0 / M_PI, azimuth * 180.0 / M_PI);
        return buf;
      }
      const double r = (*uv - *centre).norm();
      if (!(r > previous)) {
        std::snprintf(buf, sizeof(buf), "image radius is not increasing at %.2f deg from the axis (azimuth %.0f deg)",
                      theta * 180.0 / M_PI, azimuth * 180.0 / M_PI);
        return buf;
      }
      previous = r;
    }
  }
  return "";
}

// Parses /rig (or a rig.json object) into `rig`, recording every problem.
Rig ParseRig(JsonChecker& check, const json& rig_json, const std::string& pointer) {
  Rig rig;
  if (!check.Object(rig_json, pointer)) return rig;
  const json* cameras = check.Member(rig_json, pointer, "cameras");
  if (!cameras) return rig;
  const std::string cp = pointer + "/cameras";
  if (!cameras->is_array() || cameras->empty()) {
    check.Issue(cp, "expected a non-empty array of cameras");
    return rig;
  }
  std::set<std::string> names;
  for (size_t i = 0; i < cameras->size(); ++i) {
    const json& cj = (*cameras)[i];
    const std::string p = cp + "/" + std::to_string(i);
    if (!check.Object(cj, p)) continue;
    const size_t before = check.NumIssues();
    RigCamera rc;
    rc.name = check.String(cj, p, "name", true);
    if (!rc.name.empty()) {
      if (rc.name.find('/') != std::string::npos || rc.name == "." || rc.name == "..") {
        check.Issue(p + "/name", "`" + rc.name + "` is not a valid folder name");
      } else if (!names.insert(rc.name).second) {
        check.Issue(p + "/name", "duplicate camera name `" + rc.name + "`");
      }
    }
    const std::string model = check.String(cj, p, "model", true);
    bool model_ok = false;
    if (!model.empty()) {
      try {
        rc.camera.model = CameraModelFromName(model);
        model_ok = true;
      } catch (const std::exception&) {
        check.Issue(p + "/model",
                    "unknown camera model `" + model + "` (known: equidistant, double_sphere, ocam, extended_unified)");
      }
    }
    rc.camera.width = static_cast<int>(check.Integer(cj, p, "width", 0, 1, 1 << 16));
    rc.camera.height = static_cast<int>(check.Integer(cj, p, "height", 0, 1, 1 << 16));
    rc.camera.params = check.Numbers(cj, p, "params", -1);
    rc.camera.max_fov_deg = check.Number(cj, p, "max_fov_deg", 0.0, 0.0, 360.0, /*lo_open=*/true);
    bool transform_ok = false;
    rc.cam_from_rig = check.Transform(cj, p, "cam_from_rig", &transform_ok);
    if (model_ok && check.NumIssues() == before) {
      bool params_ok = false;
      try {
        rc.camera.Check(p);
        params_ok = true;
      } catch (const std::exception& e) {
        check.Issue(p + "/params", StripPrefix(e.what(), p + ": "));
      }
      if (params_ok) {
        const std::string problem = ProjectionProblem(rc.camera);
        if (!problem.empty()) check.Issue(p + "/params", problem);
      }
    }
    rig.cameras.push_back(rc);
  }
  return rig;
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
  return t;
}

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

std::string JoinIssues(const std::vector<ValidationIssue>& issues) {
  std::string out;
  for (size_t i = 0; i < issues.size(); ++i) {
    if (i) out += "\n";
    out += issues[i].file + ": " + issues[i].field + ": " + issues[i].message;
  }
  return out;
}

json CameraJson(const RigCamera& rc) {
  json j;
  j["name"] = rc.name;
  j["model"] = CameraModelName(rc.camera.model);
  j["width"] = rc.camera.width;
  j["height"] = rc.camera.height;
  j["params"] = rc.camera.params;
  j["max_fov_deg"] = rc.camera.max_fov_deg;
  j["cam_from_rig"] = Rigid3ToJson(rc.cam_from_rig);
  return j;
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
  return json{{"exposure", t.exposure},
              {"shutter_ms", t.shutter_ms},
              {"rolling_shutter_ms", t.rolling_shutter_ms},
              {"trigger_offset_std_ms", t.trigger_offset_std_ms},
              {"trigger_offset_ms", t.trigger_offset_ms}};
}

// Image header check (OpenImageIO reads the header only).
void CheckImage(const std::string& path, const std::string& field, int width, int height, int max_channels,
                std::vector<ValidationIssue>* issues) {
  const std::string png_problem = PngChunkProblem(path);
  if (!png_problem.empty()) {
    issues->push_back({path, field, "unreadable image: " + png_problem});
    return;
  }
  auto input = OIIO::ImageInput::open(path);
  if (!input) {
    std::string error = OIIO::geterror();
    if (error.empty()) error = "cannot open";
    issues->push_back({path, field, "unreadable image: " + error});
    return;
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width != width || spec.height != height) {
    issues->push_back({path, field,
                       "image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                           " but the rig camera is " + std::to_string(width) + "x" + std::to_string(height)});
  }
  if (spec.nchannels < 1 || spec.nchannels > max_channels) {
    issues->push_back({path, field,
                       "image has " + std::to_string(spec.nchannels) + " channels (expected 1.." +
                           std::to_string(max_channels) + ")"});
  }
  input->close();
}

// Frame numbers of files named NNNNNN.<extension> in `folder`; other names go to `others`.
std::set<int> FrameFilesIn(const std::string& folder, const std::string& extension, std::vector<std::string>* others) {
  std::set<int> frames;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::string suffix = "." + extension;
    bool is_frame = name.size() == 6 + suffix.size() && name.compare(6, suffix.size(), suffix) == 0;
    for (int i = 0; is_frame && i < 6; ++i) is_frame = std::isdigit(static_cast<unsigned char>(name[i]));
    if (is_frame) {
      frames.insert(std::stoi(name.substr(0, 6)));
    } else if (others) {
      others->push_back(name);
    }
  }
  return frames;
}

constexpr const char* kExposureHeader = "frame,camera,exposure_ms,gain,meter_luminance,dn_per_radiance,dark_dn";

// exposure.csv rows with every problem recorded as (path, "line N", message naming the column).
std::vector<ExposureRow> ParseExposureCsv(const std::string& text, const std::string& path, int frame_count,
                                          const Rig& rig, std::vector<ValidationIssue>* issues) {
  std::vector<ExposureRow> rows;
  const int num_cameras = rig.NumCameras();
  std::stringstream in(text);
  std::string line;
  int line_number = 0;
  auto issue = [&](const std::string& message) {
    issues->push_back({path, "line " + std::to_string(line_number), message});
  };
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1) {
      if (line != kExposureHeader) issue(std::string("expected the header `") + kExposureHeader + "`");
      continue;
    }
    if (line.empty()) continue;
    std::vector<std::string> fields;
    std::stringstream fs_line(line);
    for (std::string f; std::getline(fs_line, f, ',');) fields.push_back(f);
    if (fields.size() != 7) {
      issue("expected 7 comma-separated fields, found " + std::to_string(fields.size()));
      continue;
    }
    const int index = static_cast<int>(rows.size());
    ExposureRow row;
    const int expected_frame = num_cameras > 0 ? index / num_cameras : 0;
    const std::string expected_camera = num_cameras > 0 ? rig.cameras[index % num_cameras].name : "";
    char* end = nullptr;
    const long frame = std::strtol(fields[0].c_str(), &end, 10);
    if (fields[0].empty() || *end != '\0' || frame != expected_frame)
      issue("column frame: `" + fields[0] + "`, expected " + std::to_string(expected_frame) +
            " (rows are frame-major, cameras in rig order)");
    row.frame = static_cast<int>(frame);
    row.camera = fields[1];
    if (row.camera != expected_camera) issue("column camera: `" + row.camera + "`, expected `" + expected_camera + "`");
    const char* names[5] = {"exposure_ms", "gain", "meter_luminance", "dn_per_radiance", "dark_dn"};
    const double lower[5] = {0.0, 1.0, 0.0, 0.0, 0.0};
    const bool lower_open[5] = {true, false, false, true, false};
    double* values[5] = {&row.exposure_ms, &row.gain, &row.meter_luminance, &row.dn_per_radiance, &row.dark_dn};
    for (int k = 0; k < 5; ++k) {
      const std::string& f = fields[2 + k];
      const double v = std::strtod(f.c_str(), &end);
      if (f.empty() || *end != '\0' || !std::isfinite(v)) {
        issue(std::string("column ") + names[k] + ": `" + f + "` is not a finite number");
      } else if (v < lower[k] || (lower_open[k] && v == lower[k])) {
        issue(std::string("column ") + names[k] + ": " + JsonChecker::Format(v) + " must be " +
              (lower_open[k] ? "> " : ">= ") + JsonChecker::Format(lower[k]));
      }
      *values[k] = v;
    }
    rows.push_back(row);
  }
  const size_t expected_rows = static_cast<size_t>(frame_count) * num_cameras;
  if (line_number == 0) {
    issues->push_back({path, "file", "empty file (expected the header and one row per frame and camera)"});
  } else if (rows.size() != expected_rows) {
    issues->push_back({path, "lines",
                       std::to_string(rows.size()) + " rows but dataset.json has " + std::to_string(frame_count) +
                           " frames x " + std::to_string(num_cameras) + " cameras = " + std::to_string(expected_rows)});
  }
  return rows;
}

}  // namespace

bool SensorRecord::operator==(const SensorRecord& o) const { return SensorJson(*this) == SensorJson(o); }

bool TimingRecord::operator==(const TimingRecord& o) const { return TimingJson(*this) == TimingJson(o); }

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

// ---- rig JSON -----------------------------------------------------------------------------------

json Rigid3ToJson(const Rigid3& b_from_a) {
  const Eigen::Quaterniond& q = b_from_a.rotation;
  const Eigen::Vector3d& t = b_from_a.translation;
  return json{{"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}}, {"translation", {t.x(), t.y(), t.z()}}};
}

json RigToJson(const Rig& rig) {
  json cameras = json::array();
  for (const RigCamera& rc : rig.cameras) cameras.push_back(CameraJson(rc));
  return json{{"cameras", cameras}};
}

Rig RigFromJson(const json& rig_json, const std::string& file, const std::string& pointer) {
  std::vector<ValidationIssue> issues;
  JsonChecker check(file, &issues);
  Rig rig = ParseRig(check, rig_json, pointer);
  if (!issues.empty()) throw std::runtime_error(JoinIssues(issues));
  return rig;
}

Rig ReadRigJson(const std::string& path) {
  const json root = ReadJsonFile(path);
  // A dataset.json holds the rig under /rig; a rig.json is the rig object itself.
  const bool nested = root.is_object() && root.contains("rig");
  return RigFromJson(nested ? root["rig"] : root, path, nested ? "/rig" : "");
}

void WriteRigJson(const std::string& path, const Rig& rig, const std::string& source) {
  rig.Check(path);
  json root;
  root["schema_version"] = kRigSchemaVersion;
  root["source"] = source;
  root["cameras"] = RigToJson(rig)["cameras"];
  WriteJsonFileAtomic(path, root);
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
  EnsureWritableDir(dir);
  WriteJsonFileAtomic(DatasetJsonPath(dir), root);
}

// ---- exposure.csv -------------------------------------------------------------------------------

void WriteExposureCsv(const std::string& path, const std::vector<ExposureRow>& rows) {
  std::string text = std::string(kExposureHeader) + "\n";
  char buf[512];
  for (const ExposureRow& r : rows) {
    std::snprintf(buf, sizeof(buf), "%d,%s,%.17g,%.17g,%.17g,%.17g,%.17g\n", r.frame, r.camera.c_str(), r.exposure_ms,
                  r.gain, r.meter_luminance, r.dn_per_radiance, r.dark_dn);
    text += buf;
  }
  WriteFileAtomic(path, text);
}

std::vector<ExposureRow> ReadExposureCsv(const std::string& path, int frame_count, const Rig& rig) {
  std::vector<ValidationIssue> issues;
  std::vector<ExposureRow> rows = ParseExposureCsv(ReadFile(path), path, frame_count, rig, &issues);
  if (!issues.empty()) throw std::runtime_error(JoinIssues(issues));
  return rows;
}

// ---- validator ----------------------------------------------------------------------------------

// static_masks/<cam>.png of a dataset that declares them: present, one channel, the camera's size.
static void CheckStaticMasks(const std::string& dir, const DatasetInfo& info, std::vector<ValidationIssue>* issues) {
  for (const RigCamera& rc : info.rig.cameras) {
    const std::string path = StaticMaskPath(dir, rc.name);
    if (!fs::exists(path)) {
      issues->push_back(
          {path, "file", "missing static mask of camera " + rc.name + " (dataset.json has_static_masks)"});
    } else {
      CheckImage(path, "header", rc.camera.width, rc.camera.height, 1, issues);
    }
  }
}

// exposure.csv of a dataset whose dataset.json has /sensor: present, one row per frame and camera.
static void CheckExposureRecord(const std::string& dir, const DatasetInfo& info, std::vector<ValidationIssue>* issues) {
  const std::string path = ExposurePath(dir);
  if (!fs::exists(path)) {
    issues->push_back({path, "file", "missing exposure record of every frame and camera (dataset.json has /sensor)"});
    return;
  }
  try {
    ParseExposureCsv(ReadFile(path), path, info.frame_count, info.rig, issues);
  } catch (const std::exception& e) {
    issues->push_back({path, "file", e.what()});
  }
}

std::vector<ValidationIssue> ValidateDataset(const std::string& dir) {
  std::vector<ValidationIssue> issues;
  if (!fs::is_directory(dir)) {
    issues.push_back({dir, "/", "not a folder"});
    return issues;
  }
  const std::string json_path = DatasetJsonPath(dir);
  DatasetInfo info;
  bool json_ok = false;
  try {
    const json root = ReadJsonFile(json_path);
    JsonChecker check(json_path, &issues);
    info = ParseDatasetJson(check, root);
    json_ok = true;
  } catch (const std::exception& e) {
    const std::string message = StripPrefix(e.what(), json_path + ": ");
    issues.push_back({json_path, "/", message == e.what() ? "cannot read JSON: " + message : message});
  }

  // groundtruth.tum: every line parses, unit quaternions, increasing timestamps, one per frame.
  const std::string gt_path = GroundTruthPath(dir);
  int gt_lines = -1;
  if (json_ok && !info.has_ground_truth) {
    // A capture without ground truth: nothing to check (a file present is ignored).
  } else if (!fs::exists(gt_path)) {
    issues.push_back({gt_path, "file", "missing ground truth (world_from_rig per frame, TUM format)"});
  } else {
    try {
      std::vector<std::string> errors;
      const std::vector<TumLine> lines = ParseTumText(ReadFile(gt_path), gt_path, &errors);
      for (const std::string& e : errors) {
        // "<path>: line N: message" -> field "line N".
        const size_t a = e.find(": line ");
        const size_t b = a == std::string::npos ? std::string::npos : e.find(": ", a + 2);
        if (b == std::string::npos) {
          issues.push_back({gt_path, "line", e});
        } else {
          issues.push_back({gt_path, e.substr(a + 2, b - a - 2), e.substr(b + 2)});
        }
      }
      double previous_t = -std::numeric_limits<double>::infinity();
      for (const TumLine& line : lines) {
        const std::string field = "line " + std::to_string(line.line_number);
        const double qn = std::sqrt(line.values[4] * line.values[4] + line.values[5] * line.values[5] +
                                    line.values[6] * line.values[6] + line.values[7] * line.values[7]);
        if (!(std::abs(qn - 1.0) <= 1e-6)) {
          issues.push_back({gt_path, field,
                            "quaternion (qx qy qz qw) norm " + JsonChecker::Format(qn) + " is not 1 (tolerance 1e-6)"});
        }
        if (!(line.values[0] > previous_t)) {
          issues.push_back({gt_path, field,
                            "timestamp " + JsonChecker::Format(line.values[0]) + " is not after the previous one " +
                                JsonChecker::Format(previous_t)});
        }
        previous_t = line.values[0];
      }
      gt_lines = static_cast<int>(lines.size() + errors.size());
    } catch (const std::exception& e) {
      issues.push_back({gt_path, "file", e.what()});
    }
  }
  if (!json_ok) return issues;
  if (gt_lines >= 0 && info.frame_count > 0 && gt_lines != info.frame_count) {
    issues.push_back(
        {gt_path, "lines",
         std::to_string(gt_lines) + " poses but dataset.json /frame_count is " + std::to_string(info.frame_count)});
  }

  if (json_ok && info.has_static_masks) CheckStaticMasks(dir, info, &issues);
  if (json_ok && info.sensor) CheckExposureRecord(dir, info, &issues);

  // Images (and depth/masks when declared): present, readable, the rig camera's size; no extras.
  struct Layer {
    bool enabled;
    std::string folder_prefix;  // "" for images, "depth/" or "masks/"
    const char* extension;
    int max_channels;
    std::string (*path)(const std::string&, const std::string&, int);
  };
  const int image_channels = info.sensor && info.sensor->grayscale ? 1 : 4;  // a grayscale sensor: 1 channel
  const Layer layers[3] = {{true, "", "png", image_channels, &ImagePath},
                           {info.has_depth, "depth/", "exr", 1, &DepthPath},
                           {info.has_masks, "masks/", "png", 1, &MaskPath}};
  for (const Layer& layer : layers) {
    if (!layer.enabled) continue;
    for (const RigCamera& rc : info.rig.cameras) {
      if (rc.name.empty() || rc.camera.width <= 0 || rc.camera.height <= 0) continue;  // reported above
      const std::string folder = (fs::path(dir) / (layer.folder_prefix + rc.name)).string();
      if (!fs::is_directory(folder)) {
        issues.push_back({folder, "folder", "missing image folder of camera " + rc.name});
        continue;
      }
      const std::set<int> present = FrameFilesIn(folder, layer.extension, nullptr);
      int missing = 0;
      for (int frame = 0; frame < info.frame_count; ++frame) {
        const std::string path = layer.path(dir, rc.name, frame);
        if (!present.count(frame)) {
          // List the first few; summarise the rest so a missing folder does not flood the output.
          if (++missing <= 5) issues.push_back({path, "file", "missing (frame " + std::to_string(frame) + ")"});
          continue;
        }
        CheckImage(path, "header", rc.camera.width, rc.camera.height, layer.max_channels, &issues);
      }
      if (missing > 5) {
        issues.push_back({folder, "files", std::to_string(missing) + " frames missing in total"});
      }
      for (int frame : present) {
        if (info.frame_count > 0 && frame >= info.frame_count) {  // 0: /frame_count itself was bad
          issues.push_back({layer.path(dir, rc.name, frame), "file",
                            "frame " + std::to_string(frame) + " beyond dataset.json /frame_count " +
                                std::to_string(info.frame_count)});
        }
      }
    }
  }
  return issues;
}

}  // namespace rovo
