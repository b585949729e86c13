#pragma once
// The seam between the ROVO front-end (paper IV-A, IV-B: hybrid projection, intra-view tracking,
// inter-view matching) and the back-end (IV-C, IV-D: pose estimation, mapping, local BA).
//
// Identity: a feature's `track_id` names a scene point, not a 2D track. KLT keeps the id from frame
// to frame within a view; an accepted inter-view match gives both features one id, so a point seen
// in two views at the same frame carries the same id in both, and a point that leaves one view and
// continues in the next keeps its id. The back-end keys landmarks by track_id.

#include "datasets/rig.h"

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <utility>
#include <vector>

namespace rovo {

struct Feature {
  uint64_t track_id = 0;
  int camera = 0;
  Eigen::Vector2f warped_px;        // in the camera's hybrid-projection image
  Eigen::Vector3d bearing_in_cam;   // unit, exact (from the warped pixel through the model)
  int age = 0;                      // frames this id has been tracked in this view
};

struct FrontendFrame {
  std::vector<std::vector<Feature>> features_per_camera;  // index = camera
  // (from, into): ids the front-end unified this frame because an inter-view match joined two
  // existing tracks; the back-end merges landmark `from` into `into`.
  std::vector<std::pair<uint64_t, uint64_t>> merged_ids;
  // Wall time per stage in milliseconds: warp, detect, track, match.
  double ms_warp = 0, ms_detect = 0, ms_track = 0, ms_match = 0;
};

}  // namespace rovo
