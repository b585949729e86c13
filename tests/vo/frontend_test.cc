// Front-end on images ray-cast in a textured box (no renderer needed): warping, tracking, inter-view
// matching and id unification checked against the exact geometry.
#include "vo/frontend.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <map>
#include <opencv2/core/utility.hpp>
#include <set>
#include <string>
#include <thread>

#include "datasets/rig.h"

namespace rovo {
namespace {

// Axis-aligned room around the origin; walls textured with random-intensity tiles plus value noise.
struct BoxWorld {
  Eigen::Vector3d min_corner{-9.0, -7.0, -1.6}, max_corner{11.0, 8.0, 4.0};

  static double Hash(int64_t x, int64_t y, int64_t face) {
    uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull ^ static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full ^
                 static_cast<uint64_t>(face) * 0x165667B19E3779F9ull;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return (h & 0xFFFF) / 65535.0;
  }
  static double Noise(double x, double y, int face, double cell) {
    const double fx = x / cell, fy = y / cell;
    const int64_t ix = static_cast<int64_t>(std::floor(fx)), iy = static_cast<int64_t>(std::floor(fy));
    const double tx = fx - ix, ty = fy - iy;
    const double sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
    const double a = Hash(ix, iy, face), b = Hash(ix + 1, iy, face);
    const double c = Hash(ix, iy + 1, face), d = Hash(ix + 1, iy + 1, face);
    return (a * (1 - sx) + b * sx) * (1 - sy) + (c * (1 - sx) + d * sx) * sy;
  }
  static double Texture(double x, double y, int face) {
    const double tiles =
        Hash(static_cast<int64_t>(std::floor(x / 0.35)), static_cast<int64_t>(std::floor(y / 0.35)), face + 17);
    return 30.0 + 140.0 * tiles + 80.0 * Noise(x, y, face, 0.09);
  }

  // Distance along a unit ray from inside the box to the wall, and the wall's intensity there.
  double Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* intensity) const {
    double best = 1e18;
    int best_axis = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(direction[axis]) < 1e-12) continue;
      const double bound = direction[axis] > 0 ? max_corner[axis] : min_corner[axis];
      const double t = (bound - origin[axis]) / direction[axis];
      if (t > 0 && t < best) best = t, best_axis = axis;
    }
    if (intensity) {
      const Eigen::Vector3d hit = origin + best * direction;
      const int u_axis = (best_axis + 1) % 3, v_axis = (best_axis + 2) % 3;
      const int face = 2 * best_axis + (direction[best_axis] > 0);
      *intensity = Texture(hit[u_axis], hit[v_axis], face);
    }
    return best;
  }

  std::vector<cv::Mat> Render(const Rig& rig, const Rigid3& world_from_rig) const {
    std::vector<cv::Mat> images;
    for (const RigCamera& rc : rig.cameras) {
      const Rigid3 world_from_cam = world_from_rig * rc.cam_from_rig.Inverse();
      cv::Mat image(rc.camera.height, rc.camera.width, CV_8UC1, cv::Scalar(0));
      for (int v = 0; v < image.rows; ++v) {
        for (int u = 0; u < image.cols; ++u) {
          const auto bearing = rc.camera.Unproject(Eigen::Vector2d(u, v));
          if (!bearing || !rc.camera.InFov(*bearing)) continue;
          double intensity = 0;
          Cast(world_from_cam.translation, world_from_cam.rotation * *bearing, &intensity);
          image.at<uint8_t>(v, u) = static_cast<uint8_t>(std::clamp(intensity, 0.0, 255.0));
        }
      }
      images.push_back(image);
    }
    return images;
  }

  Eigen::Vector3d PointInWorld(const Rig& rig, const Rigid3& world_from_rig, int camera,
                               const Eigen::Vector3d& bearing_in_cam) const {
    const Rigid3 world_from_cam = world_from_rig * rig.cameras[camera].cam_from_rig.Inverse();
    const Eigen::Vector3d direction = world_from_cam.rotation * bearing_in_cam;
    return world_from_cam.translation + Cast(world_from_cam.translation, direction, nullptr) * direction;
  }
};

