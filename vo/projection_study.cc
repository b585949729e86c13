#include "vo/projection_study.h"

#include "datasets/cli_groups.h"
#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "rovo/version.h"
#include "vo/frontend.h"
#include "vo/hybrid_projection.h"
#include "vo/interview_matching.h"
#include "vo/tracking.h"

#include <CLI/CLI.hpp>
#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace rovo {
namespace {

cv::Mat ReadGray(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error(path + ": cannot read image");
  return image;
}

}  // namespace

cv::Mat ReadDepthImage(const std::string& path) {
  auto input = OIIO::ImageInput::open(path);
  if (!input) throw std::runtime_error(path + ": cannot read depth: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = input->spec();
  std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    throw std::runtime_error(path + ": cannot read depth pixels: " + input->geterror());
  }
  cv::Mat depth(spec.height, spec.width, CV_32F);
  for (int v = 0; v < spec.height; ++v) {
    for (int u = 0; u < spec.width; ++u) {
      depth.at<float>(v, u) = pixels[(static_cast<size_t>(v) * spec.width + u) * spec.nchannels];
    }
  }
  return depth;
}

namespace {

float DepthAt(const cv::Mat& depth, const Eigen::Vector2d& px) {
  const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
  if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) return 0.0f;
  return depth.at<float>(v, u);
}

}  // namespace

int GroundTruthMatchVerdict(const Rig& rig, int camera_a, const Eigen::Vector3d& bearing_a, const Eigen::Vector2d& fisheye_a,
                            int camera_b, const Eigen::Vector2d& fisheye_b, const cv::Mat& depth_a, const cv::Mat& depth_b,
                            double inlier_px) {
  const float range = DepthAt(depth_a, fisheye_a);
  if (!(range > 0.0f) || !std::isfinite(range)) return -1;
  const Rigid3& a_from_rig = rig.cameras[camera_a].cam_from_rig;
  const Rigid3& b_from_rig = rig.cameras[camera_b].cam_from_rig;
  const Eigen::Vector3d point_in_rig = a_from_rig.Inverse() * (static_cast<double>(range) * bearing_a);
  const Eigen::Vector3d point_in_b = b_from_rig * point_in_rig;
  const auto predicted = rig.cameras[camera_b].camera.Project(point_in_b);
  if (!predicted || (*predicted - fisheye_b).norm() > inlier_px) return 0;
  const double expected = point_in_b.norm();
  const int u0 = static_cast<int>(std::lround(predicted->x())), v0 = static_cast<int>(std::lround(predicted->y()));
  for (int v = v0 - 1; v <= v0 + 1; ++v) {
    for (int u = u0 - 1; u <= u0 + 1; ++u) {
      if (u < 0 || v < 0 || u >= depth_b.cols || v >= depth_b.rows) continue;
      const double d = depth_b.at<float>(v, u);
      if (d > 0 && std::abs(d - expected) <= 0.03 * expected + 0.05) return 1;
    }
  }
  return 0;
}

