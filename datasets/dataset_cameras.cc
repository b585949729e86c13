// A dataset's description restricted to some of its cameras (dataset_cameras.h).
#include "datasets/dataset_cameras.h"

#include <stdexcept>

namespace rovo {

DatasetInfo SelectDatasetCameras(const DatasetInfo& info, const std::vector<int>& cameras, const std::string& what) {
  DatasetInfo out = info;
  out.rig.cameras.clear();
  for (PerturbedExtrinsics& set : out.perturbed) set.cam_from_rig.clear();
  std::vector<bool> seen(info.rig.cameras.size(), false);
  for (int k : cameras) {
    if (k < 0 || k >= info.rig.NumCameras()) {
      throw std::invalid_argument(what + ": camera " + std::to_string(k) + " does not exist (the rig has " +
                                  std::to_string(info.rig.NumCameras()) + " cameras, 0.." +
                                  std::to_string(info.rig.NumCameras() - 1) + ")");
    }
    if (seen[static_cast<size_t>(k)])
      throw std::invalid_argument(what + ": camera " + std::to_string(k) + " given twice");
    seen[static_cast<size_t>(k)] = true;
    out.rig.cameras.push_back(info.rig.cameras[static_cast<size_t>(k)]);
    for (size_t s = 0; s < info.perturbed.size(); ++s) {
      if (static_cast<size_t>(k) < info.perturbed[s].cam_from_rig.size()) {
        out.perturbed[s].cam_from_rig.push_back(info.perturbed[s].cam_from_rig[static_cast<size_t>(k)]);
      }
    }
  }
  return out;
}

}  // namespace rovo
