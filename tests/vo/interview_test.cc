#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>

#include "datasets/rig.h"
#include "vo/hybrid_projection.h"
#include "vo/interview_matching.h"

namespace rovo {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(InterviewFilters, EpipolarAngle) {
  const Eigen::Vector3d ca(0, 0, 0), cb(1, 0, 0);
  const Eigen::Vector3d point(3, 5, 1);
  const Eigen::Vector3d da = (point - ca).normalized(), db = (point - cb).normalized();
  EXPECT_NEAR(EpipolarAngle(ca, da, cb, db), 0.0, 1e-12);
  // Tilting b's ray by 1 deg out of the epipolar plane gives ~1 deg.
  const Eigen::Vector3d plane_normal = (cb - ca).cross(da).normalized();
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(1.0 * kDeg, db.cross(plane_normal).normalized()) * db;
  EXPECT_NEAR(EpipolarAngle(ca, da, cb, tilted) / kDeg, 1.0, 0.05);
  // A ray along the baseline defines no plane.
  EXPECT_NEAR(EpipolarAngle(ca, Eigen::Vector3d::UnitX(), cb, db), 0.5 * M_PI, 1e-12);
}

TEST(InterviewFilters, PositiveDisparity) {
  const Eigen::Vector3d ca(0, 0, 0), cb(1, 0, 0);
  const Eigen::Vector3d point(0.3, 4, 0.5);
  const Eigen::Vector3d da = (point - ca).normalized(), db = (point - cb).normalized();
  const auto lambdas = ClosestRayParameters(ca, da, cb, db);
  ASSERT_TRUE(lambdas.has_value());
  EXPECT_NEAR(lambdas->x(), (point - ca).norm(), 1e-9);
  EXPECT_NEAR(lambdas->y(), (point - cb).norm(), 1e-9);
  EXPECT_TRUE(PositiveDisparity(ca, da, cb, db));
  // Same rays, swapped cameras: they diverge (negative disparity).
  EXPECT_FALSE(PositiveDisparity(cb, da, ca, db));
  // Point behind camera b.
  EXPECT_FALSE(PositiveDisparity(ca, da, cb, -db));
  // Parallel rays: no intersection.
  EXPECT_FALSE(ClosestRayParameters(ca, da, cb, da).has_value());
  EXPECT_FALSE(PositiveDisparity(ca, da, cb, da));
}

// Sub-pixel refinement: view b is view a shifted by a known sub-pixel offset; detections on the
// integer grid move to within 0.05 px of the true positions, and a point without texture to follow
// (flat patch) or a start far from the answer is left alone.
TEST(InterviewRefinement, RecoversSubpixelOffsets) {
  // A band-limited texture (sum of random sinusoids, wavelengths 6..30 px) sampled exactly in both
  // images, so that no resampling error enters the truth.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  struct Wave {
    double kx, ky, phase;
  };
  std::vector<Wave> waves;
  for (int k = 0; k < 24; ++k) {
    const double wavelength = 6.0 + 24.0 * unit(rng), direction = 2.0 * M_PI * unit(rng);
    waves.push_back({2.0 * M_PI / wavelength * std::cos(direction), 2.0 * M_PI / wavelength * std::sin(direction),
                     2.0 * M_PI * unit(rng)});
  }
  const cv::Point2f offset(3.37f, -1.21f);  // b(x + offset) = a(x)
  const auto render = [&](cv::Point2f shift) {
    cv::Mat image(240, 320, CV_8U);
    for (int v = 0; v < image.rows; ++v) {
      for (int u = 0; u < image.cols; ++u) {
        double value = 0.0;
        for (const Wave& w : waves) value += std::cos(w.kx * (u - shift.x) + w.ky * (v - shift.y) + w.phase);
        image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(128.0 + 22.0 * value);
      }
    }
    image(cv::Rect(0, 0, 60, 60)).setTo(128);  // flat corner (the same in both)
    return image;
  };
  const cv::Mat image_a = render(cv::Point2f(0, 0)), image_b = render(offset);

  std::vector<cv::Point2f> from, to;
  for (int v = 80; v <= 180; v += 25) {
    for (int u = 80; u <= 260; u += 30) {
      from.emplace_back(static_cast<float>(u), static_cast<float>(v));
      const cv::Point2f truth = from.back() + offset;
      to.emplace_back(std::round(truth.x), std::round(truth.y));  // FAST-like integer position
    }
  }
  from.emplace_back(30.0f, 30.0f);  // flat
  to.emplace_back(33.0f, 29.0f);
  from.emplace_back(150.0f, 120.0f);  // start 6 px off: beyond max_shift_px
  to.emplace_back(150.0f + offset.x + 6.0f, 120.0f + offset.y);

