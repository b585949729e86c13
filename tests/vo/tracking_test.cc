#include "vo/tracking.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <map>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <random>
#include <set>

#include "blurred_noise.h"

namespace rovo {
namespace {

// Smooth random texture (blurred noise plus random rectangles) with strong corners.
cv::Mat TexturedImage(int width, int height, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image = BlurredNoise(width, height, rng);
  for (int k = 0; k < 400; ++k) {
    const int x = rng.uniform(0, width), y = rng.uniform(0, height);
    cv::rectangle(image, cv::Rect(x, y, rng.uniform(8, 40), rng.uniform(8, 40)), cv::Scalar(rng.uniform(0, 255)),
                  cv::FILLED);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.8);
  return image;
}

cv::Mat Shifted(const cv::Mat& image, double dx, double dy) {
  cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat out;
  cv::warpAffine(image, out, m, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

uint64_t Counter() {
  static uint64_t next = 0;
  return ++next;
}

TEST(Tracking, DetectsUniformlyUpToTheTarget) {
  TrackerOptions options;
  options.target_features = 300;
  options.min_feature_distance_px = 15.0f;
  ViewTracker tracker(options);
  const cv::Mat image = TexturedImage(640, 480, 1);
  cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(320, 0, 320, 480)).setTo(0);  // right half invalid
  tracker.Track(image, mask);
  tracker.DetectAndDescribe(Counter);
  const auto& points = tracker.points();
  ASSERT_GE(static_cast<int>(points.size()), 250);
  ASSERT_LE(static_cast<int>(points.size()), 300);
  std::set<uint64_t> ids;
  for (size_t i = 0; i < points.size(); ++i) {
    ids.insert(points[i].track_id);
    EXPECT_LT(points[i].px.x, 320 - options.border_px);  // inside the eroded mask
    EXPECT_TRUE(points[i].has_descriptor);
    EXPECT_EQ(points[i].descriptor.cols, 32);
    EXPECT_EQ(points[i].age, 0);
    for (size_t j = i + 1; j < points.size(); ++j) {
      EXPECT_GE(cv::norm(points[i].px - points[j].px), options.min_feature_distance_px - 1e-3);
    }
  }
  EXPECT_EQ(ids.size(), points.size());
  // Uniform coverage: every quadrant of the valid half holds features.
  int quadrant[4] = {0, 0, 0, 0};
  for (const TrackedPoint& p : points) quadrant[(p.px.x >= 160) + 2 * (p.px.y >= 240)]++;
  for (int q : quadrant) EXPECT_GT(q, 30);
}

TEST(Tracking, KltFollowsAShiftAndKeepsIds) {
  ViewTracker tracker;
  const cv::Mat image = TexturedImage(640, 480, 2);
  const cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(255));
  tracker.Track(image, mask);
  tracker.DetectAndDescribe(Counter);
  std::map<uint64_t, cv::Point2f> before;
  for (const TrackedPoint& p : tracker.points()) before[p.track_id] = p.px;
  const double dx = 3.3, dy = -1.7;
  const int kept = tracker.Track(Shifted(image, dx, dy), mask);
  EXPECT_GT(kept, 0.85 * before.size());
  double sum_error = 0;
  for (const TrackedPoint& p : tracker.points()) {
    ASSERT_TRUE(before.count(p.track_id));
    EXPECT_EQ(p.age, 1);
    const cv::Point2f error = p.px - before[p.track_id] - cv::Point2f(dx, dy);
    EXPECT_LT(cv::norm(error), 0.25);
    sum_error += cv::norm(error);
  }
  EXPECT_LT(sum_error / kept, 0.1);
  // Re-detection fills up to the target again with fresh ids.
  tracker.DetectAndDescribe(Counter);
  EXPECT_GT(static_cast<int>(tracker.points().size()), kept);
  int fresh = 0;
  for (const TrackedPoint& p : tracker.points()) fresh += before.count(p.track_id) == 0;
  EXPECT_EQ(fresh, static_cast<int>(tracker.points().size()) - kept);
}

// A texture moving 28 px per frame: the first step needs the pyramid, the later ones start from the
// last displacement with the base level only. When the motion reverses, the prediction is 56 px off
// and the tracks must survive through the full-pyramid retry.
TEST(Tracking, PredictedFlowFollowsFastMotionAndRecoversFromAReversal) {
  TrackerOptions options;
  options.klt_predict_flow = true;
  options.klt_predicted_levels = 0;
  ViewTracker tracker(options);
  const cv::Mat base = TexturedImage(760, 480, 5);
  const cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(255));
  const std::vector<double> offsets = {0, 28, 56, 84, 56, 28};  // x shift of the view per frame
  std::map<uint64_t, cv::Point2f> first;
  for (size_t k = 0; k < offsets.size(); ++k) {
    // The view moves right over the texture: features move left by the offset.
    const cv::Mat view = Shifted(base, -offsets[k], 0)(cv::Rect(0, 0, 640, 480)).clone();
    const int kept = tracker.Track(view, mask);
    if (k == 0) {
      tracker.DetectAndDescribe(Counter);
      for (const TrackedPoint& p : tracker.points()) first[p.track_id] = p.px;
      continue;
    }
    int checked = 0;
    double sum_error = 0;
    for (const TrackedPoint& p : tracker.points()) {
      if (!first.count(p.track_id)) continue;
      const cv::Point2f expected = first[p.track_id] - cv::Point2f(static_cast<float>(offsets[k]), 0);
      sum_error += cv::norm(p.px - expected);
      ++checked;
      EXPECT_NEAR(p.flow.x, -(offsets[k] - offsets[k - 1]), 0.2) << "flow is the last displacement";
      EXPECT_NEAR(p.flow.y, 0.0, 0.2);
    }
    ASSERT_GT(checked, 0) << "frame " << k;
    EXPECT_LT(sum_error / checked, 0.1) << "frame " << k;
    // Nearly every original track whose point is still inside the view (away from the border) survives.
    int inside = 0;
    for (const auto& [id, px] : first) inside += px.x - offsets[k] > 40 && px.x - offsets[k] < 600;
    EXPECT_GT(checked, 0.85 * inside) << "frame " << k << ", kept " << kept;
    tracker.DetectAndDescribe(Counter);
  }
}

TEST(Tracking, ForwardBackwardCheckDropsChangedRegions) {
  ViewTracker tracker;
  const cv::Mat image = TexturedImage(640, 480, 3);
  const cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(255));
  tracker.Track(image, mask);
  tracker.DetectAndDescribe(Counter);
  int left_before = 0;
  for (const TrackedPoint& p : tracker.points()) left_before += p.px.x < 280;
  // The right half becomes an unrelated texture: those tracks must go, the left ones stay.
  cv::Mat next = image.clone();
  TexturedImage(640, 480, 99)(cv::Rect(320, 0, 320, 480)).copyTo(next(cv::Rect(320, 0, 320, 480)));
  tracker.Track(next, mask);
  int left_after = 0, right_after = 0;
  for (const TrackedPoint& p : tracker.points()) {
    if (p.px.x < 280) ++left_after;
    if (p.px.x > 360) ++right_after;
  }
  EXPECT_GT(left_after, 0.9 * left_before);
  EXPECT_LT(right_after, 0.1 * left_before);
}