class FrontendBox : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rig_ = new Rig(MakeRigPreset("omnimvs4"));
    world_ = new BoxWorld();
    for (int k = 0; k < 3; ++k) {
      const Rigid3 world_from_rig(QuaternionFromRollPitchYawDeg(0, 0, 1.5 * k), Eigen::Vector3d(0.15 * k, 0.05 * k, 0));
      poses_.push_back(world_from_rig);
      frames_.push_back(world_->Render(*rig_, world_from_rig));
    }
  }
  static void TearDownTestSuite() {
    delete rig_;
    delete world_;
    poses_.clear();
    frames_.clear();
  }
  // Angle between a feature's bearing and the direction from its camera to `point_in_world`.
  static double AngleTo(const Feature& f, int frame, const Eigen::Vector3d& point_in_world) {
    const Rigid3 cam_from_world = rig_->cameras[f.camera].cam_from_rig * poses_[frame].Inverse();
    return AngleBetween(f.bearing_in_cam, cam_from_world * point_in_world);
  }

  static Rig* rig_;
  static BoxWorld* world_;
  static std::vector<Rigid3> poses_;
  static std::vector<std::vector<cv::Mat>> frames_;
};
Rig* FrontendBox::rig_ = nullptr;
BoxWorld* FrontendBox::world_ = nullptr;
std::vector<Rigid3> FrontendBox::poses_;
std::vector<std::vector<cv::Mat>> FrontendBox::frames_;

TEST_F(FrontendBox, TracksMatchesAndUnifiesIds) {
  FrontendOptions options;
  options.target_features_per_view = 400;
  Frontend frontend(*rig_, options);
  std::map<uint64_t, Eigen::Vector3d> point_of_id;  // world point of each id, from its first sighting
  double pixel_rad = 1.0 / frontend.projection(0).focal_px();
  int tracked_checked = 0, tracked_bad = 0, matches_total = 0, matches_bad = 0;
  for (int k = 0; k < 3; ++k) {
    const FrontendFrame frame = frontend.Process(frames_[k]);
    ASSERT_EQ(frame.features_per_camera.size(), 4u);
    EXPECT_GT(frame.ms_warp, 0.0);
    EXPECT_GT(frame.ms_detect, 0.0);
    for (int c = 0; c < 4; ++c) {
      const auto& features = frame.features_per_camera[c];
      EXPECT_GT(features.size(), 300u) << "camera " << c;
      std::set<uint64_t> ids;
      for (const Feature& f : features) {
        EXPECT_TRUE(ids.insert(f.track_id).second) << "id twice in one view";
        EXPECT_EQ(f.camera, c);
        EXPECT_NEAR(f.bearing_in_cam.norm(), 1.0, 1e-9);
        const auto px = frontend.projection(c).WarpedFromBearing(f.bearing_in_cam);
        ASSERT_TRUE(px.has_value());
        EXPECT_LT((px->cast<float>() - f.warped_px).norm(), 1e-3);
        const auto it = point_of_id.find(f.track_id);
        if (it == point_of_id.end()) {
          point_of_id[f.track_id] = world_->PointInWorld(*rig_, poses_[k], c, f.bearing_in_cam);
        } else if (f.age > 0 || k > 0) {
          // Same id, same scene point (within 3 px), whether tracked or matched into this view.
          ++tracked_checked;
          tracked_bad += AngleTo(f, k, it->second) > 3.0 * pixel_rad;
        }
      }
    }
    // Accepted inter-view matches are right by ground truth (2 px) and share one id.
    for (const auto& m : frontend.last_matches()) {
      const auto& pa = frontend.tracker(m.camera_a).points()[m.index_a];
      const auto& pb = frontend.tracker(m.camera_b).points()[m.index_b];
      EXPECT_EQ(pa.track_id, pb.track_id);
      const auto ba = frontend.projection(m.camera_a).BearingFromWarped(Eigen::Vector2d(pa.px.x, pa.px.y));
      const auto bb = frontend.projection(m.camera_b).BearingFromWarped(Eigen::Vector2d(pb.px.x, pb.px.y));
      ASSERT_TRUE(ba && bb);
      const Eigen::Vector3d point = world_->PointInWorld(*rig_, poses_[k], m.camera_a, *ba);
      Feature fb;
      fb.camera = m.camera_b;
      fb.bearing_in_cam = *bb;
      ++matches_total;
      matches_bad += AngleTo(fb, k, point) > 2.0 * pixel_rad;
    }
    if (k == 0) {
      EXPECT_FALSE(frame.merged_ids.empty());
    }
    for (const auto& [from, into] : frame.merged_ids) EXPECT_LT(into, from);
  }
  EXPECT_GT(tracked_checked, 1000);
  EXPECT_LT(tracked_bad, 0.02 * tracked_checked);
  EXPECT_GT(matches_total, 100);
  EXPECT_LE(matches_bad, 0.1 * matches_total) << matches_bad << " of " << matches_total;
}