  const auto refined = RefineMatchPositions(image_a, image_b, from, to);
  ASSERT_EQ(refined.size(), from.size());
  double worst = 0.0, worst_start = 0.0;
  const size_t textured = from.size() - 2;
  for (size_t k = 0; k < textured; ++k) {
    ASSERT_TRUE(refined[k].has_value()) << k;
    const cv::Point2f truth = from[k] + offset;
    worst = std::max(worst, cv::norm(*refined[k] - truth));
    worst_start = std::max(worst_start, cv::norm(to[k] - truth));
  }
  EXPECT_GT(worst_start, 0.3);  // the integer starts are off by up to ~0.5 px
  EXPECT_LT(worst, 0.05);
  EXPECT_FALSE(refined[textured].has_value());
  EXPECT_FALSE(refined[textured + 1].has_value());
  EXPECT_THROW(RefineMatchPositions(image_a, image_b, from, {}), std::invalid_argument);
  // Images of different sizes (views of different cameras) work alike.
  const cv::Mat larger_b = cv::Mat::zeros(image_b.rows + 17, image_b.cols + 40, CV_8U);
  image_b.copyTo(larger_b(cv::Rect(0, 0, image_b.cols, image_b.rows)));
  const auto refined_larger = RefineMatchPositions(image_a, larger_b, from, to);
  for (size_t k = 0; k < from.size(); ++k) EXPECT_EQ(refined_larger[k].has_value(), refined[k].has_value()) << k;
  EXPECT_LT(cv::norm(*refined_larger[0] - (from[0] + offset)), 0.05);
}

TEST(InterviewFilters, RectifiedYAndAngles) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), m = Eigen::Vector3d::UnitX();
  EXPECT_NEAR(*RectifiedY(Eigen::Vector3d(2, 5, -1).normalized(), up, m), 0.5, 1e-12);
  EXPECT_FALSE(RectifiedY(Eigen::Vector3d(-1, 0, 0), up, m).has_value());
  EXPECT_NEAR(AngleDifferenceDeg(350, 10), 20, 1e-12);
  EXPECT_NEAR(AngleDifferenceDeg(10, 190), 180, 1e-12);
  EXPECT_NEAR(AngleDifferenceDeg(725, 0), 5, 1e-12);
}

TEST(InterviewFilters, Zncc) {
  cv::Mat a(64, 64, CV_8UC1);
  cv::RNG rng(5);
  rng.fill(a, cv::RNG::UNIFORM, 0, 200);
  cv::Mat b;
  a.convertTo(b, CV_8UC1, 0.5, 40);  // gain and offset change
  EXPECT_NEAR(*Zncc(a, {30, 30}, b, {30, 30}, 11), 1.0, 0.02);
  EXPECT_LT(*Zncc(a, {30, 30}, a, {20, 40}, 11), 0.5);
  EXPECT_FALSE(Zncc(a, {2, 30}, b, {30, 30}, 11).has_value());  // patch leaves the image
  const cv::Mat flat(64, 64, CV_8UC1, cv::Scalar(90));
  EXPECT_FALSE(Zncc(flat, {30, 30}, a, {30, 30}, 11).has_value());
}

// ZNCC of the side x side patches around two pixels, in doubles from the mean-subtracted values.
double PlainZncc(const cv::Mat& a, cv::Point pa, const cv::Mat& b, cv::Point pb, int side) {
  const int half = side / 2, n = side * side;
  double ma = 0, mb = 0;
  for (int r = -half; r <= half; ++r) {
    for (int c = -half; c <= half; ++c) {
      ma += a.at<uint8_t>(pa.y + r, pa.x + c);
      mb += b.at<uint8_t>(pb.y + r, pb.x + c);
    }
  }
  ma /= n;
  mb /= n;
  double ab = 0, aa = 0, bb = 0;
  for (int r = -half; r <= half; ++r) {
    for (int c = -half; c <= half; ++c) {
      const double da = a.at<uint8_t>(pa.y + r, pa.x + c) - ma, db = b.at<uint8_t>(pb.y + r, pb.x + c) - mb;
      ab += da * db;
      aa += da * da;
      bb += db * db;
    }
  }
  return ab / std::sqrt(aa * bb);
}

