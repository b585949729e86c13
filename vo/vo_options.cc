#include "vo/vo_options.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rovo {

ExtrinsicsMode ExtrinsicsModeFromName(const std::string& name) {
  if (name == "gt") return ExtrinsicsMode::kGroundTruth;
  if (name == "noisy") return ExtrinsicsMode::kNoisy;
  if (name == "online") return ExtrinsicsMode::kOnline;
  throw std::invalid_argument("extrinsics mode: expected 'gt', 'noisy' or 'online', got '" + name + "'");
}

std::string ExtrinsicsModeName(ExtrinsicsMode mode) {
  switch (mode) {
    case ExtrinsicsMode::kGroundTruth:
      return "gt";
    case ExtrinsicsMode::kNoisy:
      return "noisy";
    case ExtrinsicsMode::kOnline:
      return "online";
  }
  return "gt";
}

void VoIoOptions::Check() const {
  if (dataset_dir.empty()) throw std::invalid_argument("vo: no dataset folder given");
  if (out_dir.empty()) throw std::invalid_argument("vo: no output (run) folder given");
  if (timed_from < 0) throw std::invalid_argument("vo: --timed-from must be >= 0");
}

std::vector<int> VoCameraIndices(const std::string& cameras, const Rig& rig) {
  std::vector<int> out;
  if (cameras == "auto" || cameras == "all") {
    for (int i = 0; i < rig.NumCameras(); ++i) {
      if (cameras == "all" || rig.cameras[static_cast<size_t>(i)].camera.max_fov_deg > 180.0) out.push_back(i);
    }
    if (out.empty()) {
      for (int i = 0; i < rig.NumCameras(); ++i) out.push_back(i);
    }
    return out;
  }
  std::stringstream list(cameras);
  for (std::string item; std::getline(list, item, ',');) {
    size_t used = 0;
    int index = -1;
    try {
      index = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size()) {
      throw std::invalid_argument("vo: --cameras " + cameras + ": `" + item +
                                  "` is not a camera index (auto, all or "
                                  "indices such as 0,1,2,3)");
    }
    if (index < 0 || index >= rig.NumCameras()) {
      throw std::invalid_argument("vo: --cameras " + cameras + ": camera " + item + " does not exist (the rig has " +
                                  std::to_string(rig.NumCameras()) + ")");
    }
    if (!out.empty() && index <= out.back()) {
      throw std::invalid_argument("vo: --cameras " + cameras + ": indices must increase");
    }
    out.push_back(index);
  }
  if (out.empty() || out.front() != 0) {
    throw std::invalid_argument("vo: --cameras " + cameras +
                                ": must include camera 0 (the gauge of the rig frame and of the extrinsics)");
  }
  return out;
}

void VoStartOptions::Check() const {
  if (mode != ExtrinsicsMode::kGroundTruth && draw_seed >= 0 && !(draw_sigma_deg >= 0.0)) {
    throw std::invalid_argument("vo: --draw-sigma must be non-negative (degrees), got " +
                                std::to_string(draw_sigma_deg));
  }
}

void VoStartupOptions::Check() const {
  if (!(anchor_deg >= 0.0) || !(anchor_mm >= 0.0)) {
    throw std::invalid_argument("vo: the OnlineExt anchor's sigmas must be >= 0 (--online-anchor " +
                                std::to_string(anchor_deg) + " deg, --online-anchor-mm " + std::to_string(anchor_mm) +
                                ")");
  }
}

void VoOptions::Check() const {
  io.Check();
  if (!(backend.ransac.tau_rad > 0.0)) {
    throw std::invalid_argument("vo: the RANSAC inlier threshold must be positive (--tau, degrees), got " +
                                std::to_string(backend.ransac.tau_rad * 180.0 / M_PI));
  }
  startup.Check();
}

namespace {

// Writes each recorded field under its json_key ("a.b": key b of object a).
struct JsonWriter {
  nlohmann::json* j;
  void Put(const OptionSpec& spec, nlohmann::json value) {
    if (spec.json_key == nullptr) return;
    const std::string key = spec.json_key;
    const size_t dot = key.find('.');
    if (dot == std::string::npos) {
      (*j)[key] = std::move(value);
    } else {
      (*j)[key.substr(0, dot)][key.substr(dot + 1)] = std::move(value);
    }
  }
  template <typename T>
  void operator()(const OptionSpec& spec, const T& value) {
    Put(spec, value);
  }
  void operator()(const OptionSpec&, const FrameRange&) {}  // recorded resolved by RunVo ("frames")
  template <typename E>
  void operator()(const OptionSpec& spec, const Named<E>& field) {
    for (const auto& [value, name] : field.names) {
      if (value == *field.value) Put(spec, name);
    }
  }
  void operator()(const OptionSpec& spec, const Named<bool>& field) { Put(spec, *field.value); }
  void operator()(const OptionSpec& spec, const DegreesOfRadians& field) { Put(spec, *field.radians * 180.0 / M_PI); }
  void operator()(const OptionSpec& spec, const InvertedFlag& field) { Put(spec, *field.value); }
};

// Collects the wanted values of the reuse fields.
struct ReuseCollector {
  std::vector<std::pair<OptionSpec, nlohmann::json>> fields;
  template <typename T>
  void operator()(const OptionSpec& spec, const T& value) {
    nlohmann::json record;
    JsonWriter{&record}(spec, value);
    if (spec.reuse != Reuse::kNo && spec.json_key != nullptr) fields.emplace_back(spec, record[spec.json_key]);
  }
};

}  // namespace

nlohmann::json VoOptionsJson(const VoOptions& options) {
  VoOptions copy = options;
  nlohmann::json j = nlohmann::json::object();
  JsonWriter writer{&j};
  ForEachVoOption(copy, writer);
  return j;
}

bool VoRunSettingsMatch(const nlohmann::json& info, const VoOptions& want, std::string* mismatch) {
  mismatch->clear();
  VoOptions wanted = want, defaults;
  ReuseCollector want_fields, default_fields;
  ForEachVoOption(wanted, want_fields);
  ForEachVoOption(defaults, default_fields);
  // Unconditional fields first, then those of drawn runs.
  for (const bool drawn_pass : {false, true}) {
    for (size_t k = 0; k < want_fields.fields.size(); ++k) {
      const auto& [spec, value] = want_fields.fields[k];
      if ((spec.reuse == Reuse::kYesWhenDrawn) != drawn_pass) continue;
      if (drawn_pass && want.start.draw_seed < 0) continue;
      const nlohmann::json missing =
          spec.reuse == Reuse::kYesMissingIsDefault ? default_fields.fields[k].second : nlohmann::json();
      const nlohmann::json recorded = info.value(spec.json_key, missing);
      if (recorded != value) {
        *mismatch = std::string(spec.json_key) + ": " + recorded.dump() + " vs " + value.dump();
        return false;
      }
    }
  }
  return true;
}

}  // namespace rovo
