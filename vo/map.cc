#include "vo/map.h"

#include <algorithm>
#include <stdexcept>

namespace rovo {

int Landmark::NumCameras() const {
  unsigned mask = 0;
  int count = 0;
  for (const Observation& o : observations) {
    const unsigned bit = 1u << (o.camera & 31);
    if (!(mask & bit)) {
      mask |= bit;
      ++count;
    }
  }
  return count;
}

int Landmark::NumCamerasAtFrame(int frame) const {
  unsigned mask = 0;
  int count = 0;
  for (const Observation& o : observations) {
    if (o.frame != frame) continue;
    const unsigned bit = 1u << (o.camera & 31);
    if (!(mask & bit)) {
      mask |= bit;
      ++count;
    }
  }
  return count;
}

Landmark* LandmarkMap::Find(uint64_t id) {
  auto it = landmarks_.find(id);
  return it == landmarks_.end() ? nullptr : &it->second;
}

const Landmark* LandmarkMap::Find(uint64_t id) const {
  auto it = landmarks_.find(id);
  return it == landmarks_.end() ? nullptr : &it->second;
}

Landmark& LandmarkMap::AddObservation(uint64_t id, const Observation& observation) {
  auto [it, inserted] = landmarks_.try_emplace(id);
  Landmark& lm = it->second;
  if (inserted) {
    lm.id = id;
    lm.first_seen_frame = observation.frame;
  }
  // One observation per (frame, camera): a repeated one replaces the old.
  for (Observation& o : lm.observations) {
    if (o.frame == observation.frame && o.camera == observation.camera) {
      o = observation;
      return lm;
    }
  }
  lm.observations.push_back(observation);
  lm.last_seen_frame = std::max(lm.last_seen_frame, observation.frame);
  return lm;
}

void LandmarkMap::Merge(uint64_t from, uint64_t into) {
  if (from == into) return;
  auto it_from = landmarks_.find(from);
  if (it_from == landmarks_.end()) return;
  Landmark source = std::move(it_from->second);
  landmarks_.erase(it_from);
  auto [it, inserted] = landmarks_.try_emplace(into);
  Landmark& target = it->second;
  if (inserted) {
    target = source;
    target.id = into;
    return;
  }
  for (const Observation& o : source.observations) AddObservation(into, o);
  std::stable_sort(target.observations.begin(), target.observations.end(),
                   [](const Observation& a, const Observation& b) { return a.frame < b.frame; });
  if (!target.has_point && source.has_point) {
    target.has_point = true;
    target.point_in_world = source.point_in_world;
    target.triangulated_frame = source.triangulated_frame;
  }
  target.first_seen_frame = std::min(target.first_seen_frame, source.first_seen_frame);
}

void LandmarkMap::Cull(int min_last_seen_frame, int min_observation_frame) {
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    if (it->second.last_seen_frame < min_last_seen_frame) {
      it = landmarks_.erase(it);
      continue;
    }
    auto& obs = it->second.observations;
    obs.erase(
        std::remove_if(obs.begin(), obs.end(), [&](const Observation& o) { return o.frame < min_observation_frame; }),
        obs.end());
    ++it;
  }
}

size_t LandmarkMap::NumWithPoint() const {
  size_t n = 0;
  for (const auto& [id, lm] : landmarks_) n += lm.has_point ? 1 : 0;
  return n;
}

void KeyframeOptions::Check() const {
  if (max_frame_gap < 1) throw std::invalid_argument("KeyframeOptions.max_frame_gap must be >= 1");
  if (!(min_tracked_fraction >= 0.0 && min_tracked_fraction <= 1.0)) {
    throw std::invalid_argument("KeyframeOptions.min_tracked_fraction must be in [0, 1]");
  }
}

bool IsKeyframe(const KeyframeCandidate& candidate, const KeyframeOptions& options) {
  return candidate.frames_since_keyframe >= options.max_frame_gap ||
         candidate.translation_m >= options.min_translation_m || candidate.rotation_deg >= options.min_rotation_deg ||
         candidate.tracked_fraction < options.min_tracked_fraction;
}

}  // namespace rovo