// The integer ZNCC of filter 8's scan (SIMD rows for patches up to 16 px, scalar beyond, and at the
// right edge where a 16-byte row load would leave the image) equals the plain ZNCC, and the float
// Zncc up to getRectSubPix's rounding.
TEST(InterviewFilters, ZnccAtPixelsEqualsZncc) {
  cv::Mat a(70, 90, CV_8UC1), b(70, 90, CV_8UC1);
  cv::RNG rng(11);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  rng.fill(b, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(b, b, cv::Size(3, 3), 0.8);
  b = 0.6 * b + 0.4 * a;  // correlated, not identical
  int compared = 0, right_edge = 0;
  for (const int side : {3, 7, 11, 15, 17, 25}) {
    const int half = side / 2;
    for (int trial = 0; trial < 300; ++trial) {
      // Each centre inside the image by at least the float Zncc's margin (half + 1).
      const cv::Point pa(rng.uniform(half + 2, a.cols - half - 2), rng.uniform(half + 2, a.rows - half - 2));
      const cv::Point pb(trial % 3 == 0 ? b.cols - half - 2 : rng.uniform(half + 2, b.cols - half - 2),
                         rng.uniform(half + 2, b.rows - half - 2));
      const auto exact = ZnccAtPixels(a, pa, b, {pb}, side).at(0);
      const auto reference = Zncc(a, cv::Point2f(pa), b, cv::Point2f(pb), side);
      ASSERT_TRUE(exact.has_value());
      ASSERT_TRUE(reference.has_value());
      EXPECT_NEAR(*exact, PlainZncc(a, pa, b, pb, side), 1e-12) << "side " << side << " at " << pa << ", " << pb;
      EXPECT_NEAR(*exact, *reference, 2e-3) << "side " << side << " at " << pa << ", " << pb;
      ++compared;
      right_edge += pb.x - half + 16 > b.cols;
    }
  }
  EXPECT_EQ(compared, 1800);
  EXPECT_GT(right_edge, 100);  // the scalar fallback ran too
  EXPECT_NEAR(*ZnccAtPixels(a, {30, 30}, a, {{30, 30}}, 11).at(0), 1.0, 1e-12);
  EXPECT_FALSE(ZnccAtPixels(a, {4, 30}, b, {{30, 30}}, 11).at(0).has_value());  // patch leaves the image
  const cv::Mat flat(70, 90, CV_8UC1, cv::Scalar(90));
  EXPECT_FALSE(ZnccAtPixels(a, {30, 30}, flat, {{30, 30}}, 11).at(0).has_value());
}

// Filter 8 on a rectified pair: cameras a at the origin and b 1 m to its right (+x), both looking
// along +y (z up), pinhole f = 100 px, so epipolar curves are image rows. b's image is a's shifted
// by the disparity of a point 5 m away; a copy of the matched patch elsewhere on the same row (a
// repeated structure) makes the match ambiguous, a copy on another row does not.
TEST(InterviewFilters, UniquenessAlongTheEpipolarCurve) {
  constexpr double f = 100.0, cx = 200.0, cy = 100.0;
  const auto pixel = [&](const Eigen::Vector3d& d) -> std::optional<Eigen::Vector2d> {
    if (d.y() <= 1e-9) return std::nullopt;
    const Eigen::Vector2d px(cx + f * d.x() / d.y(), cy - f * d.z() / d.y());
    if (px.x() < 0 || px.y() < 0 || px.x() > 399 || px.y() > 199) return std::nullopt;
    return px;
  };
  const auto bearing = [&](cv::Point2f px) {
    return Eigen::Vector3d((px.x - cx) / f, 1.0, -(px.y - cy) / f).normalized();
  };
  cv::Mat image_a(200, 400, CV_8UC1);
  cv::RNG rng(11);
  rng.fill(image_a, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(image_a, image_a, cv::Size(0, 0), 1.5);
  // Point 5 m ahead: disparity f * 1 m / 5 m = 20 px, u_b = u_a - 20.
  cv::Mat image_b(200, 400, CV_8UC1, cv::Scalar(0));
  image_a.colRange(20, 400).copyTo(image_b.colRange(0, 380));
  const cv::Point2f pa(250, 100), pb(230, 100);
  const Eigen::Vector3d ca(0, 0, 0), cb(1, 0, 0);
  InterviewMatchOptions options;
  options.uniqueness_range_deg = 60.0;
  MatchView view_b;
  view_b.image = &image_b;
  view_b.pixel_from_direction_in_rig = pixel;
  EXPECT_TRUE(UniqueAlongEpipolarCurve(image_a, pa, ca, bearing(pa), view_b, cb, bearing(pb), f, options));

  cv::Mat repeated = image_b.clone();  // the patch again 80 px to the left on the same row
  image_b(cv::Rect(220, 90, 21, 21)).copyTo(repeated(cv::Rect(140, 90, 21, 21)));
  view_b.image = &repeated;
  EXPECT_FALSE(UniqueAlongEpipolarCurve(image_a, pa, ca, bearing(pa), view_b, cb, bearing(pb), f, options));
  // The same copy beyond the scan range is not seen.
  options.uniqueness_range_deg = 20.0;
  EXPECT_TRUE(UniqueAlongEpipolarCurve(image_a, pa, ca, bearing(pa), view_b, cb, bearing(pb), f, options));

  options.uniqueness_range_deg = 60.0;
  cv::Mat other_row = image_b.clone();  // the copy 40 px lower: not on the epipolar curve
  image_b(cv::Rect(220, 90, 21, 21)).copyTo(other_row(cv::Rect(140, 130, 21, 21)));
  view_b.image = &other_row;
  EXPECT_TRUE(UniqueAlongEpipolarCurve(image_a, pa, ca, bearing(pa), view_b, cb, bearing(pb), f, options));
  // Without a mapping into the view there is nothing to scan.
  view_b.pixel_from_direction_in_rig = nullptr;
  view_b.image = &repeated;
  EXPECT_TRUE(UniqueAlongEpipolarCurve(image_a, pa, ca, bearing(pa), view_b, cb, bearing(pb), f, options));
}

// Synthetic overlap of two omnimvs4 neighbours: true points with (noisy) shared descriptors, plus
// distractors that copy a true point's descriptor at a wrong place. All filters but ZNCC (no
// images): every accepted match is right, and most true pairs are found.
class SyntheticPair : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = MakeRigPreset("omnimvs4");
    layouts_ = ComputeHybridLayouts(rig_);
    a_ = 0;
    b_ = layouts_[0].right_neighbour;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    std::uniform_int_distribution<int> byte(0, 255);
    const Eigen::Vector3d m = layouts_[a_].right_normal_in_rig;
    const Eigen::Vector3d tangent = m.cross(Eigen::Vector3d::UnitZ());
    cv::RNG cv_rng(3);
    while (truth_.size() < 200) {
      const Eigen::Vector3d point = (4.0 + 20.0 * std::abs(uniform(rng))) * m + 12.0 * uniform(rng) * tangent +
                                    3.0 * uniform(rng) * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d in_a = rig_.cameras[a_].cam_from_rig * point;
      const Eigen::Vector3d in_b = rig_.cameras[b_].cam_from_rig * point;
      if (!rig_.cameras[a_].camera.InFov(in_a) || !rig_.cameras[b_].camera.InFov(in_b)) continue;
      cv::Mat descriptor(1, 32, CV_8UC1);
      for (int k = 0; k < 32; ++k) descriptor.at<uint8_t>(0, k) = static_cast<uint8_t>(byte(rng));
      const float angle = static_cast<float>(360.0 * std::abs(uniform(rng)));
      AddFeature(&points_a_, &bearings_a_, a_, in_a, Flip(descriptor, 8, cv_rng), angle);
      AddFeature(&points_b_, &bearings_b_, b_, in_b, Flip(descriptor, 8, cv_rng), angle + 5.0f);
      truth_.push_back({static_cast<int>(points_a_.size()) - 1, static_cast<int>(points_b_.size()) - 1});
      // Distractor in b: same descriptor and orientation, a different direction.
      const Eigen::Vector3d wrong =
          rig_.cameras[b_].cam_from_rig * (point + 2.0 * tangent + 1.5 * Eigen::Vector3d::UnitZ());
      if (rig_.cameras[b_].camera.InFov(wrong)) {
        AddFeature(&points_b_, &bearings_b_, b_, wrong, Flip(descriptor, 4, cv_rng), angle);
      }
    }
  }

  static cv::Mat Flip(const cv::Mat& descriptor, int bits, cv::RNG& rng) {
    cv::Mat out = descriptor.clone();
    for (int k = 0; k < bits; ++k) {
      const int bit = rng.uniform(0, 256);
      out.at<uint8_t>(0, bit / 8) ^= static_cast<uint8_t>(1u << (bit % 8));
    }
    return out;
  }

  void AddFeature(std::vector<TrackedPoint>* points, std::vector<Eigen::Vector3d>* bearings, int camera,
                  const Eigen::Vector3d& point_in_cam, const cv::Mat& descriptor, float angle) {
    TrackedPoint p;
    p.track_id = points->size() + 1;
    p.has_descriptor = true;
    p.descriptor = descriptor;
    p.angle_deg = std::fmod(angle, 360.0f);
    points->push_back(p);
    bearings->push_back(rig_.cameras[camera].cam_from_rig.RotationMatrix().transpose() * point_in_cam.normalized());
  }

  std::vector<InterviewMatch> Match(const InterviewMatchOptions& options, double noise_deg = 0.0) {
    MatchView va, vb;
    va.points = &points_a_;
    vb.points = &points_b_;
    va.bearings_in_rig = bearings_a_;
    vb.bearings_in_rig = bearings_b_;
    std::mt19937_64 rng(5);
    std::normal_distribution<double> normal(0.0, noise_deg * kDeg);
    for (auto* bearings : {&va.bearings_in_rig, &vb.bearings_in_rig}) {
      for (Eigen::Vector3d& d : *bearings) {
        d = (Eigen::AngleAxisd(normal(rng), Eigen::Vector3d::UnitZ()) *
             Eigen::AngleAxisd(normal(rng), d.unitOrthogonal()) * d)
                .normalized();
      }
    }
    va.centre_in_rig = rig_.cameras[a_].cam_from_rig.Inverse().translation;
    vb.centre_in_rig = rig_.cameras[b_].cam_from_rig.Inverse().translation;
    PairGeometry pair;
    pair.up_in_rig = layouts_[a_].up_in_rig;
    pair.plane_normal_in_rig = layouts_[a_].right_normal_in_rig;
    pair.focal_px = 200.0;
    return MatchViews(pair, va, vb, options);
  }

  int CountCorrect(const std::vector<InterviewMatch>& matches) const {
    int correct = 0;
    for (const InterviewMatch& m : matches) {
      for (const auto& [ia, ib] : truth_) correct += (m.index_a == ia && m.index_b == ib);
    }
    return correct;
  }

  Rig rig_;
  std::vector<HybridLayout> layouts_;
  int a_ = 0, b_ = 0;
  std::vector<TrackedPoint> points_a_, points_b_;
  std::vector<Eigen::Vector3d> bearings_a_, bearings_b_;
  std::vector<std::pair<int, int>> truth_;
};

