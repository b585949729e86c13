#pragma once
// What dataset.cc shares with the validator: the checked parser of dataset.json.

#include <nlohmann/json_fwd.hpp>

#include "datasets/dataset.h"

namespace rovo {

class JsonChecker;

// dataset.json's fields, every problem recorded in `check`.
DatasetInfo ParseDatasetJson(JsonChecker& check, const nlohmann::json& root);

}  // namespace rovo
