#pragma once
// A dataset's description restricted to some of its cameras (exports of a camera subset, the VO's
// choice of cameras on rigs that mix lenses).

#include <string>
#include <vector>

#include "datasets/dataset.h"

namespace rovo {

// The description restricted to `cameras` (dataset indices, in that order): the rig's cameras keep
// their names (their image folders), the perturbed sets keep those cameras' extrinsics. Throws
// std::invalid_argument "<what>: ..." for an index out of range or given twice.
DatasetInfo SelectDatasetCameras(const DatasetInfo& info, const std::vector<int>& cameras, const std::string& what);

}  // namespace rovo