TEST_F(FrontendBox, DeterministicIds) {
  FrontendOptions options;
  options.target_features_per_view = 200;
  Frontend a(*rig_, options), b(*rig_, options);
  for (int k = 0; k < 2; ++k) {
    const FrontendFrame fa = a.Process(frames_[k]);
    const FrontendFrame fb = b.Process(frames_[k]);
    for (int c = 0; c < 4; ++c) {
      ASSERT_EQ(fa.features_per_camera[c].size(), fb.features_per_camera[c].size());
      for (size_t i = 0; i < fa.features_per_camera[c].size(); ++i) {
        EXPECT_EQ(fa.features_per_camera[c][i].track_id, fb.features_per_camera[c][i].track_id);
      }
    }
    EXPECT_EQ(fa.merged_ids, fb.merged_ids);
  }
}

// The whole output (ids, sub-pixel positions, merges, matches), including a warp-map rebuild by
// SetExtrinsics, is identical for 1, 2 and 4 TBB threads (OpenCV runs serially inside each view).
TEST_F(FrontendBox, IdenticalForAnyThreadCount) {
  const auto run = [](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    FrontendOptions options;
    options.target_features_per_view = 300;
    Frontend frontend(*rig_, options);
    std::vector<FrontendFrame> frames;
    std::vector<std::vector<Frontend::ViewMatch>> matches;
    for (int k = 0; k < 3; ++k) {
      if (k == 2) {
        std::vector<Rigid3> extrinsics = rig_->Extrinsics();
        extrinsics[2] = Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d::UnitX())),
                               Eigen::Vector3d::Zero()) *
                        extrinsics[2];
        frontend.SetExtrinsics(extrinsics);
      }
      frames.push_back(frontend.Process(frames_[k]));
      matches.push_back(frontend.last_matches());
    }
    return std::make_pair(frames, matches);
  };
  const auto reference = run(1);
  for (int threads : {2, 4}) {
    const auto other = run(threads);
    for (int k = 0; k < 3; ++k) {
      const FrontendFrame& fa = reference.first[k];
      const FrontendFrame& fb = other.first[k];
      EXPECT_EQ(fa.merged_ids, fb.merged_ids) << threads << " threads, frame " << k;
      for (int c = 0; c < 4; ++c) {
        ASSERT_EQ(fa.features_per_camera[c].size(), fb.features_per_camera[c].size()) << threads << " threads";
        for (size_t i = 0; i < fa.features_per_camera[c].size(); ++i) {
          EXPECT_EQ(fa.features_per_camera[c][i].track_id, fb.features_per_camera[c][i].track_id);
          EXPECT_EQ(fa.features_per_camera[c][i].warped_px, fb.features_per_camera[c][i].warped_px);
        }
      }
      const auto& ma = reference.second[k];
      const auto& mb = other.second[k];
      ASSERT_EQ(ma.size(), mb.size()) << threads << " threads, frame " << k;
      for (size_t i = 0; i < ma.size(); ++i) {
        EXPECT_EQ(ma[i].index_a, mb[i].index_a);
        EXPECT_EQ(ma[i].index_b, mb[i].index_b);
      }
    }
  }
}

