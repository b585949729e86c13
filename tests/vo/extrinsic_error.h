#pragma once
// Test helpers for tests that link vo only (eval's ExtrinsicErrorDeg, ExtrinsicTranslationErrorM):
// the largest, over cameras i >= 1, of the rotation angle between est(cam_i_from_cam0) and
// truth(cam_i_from_cam0) in degrees, and of the distance between their translations in metres.
#include <algorithm>
#include <vector>

#include "datasets/rigid3.h"

namespace rovo {

inline double RelativeExtrinsicErrorDeg(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth) {
  double worst = 0.0;
  for (size_t i = 1; i < est.size(); ++i) {
    worst = std::max(worst, RotationDistanceDeg(est[i].rotation * est[0].rotation.inverse(),
                                                truth[i].rotation * truth[0].rotation.inverse()));
  }
  return worst;
}

inline double RelativeExtrinsicTranslationErrorM(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth) {
  double worst = 0.0;
  for (size_t i = 1; i < est.size(); ++i) {
    const Eigen::Vector3d e = (est[i] * est[0].Inverse()).translation;
    const Eigen::Vector3d t = (truth[i] * truth[0].Inverse()).translation;
    worst = std::max(worst, (e - t).norm());
  }
  return worst;
}

}  // namespace rovo