// max_new_per_frame: a view without tracks fills up to the target; once it has tracks, at most that
// many new points are added per frame.
TEST(Tracking, LimitsNewDetectionsOnlyWhileTheViewHasTracks) {
  TrackerOptions options;
  options.target_features = 300;
  options.max_new_per_frame = 40;
  ViewTracker tracker(options);
  const cv::Mat image = TexturedImage(640, 480, 5);
  const cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(255));
  tracker.Track(image, mask);
  tracker.DetectAndDescribe(Counter);
  ASSERT_GE(static_cast<int>(tracker.points().size()), 250);  // first frame: no limit
  // The right half becomes an unrelated texture: its tracks die, and only 40 new points replace them.
  cv::Mat next = image.clone();
  TexturedImage(640, 480, 98)(cv::Rect(320, 0, 320, 480)).copyTo(next(cv::Rect(320, 0, 320, 480)));
  const int kept = tracker.Track(next, mask);
  ASSERT_LT(kept, 250);
  tracker.DetectAndDescribe(Counter);
  int fresh = 0;
  for (const TrackedPoint& p : tracker.points()) fresh += p.age == 0;
  EXPECT_EQ(fresh, 40);
  EXPECT_EQ(static_cast<int>(tracker.points().size()), kept + 40);
  // A view that lost every track (e.g. a black frame) fills up again.
  tracker.Clear();
  tracker.Track(next, mask);
  tracker.DetectAndDescribe(Counter);
  EXPECT_GE(static_cast<int>(tracker.points().size()), 250);
}