// Process sets OpenCV's thread count to 1 only while it runs; the fused per-view stages report times
// that split the call's wall time (they sum to at most the wall time of the call).
TEST_F(FrontendBox, RestoresOpenCvThreadsAndSplitsStageTimes) {
  const int original = cv::getNumThreads();
  cv::setNumThreads(2);
  const int before = cv::getNumThreads();
  ASSERT_NE(before, 1);  // so that a missing restore would show
  FrontendOptions options;
  options.target_features_per_view = 200;
  Frontend frontend(*rig_, options);
  for (int k = 0; k < 2; ++k) {
    const auto start = std::chrono::steady_clock::now();
    const FrontendFrame frame = frontend.Process(frames_[k]);
    const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(cv::getNumThreads(), before);
    for (double ms : {frame.ms_warp, frame.ms_track, frame.ms_detect, frame.ms_match, frame.cpu_ms_warp,
                      frame.cpu_ms_track, frame.cpu_ms_detect, frame.cpu_ms_match}) {
      EXPECT_GE(ms, 0.0);
    }
    EXPECT_GT(frame.ms_warp, 0.0);
    EXPECT_GT(frame.ms_detect, 0.0);
    EXPECT_LE(frame.ms_warp + frame.ms_track + frame.ms_detect + frame.ms_match, wall_ms + 1e-6);
    if (k == 1) {
      EXPECT_GT(frame.ms_track, 0.0);  // the first frame only stores its image
    }
  }
  frontend.SetExtrinsics(rig_->Extrinsics());
  EXPECT_EQ(cv::getNumThreads(), before);
  cv::setNumThreads(original);
}

// Two front-ends in two threads at once (as `rovo suite --jobs 2` runs two VO runs in one process):
// each gives the same features as when run alone, and OpenCV's thread count is restored at the end.
TEST_F(FrontendBox, ConcurrentFrontendsMatchSequentialRuns) {
  const int original = cv::getNumThreads();
  cv::setNumThreads(2);
  FrontendOptions options;
  options.target_features_per_view = 200;
  const auto run = [&](std::vector<FrontendFrame>* out) {
    Frontend frontend(*rig_, options);
    for (int repeat = 0; repeat < 3; ++repeat) {
      for (const auto& frame : frames_) out->push_back(frontend.Process(frame));
    }
  };
  std::vector<FrontendFrame> alone, first, second;
  run(&alone);
  std::thread a(run, &first), b(run, &second);
  a.join();
  b.join();
  EXPECT_EQ(cv::getNumThreads(), 2);
  for (const auto* together : {&first, &second}) {
    ASSERT_EQ(together->size(), alone.size());
    for (size_t k = 0; k < alone.size(); ++k) {
      for (int i = 0; i < rig_->NumCameras(); ++i) {
        const auto& x = alone[k].features_per_camera[i];
        const auto& y = (*together)[k].features_per_camera[i];
        ASSERT_EQ(x.size(), y.size()) << "frame " << k << " camera " << i;
        for (size_t j = 0; j < x.size(); ++j) {
          EXPECT_EQ(x[j].track_id, y[j].track_id);
          EXPECT_EQ(x[j].warped_px, y[j].warped_px);
        }
      }
    }
  }
  cv::setNumThreads(original);
}

TEST_F(FrontendBox, ExtrinsicUpdatesRebuildOnlyPastTheThreshold) {
  FrontendOptions options;
  options.target_features_per_view = 300;
  Frontend frontend(*rig_, options);
  frontend.Process(frames_[0]);
  std::vector<Rigid3> extrinsics = rig_->Extrinsics();
  const Rigid3 small_turn(Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * M_PI / 180, Eigen::Vector3d::UnitY())),
                          Eigen::Vector3d::Zero());
  extrinsics[1] = small_turn * extrinsics[1];
  frontend.SetExtrinsics(extrinsics);
  EXPECT_LT(RotationDistanceDeg(frontend.projection(1).cam_from_rig().rotation, rig_->cameras[1].cam_from_rig.rotation),
            1e-9);  // 0.3 deg: maps kept
  const Rigid3 big_turn(Eigen::Quaterniond(Eigen::AngleAxisd(3.0 * M_PI / 180, Eigen::Vector3d::UnitY())),
                        Eigen::Vector3d::Zero());
  extrinsics[1] = big_turn * rig_->cameras[1].cam_from_rig;
  const size_t before = frontend.tracker(1).points().size();
  frontend.SetExtrinsics(extrinsics);
  EXPECT_NEAR(RotationDistanceDeg(frontend.projection(1).cam_from_rig().rotation, extrinsics[1].rotation), 0.0, 1e-9);
  EXPECT_GT(frontend.tracker(1).points().size(), 0.8 * before);  // features carried over
  // Tracking continues across the rebuild: most features of camera 1 keep their ids.
  const FrontendFrame frame = frontend.Process(frames_[1]);
  int aged = 0;
  for (const Feature& f : frame.features_per_camera[1]) aged += f.age > 0;
  EXPECT_GT(aged, 0.6 * before);
}

