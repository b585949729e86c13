#pragma once
// Landmarks and keyframes of the back-end (ROVO paper, Sec. IV-B..IV-D).
//
// A landmark is keyed by the front-end's Feature::track_id (one scene point, possibly seen by several
// cameras at once). It collects bearing observations (frame, camera, bearing_in_cam) and, once
// triangulated, holds point_in_world. Points come from
//   - inter-view triangulation: >= 2 cameras see the id at the same frame; the rays start at the
//     camera centres of one rig pose, so the rig's metric baselines fix the scale;
//   - multi-frame triangulation: observations at several frames with estimated rig poses.
// Culling drops landmarks not seen for a number of frames and observations older than the local
// window; outlier points are removed by the pipeline.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

namespace rovo {

struct Observation {
  int frame = 0;
  int camera = 0;
  Eigen::Vector3d bearing_in_cam;  // unit
};

struct Landmark {
  uint64_t id = 0;
  bool has_point = false;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  std::vector<Observation> observations;  // in insertion (frame) order
  int first_seen_frame = 0;
  int last_seen_frame = 0;
  int triangulated_frame = -1;  // frame at which point_in_world was (re)computed
  int outlier_count = 0;        // consecutive frames rejected by the RANSAC

  // Number of distinct cameras among the observations.
  int NumCameras() const;
  // Number of distinct cameras observing at `frame`.
  int NumCamerasAtFrame(int frame) const;
};

// Landmarks in a std::map (ordered by id) so that every pass over them is deterministic.
class LandmarkMap {
 public:
  Landmark* Find(uint64_t id);
  const Landmark* Find(uint64_t id) const;
  // Adds an observation, creating the landmark on first sight.
  Landmark& AddObservation(uint64_t id, const Observation& observation);
  // Joins landmark `from` into `into` (front-end merged_ids): observations are combined; `into`
  // keeps its point, or takes `from`'s when it has none.
  void Merge(uint64_t from, uint64_t into);
  void Erase(uint64_t id) { landmarks_.erase(id); }
  void Clear() { landmarks_.clear(); }
  // Erases landmarks last seen before `min_last_seen_frame` and observations older than
  // `min_observation_frame`.
  void Cull(int min_last_seen_frame, int min_observation_frame);

  size_t size() const { return landmarks_.size(); }
  size_t NumWithPoint() const;
  std::map<uint64_t, Landmark>& landmarks() { return landmarks_; }
  const std::map<uint64_t, Landmark>& landmarks() const { return landmarks_; }

 private:
  std::map<uint64_t, Landmark> landmarks_;
};

// Keyframe policy: a frame becomes a keyframe when any of these holds since the last keyframe.
struct KeyframeOptions {
  int max_frame_gap = 5;              // frames
  double min_translation_m = 1.0;     // rig travel
  double min_rotation_deg = 10.0;     // rig rotation
  double min_tracked_fraction = 0.6;  // landmarks of the last keyframe still observed
  void Check() const;
};

struct KeyframeCandidate {
  int frames_since_keyframe = 0;
  double translation_m = 0.0;
  double rotation_deg = 0.0;
  double tracked_fraction = 1.0;
};

bool IsKeyframe(const KeyframeCandidate& candidate, const KeyframeOptions& options);

}  // namespace rovo