// Mean Hamming distance between each track's descriptor on `image` and on `image` shifted by
// (dx, dy), over the tracks KLT keeps; `count` receives their number.
double MeanDescriptorChangeUnderShift(const TrackerOptions& options, const cv::Mat& image, double dx, double dy,
                                      int* count) {
  const cv::Mat mask(image.size(), CV_8UC1, cv::Scalar(255));
  ViewTracker tracker(options);
  tracker.Track(image, mask);
  tracker.DetectAndDescribe(Counter);
  std::map<uint64_t, cv::Mat> descriptors;
  for (const TrackedPoint& p : tracker.points()) descriptors[p.track_id] = p.descriptor.clone();
  tracker.Track(Shifted(image, dx, dy), mask);
  tracker.DetectAndDescribe(Counter);
  double sum = 0;
  *count = 0;
  for (const TrackedPoint& p : tracker.points()) {
    if (!descriptors.count(p.track_id) || !p.has_descriptor) continue;
    sum += HammingDistance(descriptors[p.track_id], p.descriptor);
    ++*count;
  }
  return sum / std::max(*count, 1);
}

TEST(Tracking, DescriptorsAreStableUnderSmallShiftAndOrientationFollowsRotation) {
  const cv::Mat image = TexturedImage(640, 480, 4);
  int count = 0;
  const double mean_change = MeanDescriptorChangeUnderShift(TrackerOptions{}, image, 0.4, 0.3, &count);
  ASSERT_GT(count, 100);
  EXPECT_LT(mean_change, 30.0);  // random descriptors would be ~128 apart

  // Rotating the image by 30 deg about a point rotates its ORB orientation by 30 deg.
  const cv::Point2f centre(320, 240);
  cv::Mat rotated;
  cv::warpAffine(image, rotated, cv::getRotationMatrix2D(centre, 30.0, 1.0), image.size(), cv::INTER_CUBIC);
  const float a = IntensityCentroidAngleDeg(image, centre);
  const float b = IntensityCentroidAngleDeg(rotated, centre);
  double diff = std::fmod(a - b + 720.0, 360.0);  // OpenCV rotates counter-clockwise on screen
  EXPECT_NEAR(diff, 30.0, 3.0);
}

// Upright descriptors (angle 0) skip the intensity-centroid angle, whose noise moves oriented ORB
// bits: under a sub-pixel shift (what tracking between rectified-like views sees) they change less.
TEST(Tracking, UprightDescriptorsAreSteadierUnderSubpixelShift) {
  const cv::Mat image = TexturedImage(640, 480, 9);
  const cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(255));
  const auto mean_change = [&](bool upright) {
    TrackerOptions options;
    options.upright_descriptors = upright;
    int count = 0;
    const double change = MeanDescriptorChangeUnderShift(options, image, 0.45, -0.35, &count);
    EXPECT_GT(count, 100);
    return change;
  };
  const double oriented = mean_change(false), upright = mean_change(true);
  EXPECT_LT(upright, 0.8 * oriented) << "oriented " << oriented << ", upright " << upright;

  // Upright descriptors are ORB's at angle 0; the orientation is still measured (inter-view filter).
  TrackerOptions options;
  options.upright_descriptors = true;
  ViewTracker tracker(options);
  tracker.Track(image, mask);
  tracker.DetectAndDescribe(Counter);
  ASSERT_FALSE(tracker.points().empty());
  const TrackedPoint& p = tracker.points().front();
  std::vector<cv::KeyPoint> keypoint = {cv::KeyPoint(p.px, 31.0f, 0.0f)};
  cv::Mat expected;
  cv::ORB::create(500, 1.2f, 1, 19, 0, 2, cv::ORB::HARRIS_SCORE, 31)->compute(image, keypoint, expected);
  ASSERT_EQ(expected.rows, 1);
  EXPECT_EQ(HammingDistance(expected, p.descriptor), 0);
  EXPECT_FLOAT_EQ(p.angle_deg, IntensityCentroidAngleDeg(image, p.px));
}

