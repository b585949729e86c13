#include "datasets/rig_json.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "datasets/camera_models.h"
#include "datasets/io.h"
#include "datasets/json_check.h"
#include "datasets/ocam.h"

namespace rovo {
using nlohmann::json;

namespace {

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

}  // namespace

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
  if (rig_json.contains("imu_from_rig")) {
    bool ok = false;
    const Rigid3 imu_from_rig = check.Transform(rig_json, pointer, "imu_from_rig", &ok);
    if (ok) rig.imu_from_rig = imu_from_rig;
  }
  return rig;
}

json Rigid3ToJson(const Rigid3& b_from_a) {
  const Eigen::Quaterniond& q = b_from_a.rotation;
  const Eigen::Vector3d& t = b_from_a.translation;
  return json{{"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}}, {"translation", {t.x(), t.y(), t.z()}}};
}

json RigToJson(const Rig& rig) {
  json cameras = json::array();
  for (const RigCamera& rc : rig.cameras) cameras.push_back(CameraJson(rc));
  json j{{"cameras", cameras}};
  if (rig.imu_from_rig) j["imu_from_rig"] = Rigid3ToJson(*rig.imu_from_rig);
  return j;
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
  const json rig_json = RigToJson(rig);
  root["cameras"] = rig_json["cameras"];
  if (rig_json.contains("imu_from_rig")) root["imu_from_rig"] = rig_json["imu_from_rig"];
  WriteJsonFileAtomic(path, root);
}

}  // namespace rovo
