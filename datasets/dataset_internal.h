#pragma once
// What dataset.cc shares with the validator: the checked parser of dataset.json; the IMU checks.

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "datasets/dataset.h"

namespace rovo {

class JsonChecker;

// dataset.json's fields, every problem recorded in `check`.
DatasetInfo ParseDatasetJson(JsonChecker& check, const nlohmann::json& root);

// The IMU streams of a dataset (imu/*.csv) against its /imu record and ground truth (imu_validate.cc).
void CheckImuStreams(const std::string& dir, const DatasetInfo& info, std::vector<ValidationIssue>* issues);

}  // namespace rovo