namespace {

// Two front-ends in the same state: their trackers point by point (descriptor bytes included), their
// warped images, last matches and warp maps' extrinsics.
void ExpectSameFrontendState(const Frontend& a, const Frontend& b, const std::string& where) {
  for (int c = 0; c < a.NumCameras(); ++c) {
    const auto& x = a.tracker(c).points();
    const auto& y = b.tracker(c).points();
    ASSERT_EQ(x.size(), y.size()) << where << ", camera " << c;
    for (size_t j = 0; j < x.size(); ++j) {
      EXPECT_EQ(x[j].track_id, y[j].track_id) << where;
      EXPECT_EQ(x[j].px, y[j].px) << where;
      EXPECT_EQ(x[j].age, y[j].age) << where;
      EXPECT_EQ(x[j].flow, y[j].flow) << where;
      EXPECT_EQ(x[j].angle_deg, y[j].angle_deg) << where;
      ASSERT_EQ(x[j].has_descriptor, y[j].has_descriptor) << where;
      if (x[j].has_descriptor) {
        EXPECT_EQ(cv::norm(x[j].descriptor, y[j].descriptor, cv::NORM_HAMMING), 0.0) << where;
      }
    }
    EXPECT_EQ(cv::norm(a.warped_image(c), b.warped_image(c), cv::NORM_INF), 0.0) << where << ", camera " << c;
    EXPECT_EQ(RotationDistanceDeg(a.projection(c).cam_from_rig().rotation, b.projection(c).cam_from_rig().rotation),
              0.0)
        << where << ", camera " << c;
  }
  const auto& ma = a.last_matches();
  const auto& mb = b.last_matches();
  ASSERT_EQ(ma.size(), mb.size()) << where;
  for (size_t k = 0; k < ma.size(); ++k) {
    EXPECT_EQ(ma[k].camera_a, mb[k].camera_a) << where;
    EXPECT_EQ(ma[k].camera_b, mb[k].camera_b) << where;
    EXPECT_EQ(ma[k].index_a, mb[k].index_a) << where;
    EXPECT_EQ(ma[k].index_b, mb[k].index_b) << where;
  }
}

}  // namespace