namespace {

struct DrawnMatch {
  cv::Point2f a, b;
  bool inlier;
};

void WriteMatchesPng(const std::string& path, const cv::Mat& image_a, const cv::Mat& image_b,
                     const std::vector<DrawnMatch>& matches, const std::string& caption) {
  const int height = std::max(image_a.rows, image_b.rows);
  cv::Mat canvas(height + 30, image_a.cols + image_b.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::Mat left = canvas(cv::Rect(0, 30, image_a.cols, image_a.rows));
  cv::Mat right = canvas(cv::Rect(image_a.cols, 30, image_b.cols, image_b.rows));
  cv::cvtColor(image_a, left, cv::COLOR_GRAY2BGR);
  cv::cvtColor(image_b, right, cv::COLOR_GRAY2BGR);
  const cv::Point2f offset_a(0, 30), offset_b(static_cast<float>(image_a.cols), 30);
  for (const DrawnMatch& m : matches) {
    const cv::Scalar colour = m.inlier ? cv::Scalar(0, 220, 0) : cv::Scalar(0, 0, 255);
    cv::line(canvas, m.a + offset_a, m.b + offset_b, colour, 1, cv::LINE_AA);
    cv::circle(canvas, m.a + offset_a, 3, colour, 1, cv::LINE_AA);
    cv::circle(canvas, m.b + offset_b, 3, colour, 1, cv::LINE_AA);
  }
  cv::putText(canvas, caption, cv::Point(8, 21), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  std::vector<uchar> png;
  if (!cv::imencode(".png", canvas, png)) throw std::runtime_error(path + ": PNG encoding failed");
  WriteFileAtomic(path, std::string(png.begin(), png.end()));
}

// One image representation (raw fisheye or hybrid) of the study.
struct Arm {
  std::vector<ViewTracker> trackers;
  std::vector<std::map<uint64_t, cv::Mat>> previous_descriptors;  // per camera: id -> descriptor at t-1
  std::vector<std::set<uint64_t>> contributing;                    // per camera: ids that contributed
  double hamming_sum = 0;
  int64_t hamming_pairs = 0;
  int64_t matches = 0, inliers = 0;
  std::vector<DrawnMatch> drawn;  // last frame, first pair
};

}  // namespace

ProjectionStudyResult RunProjectionStudy(const ProjectionStudyOptions& options) {
  const DatasetInfo info = ReadDatasetInfo(options.dataset_dir);
  if (!info.has_depth) {
    throw std::runtime_error(DatasetJsonPath(options.dataset_dir) +
                             ": has_depth is false; the study needs depth (render with --depth)");
  }
  const Rig& rig = info.rig;
  const int n = rig.NumCameras();
  const int frames = std::min(options.frames, info.frame_count);
  if (frames < 2) throw std::runtime_error(DatasetJsonPath(options.dataset_dir) + ": frame_count < 2");
  EnsureWritableDir(options.out_dir);

  FrontendOptions frontend_options;
  frontend_options.target_features_per_view = options.features_per_view;
  Frontend frontend(rig, frontend_options);
  const std::vector<HybridLayout> layouts = ComputeHybridLayouts(rig);
  std::vector<std::pair<int, int>> pairs;
  {
    std::set<std::pair<int, int>> seen;
    for (int i = 0; i < n; ++i) {
      const int j = layouts[i].right_neighbour;
      if (j != i && seen.insert({std::min(i, j), std::max(i, j)}).second) pairs.emplace_back(i, j);
    }
  }

  TrackerOptions tracker_options;
  tracker_options.target_features = options.features_per_view;
  tracker_options.min_feature_distance_px = frontend_options.min_feature_distance_px;
  tracker_options.fast_threshold = frontend_options.fast_threshold;
  tracker_options.max_forward_backward_px = frontend_options.max_forward_backward_px;
  Arm fisheye_arm, hybrid_arm;
  for (Arm* arm : {&fisheye_arm, &hybrid_arm}) {
    arm->trackers.assign(n, ViewTracker(tracker_options));
    arm->previous_descriptors.resize(n);
    arm->contributing.resize(n);
  }
  std::vector<cv::Mat> fisheye_masks(n);
  for (int i = 0; i < n; ++i) {
    const Camera& camera = rig.cameras[i].camera;
    const std::vector<unsigned char> mask = camera.ValidPixelMask();
    fisheye_masks[i] = cv::Mat(camera.height, camera.width, CV_8UC1, const_cast<unsigned char*>(mask.data())).clone();
  }

  // Part (b) matcher: mutual nearest descriptors over all features; epipolar check applied after.
  InterviewMatchOptions nn_options;
  nn_options.use_y_distance = false;
  nn_options.use_zncc = false;
  nn_options.use_positive_disparity = false;
  nn_options.max_orientation_diff_deg = 180.0;
  nn_options.max_descriptor_distance = 256;
  nn_options.max_epipolar_angle_deg = 180.0;
  nn_options.max_ratio = 1.0;

  ProjectionStudyResult result;
  result.frames = frames;
  std::vector<DrawnMatch> drawn_frontend;
  cv::Mat last_fisheye_a, last_fisheye_b;
  uint64_t next_id = 0;
  const auto id_source = [&next_id] { return ++next_id; };
  Progress progress("projection study", frames, "frames", options.quiet);
  for (int t = 0; t < frames; ++t) {
    std::vector<cv::Mat> images(n), depths(n);
    tbb::parallel_for(0, n, [&](int i) {
      images[i] = ReadGray(ImagePath(options.dataset_dir, rig.cameras[i].name, t));
      depths[i] = ReadDepthImage(DepthPath(options.dataset_dir, rig.cameras[i].name, t));
    });
    frontend.Process(images);

    // Trackers of both arms (ids drawn sequentially afterwards would need care; one source per arm
    // under a lock-free sequential loop keeps it simple and deterministic).
    std::vector<cv::Mat> warped(n);
    tbb::parallel_for(0, n, [&](int i) {
      warped[i] = frontend.warped_image(i);
      fisheye_arm.trackers[i].Track(images[i], fisheye_masks[i]);
      hybrid_arm.trackers[i].Track(warped[i], frontend.projection(i).valid_mask());
    });
    for (Arm* arm : {&fisheye_arm, &hybrid_arm}) {
      for (int i = 0; i < n; ++i) arm->trackers[i].DetectAndDescribe(id_source);
    }

    // (a) descriptor distance of each track between t-1 and t.
    for (Arm* arm : {&fisheye_arm, &hybrid_arm}) {
      for (int i = 0; i < n; ++i) {
        std::map<uint64_t, cv::Mat> current;
        for (const TrackedPoint& p : arm->trackers[i].points()) {
          if (!p.has_descriptor) continue;
          const auto it = arm->previous_descriptors[i].find(p.track_id);
          if (it != arm->previous_descriptors[i].end()) {
            arm->hamming_sum += HammingDistance(it->second, p.descriptor);
            ++arm->hamming_pairs;
            arm->contributing[i].insert(p.track_id);
          }
          current[p.track_id] = p.descriptor.clone();
        }
        arm->previous_descriptors[i] = std::move(current);
      }
    }

    // (b) inter-view matching, verified with depth.
    const bool last = t + 1 == frames;
    for (Arm* arm : {&fisheye_arm, &hybrid_arm}) {
      const bool hybrid = arm == &hybrid_arm;
      std::vector<MatchView> views(n);
      for (int i = 0; i < n; ++i) {
        const Eigen::Matrix3d rig_from_cam = rig.cameras[i].cam_from_rig.RotationMatrix().transpose();
        views[i].points = &arm->trackers[i].points();
        views[i].centre_in_rig = rig.cameras[i].cam_from_rig.Inverse().translation;
        views[i].image = hybrid ? &warped[i] : &images[i];
        for (const TrackedPoint& p : arm->trackers[i].points()) {
          const Eigen::Vector2d px(p.px.x, p.px.y);
          const auto bearing =
              hybrid ? frontend.projection(i).BearingFromWarped(px) : rig.cameras[i].camera.Unproject(px);
          views[i].bearings_in_rig.push_back(bearing ? Eigen::Vector3d(rig_from_cam * *bearing) : Eigen::Vector3d::Zero());
        }
      }
      if (last) arm->drawn.clear();
      for (size_t k = 0; k < pairs.size(); ++k) {
        const auto [a, b] = pairs[k];
        const std::vector<InterviewMatch> matches = MatchViews(PairGeometry{}, views[a], views[b], nn_options);
        for (const InterviewMatch& m : matches) {
          const Eigen::Vector3d& da = views[a].bearings_in_rig[m.index_a];
          const Eigen::Vector3d& db = views[b].bearings_in_rig[m.index_b];
          if (da.isZero() || db.isZero()) continue;
          if (EpipolarAngle(views[a].centre_in_rig, da, views[b].centre_in_rig, db) > options.epipolar_deg * M_PI / 180) {
            continue;
          }
          const cv::Point2f pa = (*views[a].points)[m.index_a].px, pb = (*views[b].points)[m.index_b].px;
          std::optional<Eigen::Vector2d> fa(Eigen::Vector2d(pa.x, pa.y)), fb(Eigen::Vector2d(pb.x, pb.y));
          if (hybrid) {
            fa = frontend.projection(a).FisheyeFromWarped(*fa);
            fb = frontend.projection(b).FisheyeFromWarped(*fb);
            if (!fa || !fb) continue;
          }
          const Eigen::Vector3d bearing_a = rig.cameras[a].cam_from_rig.RotationMatrix() * da;
          const int verdict = GroundTruthMatchVerdict(rig, a, bearing_a, *fa, b, *fb, depths[a], depths[b], options.inlier_px);
          if (verdict < 0) continue;
          ++arm->matches;
          arm->inliers += verdict;
          if (last && k == 0) arm->drawn.push_back({pa, pb, verdict == 1});
        }
      }
    }

    // The front-end's own accepted matches (all filters), same verification.
    if (last) drawn_frontend.clear();
    for (const Frontend::ViewMatch& m : frontend.last_matches()) {
      const cv::Point2f pa = frontend.tracker(m.camera_a).points()[m.index_a].px;
      const cv::Point2f pb = frontend.tracker(m.camera_b).points()[m.index_b].px;
      const auto bearing_a = frontend.projection(m.camera_a).BearingFromWarped(Eigen::Vector2d(pa.x, pa.y));
      const auto fa = frontend.projection(m.camera_a).FisheyeFromWarped(Eigen::Vector2d(pa.x, pa.y));
      const auto fb = frontend.projection(m.camera_b).FisheyeFromWarped(Eigen::Vector2d(pb.x, pb.y));
      if (!bearing_a || !fa || !fb) continue;
      const int verdict = GroundTruthMatchVerdict(rig, m.camera_a, *bearing_a, *fa, m.camera_b, *fb, depths[m.camera_a],
                                            depths[m.camera_b], options.inlier_px);
      if (verdict < 0) continue;
      ++result.matches_frontend;
      result.inliers_frontend += verdict;
      if (last && !pairs.empty() && m.camera_a == pairs[0].first && m.camera_b == pairs[0].second) {
        drawn_frontend.push_back({pa, pb, verdict == 1});
      }
    }
    if (last && !pairs.empty()) {
      last_fisheye_a = images[pairs[0].first];
      last_fisheye_b = images[pairs[0].second];
    }
    progress.Add(1);
  }
  progress.Finish();

  const auto mean = [](const Arm& arm) { return arm.hamming_pairs ? arm.hamming_sum / arm.hamming_pairs : 0.0; };
  const auto distinct = [](const Arm& arm) {
    int64_t count = 0;
    for (const auto& ids : arm.contributing) count += static_cast<int64_t>(ids.size());
    return count;
  };
  result.hamming_fisheye = mean(fisheye_arm);
  result.hamming_hybrid = mean(hybrid_arm);
  result.tracked_pairs_fisheye = fisheye_arm.hamming_pairs;
  result.tracked_pairs_hybrid = hybrid_arm.hamming_pairs;
  result.features_fisheye = distinct(fisheye_arm);
  result.features_hybrid = distinct(hybrid_arm);
  result.matches_fisheye = fisheye_arm.matches;
  result.inliers_fisheye = fisheye_arm.inliers;
  result.matches_hybrid = hybrid_arm.matches;
  result.inliers_hybrid = hybrid_arm.inliers;

  // Outputs.
  char line[512];
  std::ostringstream md;
  md << "# Hybrid projection vs raw fisheye (paper Table II)\n\n";
  md << "Dataset: `" << options.dataset_dir << "` (preset " << (info.preset.empty() ? "custom" : info.preset)
     << ", seed " << info.seed << "), frames 0-" << frames - 1 << ", " << n << " cameras, "
     << options.features_per_view << " features per view. rovo " << ROVO_VERSION << ".\n\n";
  md << "| | Original fisheye | Hybrid projection (ours) | Paper: fisheye / hybrid |\n|---|---|---|---|\n";
  std::snprintf(line, sizeof(line), "| Descriptor distance (mean Hamming, t vs t+1) | %.2f | %.2f | 124.85 / 35.27 |\n",
                result.hamming_fisheye, result.hamming_hybrid);
  md << line;
  std::snprintf(line, sizeof(line), "| Inter-view inlier ratio (%%), epipolar-consistent NN matches | %.2f | %.2f | 21.53 / 73.16 |\n",
                100.0 * result.InlierRatioFisheye(), 100.0 * result.InlierRatioHybrid());
  md << line;
  std::snprintf(line, sizeof(line), "| Inter-view inlier ratio (%%), front-end filters (hybrid only) | - | %.2f | - |\n\n",
                100.0 * result.InlierRatioFrontend());
  md << line;
  std::snprintf(line, sizeof(line),
                "Ratios: descriptor distance hybrid/fisheye = %.3f (target <= 0.35); inlier ratio hybrid/fisheye = "
                "%.2f (target >= 3, hybrid >= 80%%).\n\n",
                result.hamming_fisheye > 0 ? result.hamming_hybrid / result.hamming_fisheye : 0.0,
                result.InlierRatioFisheye() > 0 ? result.InlierRatioHybrid() / result.InlierRatioFisheye() : 0.0);
  md << line;
  md << "Counts: tracked descriptor pairs fisheye " << result.tracked_pairs_fisheye << " (" << result.features_fisheye
     << " tracks), hybrid " << result.tracked_pairs_hybrid << " (" << result.features_hybrid
     << " tracks); matches (inliers) fisheye " << result.matches_fisheye << " (" << result.inliers_fisheye
     << "), hybrid " << result.matches_hybrid << " (" << result.inliers_hybrid << "), front-end "
     << result.matches_frontend << " (" << result.inliers_frontend << ").\n\n";
  md << "Method: the same tracker (FAST + " << frontend_options.min_feature_distance_px
     << " px minimum distance, pyramidal KLT with forward-backward check, ORB descriptors) on both image kinds. "
        "Matches: mutual nearest ORB neighbours between neighbouring views, kept when within "
     << options.epipolar_deg << " deg of the epipolar plane (ground-truth extrinsics). Inlier: the depth-map "
     << "back-projection of the first feature reprojects within " << options.inlier_px
     << " fisheye px of the second and is not occluded (depth agrees). Matches without depth (sky) are not counted.\n";
  WriteFileAtomic(options.out_dir + "/table.md", md.str());

  nlohmann::json json;
  json["generator"] = "rovo study projection";
  json["generator_version"] = ROVO_VERSION;
  json["dataset"] = options.dataset_dir;
  json["dataset_seed"] = info.seed;
  json["preset"] = info.preset;
  json["frames"] = frames;
  json["features_per_view"] = options.features_per_view;
  json["epipolar_deg"] = options.epipolar_deg;
  json["inlier_px"] = options.inlier_px;
  json["fisheye"] = {{"mean_hamming", result.hamming_fisheye},
                     {"tracked_pairs", result.tracked_pairs_fisheye},
                     {"tracks", result.features_fisheye},
                     {"matches", result.matches_fisheye},
                     {"inliers", result.inliers_fisheye},
                     {"inlier_ratio", result.InlierRatioFisheye()}};
  json["hybrid"] = {{"mean_hamming", result.hamming_hybrid},
                    {"tracked_pairs", result.tracked_pairs_hybrid},
                    {"tracks", result.features_hybrid},
                    {"matches", result.matches_hybrid},
                    {"inliers", result.inliers_hybrid},
                    {"inlier_ratio", result.InlierRatioHybrid()}};
  json["frontend"] = {{"matches", result.matches_frontend},
                      {"inliers", result.inliers_frontend},
                      {"inlier_ratio", result.InlierRatioFrontend()}};
  WriteJsonFileAtomic(options.out_dir + "/study.json", json);

  if (!pairs.empty()) {
    const auto [a, b] = pairs[0];
    std::vector<DrawnMatch> hybrid_drawn = drawn_frontend;
    WriteMatchesPng(options.out_dir + "/matches_hybrid.png", frontend.warped_image(a), frontend.warped_image(b),
                    hybrid_drawn,
                    "hybrid, front-end matches cam" + std::to_string(a) + "-cam" + std::to_string(b) + " frame " +
                        std::to_string(frames - 1) + " (green: inlier by depth GT, red: outlier)");
    WriteMatchesPng(options.out_dir + "/matches_fisheye.png", last_fisheye_a, last_fisheye_b, fisheye_arm.drawn,
                    "raw fisheye, epipolar-consistent NN matches cam" + std::to_string(a) + "-cam" + std::to_string(b));
  }
  return result;
}

void AddProjectionStudyCommand(CliGroups& groups) {
  auto options = std::make_shared<ProjectionStudyOptions>();
  CLI::App* cmd = groups.study->add_subcommand(
      "projection",
      "Paper Table II on a dataset: ORB descriptor distance of tracked features (frame t vs t+1) and "
      "inter-view matching inlier ratio (verified with the dataset's depth), raw fisheye vs hybrid "
      "projection. Writes table.md, study.json and match drawings. Needs a dataset rendered with --depth.");
  cmd->add_option("dataset", options->dataset_dir, "Dataset folder (with depth/)")->required();
  cmd->add_option("--out", options->out_dir, "Output folder")->required();
  cmd->add_option("--frames", options->frames, "Frames to use from the start")->capture_default_str()->check(
      CLI::Range(2, 1000000));
  cmd->add_option("--features", options->features_per_view, "Tracker target features per view")
      ->capture_default_str()
      ->check(CLI::Range(10, 100000));
  cmd->add_option("--epipolar-deg", options->epipolar_deg, "Epipolar consistency threshold of part (b), degrees")
      ->capture_default_str();
  cmd->add_option("--inlier-px", options->inlier_px, "Ground-truth inlier tolerance, fisheye pixels")
      ->capture_default_str();
  cmd->add_flag("--quiet", options->quiet, "No progress output");
  cmd->callback([options] {
    const ProjectionStudyResult r = RunProjectionStudy(*options);
    std::printf("descriptor distance: fisheye %.2f, hybrid %.2f (%lld / %lld tracked pairs)\n", r.hamming_fisheye,
                r.hamming_hybrid, static_cast<long long>(r.tracked_pairs_fisheye),
                static_cast<long long>(r.tracked_pairs_hybrid));
    std::printf("inter-view inlier ratio: fisheye %.2f%% (%lld), hybrid %.2f%% (%lld), front-end %.2f%% (%lld)\n",
                100.0 * r.InlierRatioFisheye(), static_cast<long long>(r.matches_fisheye), 100.0 * r.InlierRatioHybrid(),
                static_cast<long long>(r.matches_hybrid), 100.0 * r.InlierRatioFrontend(),
                static_cast<long long>(r.matches_frontend));
    std::printf("wrote %s/table.md\n", options->out_dir.c_str());
  });
}

}  // namespace rovo
