#include "datasets/json_check.h"

#include <cmath>
#include <cstdio>

namespace rovo {
using nlohmann::json;

const json* JsonChecker::Member(const json& obj, const std::string& pointer, const std::string& key, bool optional) {
  if (!obj.is_object()) return nullptr;  // reported by the caller's type check
  const auto it = obj.find(key);
  if (it == obj.end()) {
    if (!optional) Issue(pointer + "/" + key, "missing field");
    return nullptr;
  }
  return &*it;
}

double JsonChecker::NumberValue(const json& j, const std::string& pointer, double fallback, double lo, double hi,
                                bool lo_open) {
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

int64_t JsonChecker::Integer(const json& obj, const std::string& pointer, const std::string& key, int64_t fallback,
                             int64_t lo, int64_t hi) {
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

uint64_t JsonChecker::Unsigned(const json& obj, const std::string& pointer, const std::string& key) {
  const json* j = Member(obj, pointer, key);
  if (!j) return 0;
  if (j->is_number_unsigned()) return j->get<uint64_t>();
  Issue(pointer + "/" + key, "expected a non-negative integer, found " +
                                 (j->is_number_integer() ? std::string("a negative integer") : TypeName(*j)));
  return 0;
}

std::string JsonChecker::String(const json& obj, const std::string& pointer, const std::string& key, bool non_empty) {
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

bool JsonChecker::Bool(const json& obj, const std::string& pointer, const std::string& key) {
  const json* j = Member(obj, pointer, key);
  if (!j) return false;
  if (!j->is_boolean()) {
    Issue(pointer + "/" + key, "expected true or false, found " + TypeName(*j));
    return false;
  }
  return j->get<bool>();
}

std::vector<double> JsonChecker::Numbers(const json& obj, const std::string& pointer, const std::string& key,
                                         int expected_size) {
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

Rigid3 JsonChecker::Transform(const json& obj, const std::string& pointer, const std::string& key, bool* ok) {
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

std::string JoinIssues(const std::vector<ValidationIssue>& issues) {
  std::string out;
  for (size_t i = 0; i < issues.size(); ++i) {
    if (i) out += "\n";
    out += issues[i].file + ": " + issues[i].field + ": " + issues[i].message;
  }
  return out;
}

}  // namespace rovo