TEST_F(SyntheticPair, AllFiltersGivePreciseMatches) {
  InterviewMatchOptions options;
  options.use_zncc = false;
  const auto matches = Match(options, 0.05);
  EXPECT_EQ(CountCorrect(matches), static_cast<int>(matches.size()));
  EXPECT_GT(matches.size(), 0.8 * truth_.size());
}

TEST_F(SyntheticPair, DescriptorsAloneAreFooledByDistractors) {
  InterviewMatchOptions options;
  options.use_zncc = false;
  options.use_y_distance = false;
  options.max_epipolar_angle_deg = 180.0;
  options.max_ratio = 1.0;
  options.use_positive_disparity = false;
  const auto matches = Match(options);
  // Without geometry the closer distractor descriptors win most of the time.
  EXPECT_LT(CountCorrect(matches), 0.5 * matches.size());
  // The epipolar filter alone restores most of the precision, positive disparity the rest.
  options.max_epipolar_angle_deg = 0.5;
  const auto epipolar = Match(options);
  EXPECT_GE(CountCorrect(epipolar), 0.8 * epipolar.size());
  options.use_positive_disparity = true;
  const auto both = Match(options);
  EXPECT_EQ(CountCorrect(both), static_cast<int>(both.size()));
  EXPECT_GT(both.size(), 0.8 * truth_.size());
}

TEST_F(SyntheticPair, OrientationAndDescriptorThresholdsReject) {
  InterviewMatchOptions options;
  options.use_zncc = false;
  options.max_orientation_diff_deg = 2.0;  // true pairs differ by 5 deg
  EXPECT_EQ(CountCorrect(Match(options)), 0);
  options.max_orientation_diff_deg = 30.0;
  options.max_descriptor_distance = 5;  // true pairs differ by up to 16 bits
  EXPECT_LT(CountCorrect(Match(options)), 0.2 * truth_.size());
}

TEST_F(SyntheticPair, RotatedExtrinsicsFailTheEpipolarAndYFilters) {
  // Rotate camera b by 3 deg: matching with the wrong extrinsics rejects the true pairs.
  for (Eigen::Vector3d& d : bearings_b_) d = Eigen::AngleAxisd(3.0 * kDeg, Eigen::Vector3d::UnitX()) * d;
  InterviewMatchOptions options;
  options.use_zncc = false;
  EXPECT_LT(Match(options).size(), 0.1 * truth_.size());
}

}  // namespace
}  // namespace rovo