// Extrinsics handed over while the frame is processed (OnlineExt beside its BA) give what
// SetExtrinsics before Process gives: a 0.3-degree turn of camera 1 (maps kept: the per-view stages
// stand), a 3-degree turn (its maps rebuilt: the stages are undone and run again), then the same
// extrinsics again (no change), whose tracking starts from the state the undo path left. Extrinsics
// that throw, or of the wrong count, leave the front-end as it was.
TEST_F(FrontendBox, LateExtrinsicsAsSetBeforeProcess) {
  FrontendOptions options;
  options.target_features_per_view = 300;
  const auto turned = [&](double deg) {
    std::vector<Rigid3> extrinsics = rig_->Extrinsics();
    extrinsics[1] = Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitY())),
                           Eigen::Vector3d::Zero()) *
                    extrinsics[1];
    return extrinsics;
  };
  const std::vector<std::vector<Rigid3>> updates = {turned(0.3), turned(3.0), turned(3.0)};
  // Camera 1's warp maps after each update: kept, rebuilt, kept.
  const std::vector<Rigid3> maps_of_camera1 = {rig_->cameras[1].cam_from_rig, updates[1][1], updates[1][1]};
  Frontend before(*rig_, options), late(*rig_, options);
  before.Process(frames_[0]);
  late.Process(frames_[0]);
  for (int k = 0; k < 3; ++k) {
    const std::string where = "update " + std::to_string(k);
    before.SetExtrinsics(updates[k]);
    const FrontendFrame expected = before.Process(frames_[1 + k % 2]);
    int calls = 0;
    const FrontendFrame got = late.Process(frames_[1 + k % 2], [&] {
      ++calls;
      return updates[k];
    });
    EXPECT_EQ(calls, 1);
    EXPECT_LT(RotationDistanceDeg(late.projection(1).cam_from_rig().rotation, maps_of_camera1[k].rotation), 1e-9)
        << where;
    EXPECT_EQ(got.merged_ids, expected.merged_ids) << where;
    for (int c = 0; c < rig_->NumCameras(); ++c) {
      const auto& x = expected.features_per_camera[c];
      const auto& y = got.features_per_camera[c];
      ASSERT_EQ(x.size(), y.size()) << where << ", camera " << c;
      for (size_t j = 0; j < x.size(); ++j) {
        EXPECT_EQ(x[j].track_id, y[j].track_id);
        EXPECT_EQ(x[j].warped_px, y[j].warped_px);
        EXPECT_EQ(x[j].bearing_in_cam, y[j].bearing_in_cam);
      }
    }
    ExpectSameFrontendState(before, late, where);
  }
  EXPECT_THROW(late.Process(frames_[1], [] { return std::vector<Rigid3>(); }), std::invalid_argument);
  ExpectSameFrontendState(before, late, "after a wrong count");
  EXPECT_THROW(late.Process(frames_[1], []() -> std::vector<Rigid3> { throw std::runtime_error("no BA"); }),
               std::runtime_error);
  ExpectSameFrontendState(before, late, "after a throw");
}

// A static mask blanking the lower half of camera 1's fisheye image (a rig body, an operator): no
// feature of camera 1 is detected, tracked or matched there, over frames; the other views are unchanged.
TEST_F(FrontendBox, StaticMasksKeepFeaturesOut) {
  std::vector<cv::Mat> masks;
  for (const RigCamera& rc : rig_->cameras)
    masks.push_back(cv::Mat(rc.camera.height, rc.camera.width, CV_8UC1, cv::Scalar(255)));
  masks[1].rowRange(masks[1].rows / 2, masks[1].rows).setTo(0);
  Frontend masked(*rig_, FrontendOptions{});
  masked.SetStaticMasks(masks);
  Frontend plain(*rig_, FrontendOptions{});
  for (int k = 0; k < 3; ++k) {
    const FrontendFrame frame = masked.Process(frames_[k]);
    const FrontendFrame reference = plain.Process(frames_[k]);
    int kept = 0;
    for (const Feature& f : frame.features_per_camera[1]) {
      const auto px = rig_->cameras[1].camera.Project(f.bearing_in_cam);
      ASSERT_TRUE(px.has_value());
      EXPECT_LT(px->y(), masks[1].rows / 2.0) << "frame " << k;
      ++kept;
    }
    EXPECT_GT(kept, 50) << "frame " << k;
    int reference_below = 0;  // without the mask, features do lie there
    for (const Feature& f : reference.features_per_camera[1]) {
      reference_below += rig_->cameras[1].camera.Project(f.bearing_in_cam)->y() >= masks[1].rows / 2.0;
    }
    EXPECT_GT(reference_below, 50) << "frame " << k;
  }
  std::vector<cv::Mat> wrong = masks;
  wrong[2] = cv::Mat(10, 10, CV_8UC1, cv::Scalar(255));
  EXPECT_THROW(masked.SetStaticMasks(wrong), std::invalid_argument);
  EXPECT_THROW(masked.SetStaticMasks({masks[0]}), std::invalid_argument);
}

TEST_F(FrontendBox, RejectsBadInput) {
  Frontend frontend(*rig_, FrontendOptions{});
  std::vector<cv::Mat> three(frames_[0].begin(), frames_[0].begin() + 3);
  EXPECT_THROW(frontend.Process(three), std::invalid_argument);
  std::vector<cv::Mat> wrong = frames_[0];
  wrong[2] = cv::Mat(10, 10, CV_8UC1);
  EXPECT_THROW(frontend.Process(wrong), std::invalid_argument);
  EXPECT_THROW(frontend.SetExtrinsics({}), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
