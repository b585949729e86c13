#pragma once
// Rig JSON (datasets/FORMAT.md), the same camera objects as dataset.json's /rig:
//   {"cameras": [{"name", "model", "width", "height", "params", "max_fov_deg",
//                 "cam_from_rig": {"rotation_xyzw": [x, y, z, w], "translation": [x, y, z]}}],
//    "imu_from_rig": {...}}   (optional: the rig's IMU mount, the same transform object)
// A rig.json file adds "schema_version" and "source" at the top level.

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "datasets/rig.h"

namespace rovo {

class JsonChecker;

inline constexpr int kRigSchemaVersion = 1;
nlohmann::json Rigid3ToJson(const Rigid3& b_from_a);
nlohmann::json RigToJson(const Rig& rig);
// Parses and checks a rig object; throws std::runtime_error "<file>: <json pointer>: <problem>".
Rig RigFromJson(const nlohmann::json& json, const std::string& file, const std::string& pointer = "");
// Reads a rig.json, or the /rig of a dataset.json. Throws naming the file and field.
Rig ReadRigJson(const std::string& path);
// Atomic write; `source` records where the rig came from (e.g. "preset rovo4").
void WriteRigJson(const std::string& path, const Rig& rig, const std::string& source);

// Parses the rig object at `pointer` (dataset.json's /rig, or a rig.json), recording every
// problem in `check` (the validator's entry; RigFromJson throws instead).
Rig ParseRig(JsonChecker& check, const nlohmann::json& rig_json, const std::string& pointer);

}  // namespace rovo
