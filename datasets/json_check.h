#pragma once
// Checked reading of JSON documents: JsonChecker records every problem as (file, JSON pointer,
// message) instead of stopping at the first, so a validator can report them all.

#include <cstdint>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "datasets/dataset_validate.h"
#include "datasets/rigid3.h"

namespace rovo {

// The JSON type of `j` ("object", "array", "number", ...) for messages.
inline std::string TypeName(const nlohmann::json& j) { return j.type_name(); }

// Messages from helpers that already name the file or field: drop that prefix.
inline std::string StripPrefix(const std::string& message, const std::string& prefix) {
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
  const nlohmann::json* Member(const nlohmann::json& obj, const std::string& pointer, const std::string& key,
                               bool optional = false);

  bool Object(const nlohmann::json& j, const std::string& pointer) {
    if (j.is_object()) return true;
    Issue(pointer, "expected an object, found " + TypeName(j));
    return false;
  }

  // Finite number in [lo, hi] (open at the ends when lo_open / hi_open).
  double Number(const nlohmann::json& obj, const std::string& pointer, const std::string& key, double fallback,
                double lo, double hi, bool lo_open = false, bool optional = false) {
    const nlohmann::json* j = Member(obj, pointer, key, optional);
    if (!j) return fallback;
    return NumberValue(*j, pointer + "/" + key, fallback, lo, hi, lo_open);
  }

  double NumberValue(const nlohmann::json& j, const std::string& pointer, double fallback,
                     double lo = -std::numeric_limits<double>::infinity(),
                     double hi = std::numeric_limits<double>::infinity(), bool lo_open = false);

  int64_t Integer(const nlohmann::json& obj, const std::string& pointer, const std::string& key, int64_t fallback,
                  int64_t lo, int64_t hi);

  uint64_t Unsigned(const nlohmann::json& obj, const std::string& pointer, const std::string& key);

  std::string String(const nlohmann::json& obj, const std::string& pointer, const std::string& key, bool non_empty);

  bool Bool(const nlohmann::json& obj, const std::string& pointer, const std::string& key);

  // Array of finite numbers; size checked when expected_size >= 0.
  std::vector<double> Numbers(const nlohmann::json& obj, const std::string& pointer, const std::string& key,
                              int expected_size);

  // {"rotation_xyzw": [4], "translation": [3]}; the quaternion must be unit within 1e-6.
  Rigid3 Transform(const nlohmann::json& obj, const std::string& pointer, const std::string& key, bool* ok);

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

// The issues as one message, "<file>: <field>: <message>" per line.
std::string JoinIssues(const std::vector<ValidationIssue>& issues);

}  // namespace rovo