// The tracker's KLT runs in chunks of points that idle workers may take: the tracks, their positions,
// ages and descriptors are the same on one thread and on two, in the same order.
TEST(Tracking, TracksAreTheSameOnOneThreadAndOnTwo) {
  const auto run = [](int threads) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    uint64_t next = 0;
    ViewTracker tracker;
    const cv::Mat image = TexturedImage(640, 480, 9);
    const cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(255));
    std::vector<TrackedPoint> points;
    for (int frame = 0; frame < 4; ++frame) {
      tracker.Track(Shifted(image, 3.5 * frame, -1.25 * frame), mask);
      tracker.DetectAndDescribe([&next] { return ++next; });
    }
    return tracker.points();
  };
  const std::vector<TrackedPoint> one = run(1), two = run(2);
  ASSERT_GT(one.size(), 300u);  // several chunks of 64 points
  ASSERT_EQ(one.size(), two.size());
  int aged = 0;
  for (size_t k = 0; k < one.size(); ++k) {
    EXPECT_EQ(one[k].track_id, two[k].track_id);
    EXPECT_EQ(one[k].px, two[k].px);
    EXPECT_EQ(one[k].age, two[k].age);
    EXPECT_EQ(one[k].angle_deg, two[k].angle_deg);
    EXPECT_EQ(cv::norm(one[k].descriptor, two[k].descriptor, cv::NORM_HAMMING), 0.0);
    aged += one[k].age >= 3;
  }
  EXPECT_GT(aged, 100);
}

// PyrLkInChunks gives every point the position and status of one cv::calcOpticalFlowPyrLK call over
// all of them, from zero flow and from given starts, on one thread and on two.
TEST(Tracking, LkInChunksIsOneCall) {
  const cv::Mat image = TexturedImage(640, 480, 12);
  const cv::Mat moved = Shifted(image, 4.25, -2.5);
  const cv::Size window(15, 15);
  std::vector<cv::Mat> from_pyramid, to_pyramid;
  cv::buildOpticalFlowPyramid(image, from_pyramid, window, 3);
  cv::buildOpticalFlowPyramid(moved, to_pyramid, window, 3);
  std::vector<cv::Point2f> from, starts;
  cv::RNG rng(5);
  for (int k = 0; k < 3 * kLkChunkPoints + 17; ++k) {  // the last chunk partial; some points near the border
    from.emplace_back(rng.uniform(2.0f, 638.0f), rng.uniform(2.0f, 478.0f));
    starts.push_back(from.back() + cv::Point2f(rng.uniform(2.0f, 6.0f), rng.uniform(-4.0f, 0.0f)));
  }
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  for (const int flags : {0, static_cast<int>(cv::OPTFLOW_USE_INITIAL_FLOW)}) {
    std::vector<cv::Point2f> one = starts;
    std::vector<uint8_t> one_status;
    cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, from, one, one_status, cv::noArray(), window, 3, criteria,
                             flags);
    int tracked = 0;
    for (const int threads : {1, 2}) {
      const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      std::vector<cv::Point2f> chunked = flags != 0 ? starts : std::vector<cv::Point2f>{};
      std::vector<uint8_t> status;
      PyrLkInChunks(from_pyramid, to_pyramid, from, &chunked, &status, window, 3, criteria, flags);
      ASSERT_EQ(chunked.size(), from.size());
      ASSERT_EQ(status.size(), from.size());
      tracked = 0;
      for (size_t k = 0; k < from.size(); ++k) {
        EXPECT_EQ(status[k], one_status[k]) << k;
        EXPECT_EQ(chunked[k], one[k]) << k;
        tracked += one_status[k] != 0;
      }
    }
    EXPECT_GT(tracked, 150);
    EXPECT_LT(tracked, static_cast<int>(from.size()));  // some fail: the border, flat patches
  }
  std::vector<cv::Point2f> short_starts(3);
  std::vector<uint8_t> status;
  EXPECT_THROW(PyrLkInChunks(from_pyramid, to_pyramid, from, &short_starts, &status, window, 3, criteria,
                             cv::OPTFLOW_USE_INITIAL_FLOW),
               std::invalid_argument);
}

TEST(Tracking, HammingDistanceCountsBits) {
  cv::Mat a = cv::Mat::zeros(1, 32, CV_8UC1), b = a.clone();
  b.at<uint8_t>(0, 0) = 0xFF;
  b.at<uint8_t>(0, 31) = 0x01;
  EXPECT_EQ(HammingDistance(a, b), 9);
  EXPECT_EQ(HammingDistance(a, a), 0);
}

TEST(Tracking, RejectsNonGrayImages) {
  ViewTracker tracker;
  const cv::Mat color(100, 100, CV_8UC3);
  const cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(255));
  EXPECT_THROW(tracker.Track(color, mask), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
