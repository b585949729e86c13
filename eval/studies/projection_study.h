#pragma once
// `rovo study projection`: the paper's Table II (hybrid projection vs raw fisheye) on a dataset.
//
// (a) Descriptor stability along tracks: the same tracker (FAST + min distance, KLT with
//     forward-backward check, re-detection to the target count, ORB descriptors recomputed each
//     frame; tracking.h) runs on the raw fisheye images (with the lens' valid-pixel mask) and on the
//     hybrid-warped images, features_per_view per view (4 x 500 = the paper's 2000 features), over
//     `frames` frames (the paper: 100). For every track and every frame after its first, the
//     Hamming distance between its ORB descriptor at that frame and at its FIRST frame is
//     accumulated; the table reports the mean (appearance drift along the track, which the lens
//     distortion drives). The frame-to-frame mean (t vs t+1) is reported as a second row.
// (b) Inter-view matching inlier ratio between neighbouring views (a, b), on the features of each
//     arm's tracker that lie in the pair's overlap: bearings that fall inside BOTH cameras' hybrid
//     images (the same scene area for both arms). Matches are mutual nearest neighbours of the ORB
//     descriptors (brute force, cross-checked), kept when epipolar-consistent (angle to the
//     epipolar plane <= epipolar_deg under the ground-truth extrinsics), as in the paper. A match
//     is an inlier by GROUND TRUTH (GroundTruthMatchVerdict below). Rows: all mutual-NN matches
//     (descriptors only), those that are epipolar-consistent (the paper's row), and the front-end's
//     filter chain (interview_matching.h, same settings, the arm's own images for the appearance
//     filters) on the same overlap features of both arms; the front-end's own matches last.
// Outputs in --out: table.md (with a histogram of the ground-truth reprojection distances),
// study.json (numbers, dataset seed, settings), matches_fisheye.png, matches_hybrid.png (the NN
// matches of part (b)) and matches_frontend.png (the front-end's accepted matches), each one
// neighbour pair of the last frame (green = inlier, red = outlier).

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "datasets/rig.h"
#include "vo/frontend.h"
#include "vo/interview_matching.h"

namespace rovo {

// Depth image (EXR, channel 0 = ray length in metres, 0 = none) as CV_32F; throws naming the file.
cv::Mat ReadDepthImage(const std::string& path);

// Ground-truth verdict of an inter-view match: feature A (unit bearing in camera A and its fisheye
// pixel) and feature B (fisheye pixel), with both cameras' depth images (ray length). For each of
// the 3x3 depth pixels around A's pixel (a corner on an occlusion edge belongs to either side
// within a pixel): X = c_A + depth * d_A is projected into B; the candidate passes when the pixel
// is within inlier_px (fisheye pixels) of B's feature and not occluded in B (some depth of B's
// 3x3 neighbourhood of the projection agrees with |X - c_B| within 3% + 0.05 m).
// Returns 1 = inlier (some candidate passes), 0 = outlier, -1 = A has no depth at its centre pixel
// (sky; not counted). `error_px`, when given, receives the smallest reprojection distance of the
// candidates (infinity when none projects).
int GroundTruthMatchVerdict(const Rig& rig, int camera_a, const Eigen::Vector3d& bearing_a_in_cam,
                            const Eigen::Vector2d& fisheye_a, int camera_b, const Eigen::Vector2d& fisheye_b,
                            const cv::Mat& depth_a, const cv::Mat& depth_b, double inlier_px,
                            double* error_px = nullptr);

// GroundTruthMatchVerdict of one of the front-end's accepted inter-view matches (from
// Frontend::last_matches), its warped pixels mapped to the bearing and fisheye pixels; `depths`
// holds one depth image per camera. Returns -2 when a warped pixel has no bearing or fisheye pixel.
int FrontendMatchVerdict(const Frontend& frontend, const Rig& rig, const Frontend::ViewMatch& match,
                         const std::vector<cv::Mat>& depths, double inlier_px, double* error_px = nullptr);

struct ProjectionStudyOptions {
  std::string dataset_dir;
  std::string out_dir;
  int frames = 100;                         // frames used from the start (fewer if the dataset is shorter)
  int features_per_view = 500;              // tracker target per view (4 views: the paper's 2000 features)
  double epipolar_deg = 1.0;                // epipolar consistency for part (b)
  double inlier_px = 2.0;                   // ground-truth reprojection tolerance, fisheye pixels
  InterviewMatchOptions frontend_matching;  // filters of the front-end column (defaults = the front-end's)
  // TrackerOptions::upright_descriptors for both arms and the front-end column (default: the front-end's).
  bool upright_descriptors = FrontendOptions{}.upright_descriptors;
  bool quiet = false;
};

struct ProjectionStudyResult {
  int frames = 0;
  double hamming_fisheye = 0, hamming_hybrid = 0;               // mean Hamming distance, first frame vs later
  int64_t tracked_pairs_fisheye = 0, tracked_pairs_hybrid = 0;  // (track, later frame) pairs
  double hamming_step_fisheye = 0, hamming_step_hybrid = 0;     // mean Hamming distance, t vs t+1
  double mean_age_fisheye = 0, mean_age_hybrid = 0;             // mean frames since the first, over the pairs
  int64_t features_fisheye = 0, features_hybrid = 0;            // distinct tracks that contributed
  int64_t raw_matches_fisheye = 0, raw_inliers_fisheye = 0;     // (b), all mutual-NN matches (descriptors only)
  int64_t raw_matches_hybrid = 0, raw_inliers_hybrid = 0;
  int64_t chain_matches_fisheye = 0, chain_inliers_fisheye = 0;  // (b), the front-end's filter chain
  int64_t chain_matches_hybrid = 0, chain_inliers_hybrid = 0;
  int64_t matches_fisheye = 0, inliers_fisheye = 0;  // (b), epipolar-consistent matches
  int64_t matches_hybrid = 0, inliers_hybrid = 0;
  int64_t matches_frontend = 0, inliers_frontend = 0;  // front-end's full filters (hybrid)
  double RawInlierRatioFisheye() const {
    return raw_matches_fisheye ? double(raw_inliers_fisheye) / raw_matches_fisheye : 0.0;
  }
  double RawInlierRatioHybrid() const {
    return raw_matches_hybrid ? double(raw_inliers_hybrid) / raw_matches_hybrid : 0.0;
  }
  double ChainInlierRatioFisheye() const {
    return chain_matches_fisheye ? double(chain_inliers_fisheye) / chain_matches_fisheye : 0.0;
  }
  double ChainInlierRatioHybrid() const {
    return chain_matches_hybrid ? double(chain_inliers_hybrid) / chain_matches_hybrid : 0.0;
  }
  double InlierRatioFisheye() const { return matches_fisheye ? double(inliers_fisheye) / matches_fisheye : 0.0; }
  double InlierRatioHybrid() const { return matches_hybrid ? double(inliers_hybrid) / matches_hybrid : 0.0; }
  double InlierRatioFrontend() const { return matches_frontend ? double(inliers_frontend) / matches_frontend : 0.0; }
};

// Runs the study and writes the outputs. Throws std::runtime_error naming the file on unreadable
// input (missing image, dataset without depth).
ProjectionStudyResult RunProjectionStudy(const ProjectionStudyOptions& options);

}  // namespace rovo
