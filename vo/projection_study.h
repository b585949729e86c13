#pragma once
// `rovo study projection`: the paper's Table II (hybrid projection vs raw fisheye) on a dataset.
//
// (a) Descriptor stability: the same tracker (FAST + min distance, KLT with forward-backward check,
//     ORB descriptors recomputed each frame; tracking.h) runs on the raw fisheye images (with the
//     lens' valid-pixel mask) and on the hybrid-warped images. For every track alive at frames t
//     and t+1 in one view, the Hamming distance between its two ORB descriptors is accumulated;
//     the table reports the mean.
// (b) Inter-view matching inlier ratio between neighbouring views: mutual nearest-neighbour ORB
//     matching of all features of the two views, kept when epipolar-consistent (angle to the
//     epipolar plane <= epipolar_deg under the ground-truth extrinsics), as in the paper. A match is
//     an inlier by GROUND TRUTH: feature A is back-projected with the dataset's depth (ray length,
//     depth/camN/NNNNNN.exr) into the rig frame, projected into camera B; inlier when that pixel is
//     within inlier_px (fisheye pixels) of B's feature and B's depth there agrees with the distance
//     (not occluded: |depth_B - |X - c_B|| <= 3% + 0.05 m over the 3x3 neighbourhood). Matches
//     whose A pixel has no depth (sky) are not counted. The front-end's full filter chain
//     (interview_matching.h) on the hybrid images is reported as a third column.
// Outputs in --out: table.md, study.json (numbers, dataset seed, settings), matches_hybrid.png and
// matches_fisheye.png (one neighbour pair of the last frame; green = inlier, red = outlier).

#include "datasets/rig.h"

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

namespace rovo {

struct CliGroups;

// Depth image (EXR, channel 0 = ray length in metres, 0 = none) as CV_32F; throws naming the file.
cv::Mat ReadDepthImage(const std::string& path);

// Ground-truth verdict of an inter-view match: feature A (unit bearing in camera A and its fisheye
// pixel) and feature B (fisheye pixel), with both cameras' depth images. 1 = inlier (A's depth
// point reprojects within inlier_px of B and is not occluded in B), 0 = outlier, -1 = A has no
// depth (not counted).
int GroundTruthMatchVerdict(const Rig& rig, int camera_a, const Eigen::Vector3d& bearing_a_in_cam,
                            const Eigen::Vector2d& fisheye_a, int camera_b, const Eigen::Vector2d& fisheye_b,
                            const cv::Mat& depth_a, const cv::Mat& depth_b, double inlier_px);

struct ProjectionStudyOptions {
  std::string dataset_dir;
  std::string out_dir;
  int frames = 100;             // frames used from the start (fewer if the dataset is shorter)
  int features_per_view = 600;  // tracker target per view (4 views: 2400 features)
  double epipolar_deg = 1.0;    // epipolar consistency for part (b)
  double inlier_px = 2.0;       // ground-truth reprojection tolerance, fisheye pixels
  bool quiet = false;
};

struct ProjectionStudyResult {
  int frames = 0;
  double hamming_fisheye = 0, hamming_hybrid = 0;  // mean Hamming distance, frame t vs t+1
  int64_t tracked_pairs_fisheye = 0, tracked_pairs_hybrid = 0;
  int64_t features_fisheye = 0, features_hybrid = 0;  // distinct tracks that contributed
  int64_t matches_fisheye = 0, inliers_fisheye = 0;   // (b), epipolar-consistent matches
  int64_t matches_hybrid = 0, inliers_hybrid = 0;
  int64_t matches_frontend = 0, inliers_frontend = 0; // front-end's full filters (hybrid)
  double InlierRatioFisheye() const { return matches_fisheye ? double(inliers_fisheye) / matches_fisheye : 0.0; }
  double InlierRatioHybrid() const { return matches_hybrid ? double(inliers_hybrid) / matches_hybrid : 0.0; }
  double InlierRatioFrontend() const { return matches_frontend ? double(inliers_frontend) / matches_frontend : 0.0; }
};

// Runs the study and writes the outputs. Throws std::runtime_error naming the file on unreadable
// input (missing image, dataset without depth).
ProjectionStudyResult RunProjectionStudy(const ProjectionStudyOptions& options);

// Adds `rovo study projection DATASET --out DIR [--frames N]` (called from vo/cli.cc).
void AddProjectionStudyCommand(CliGroups& groups);

}  // namespace rovo
