#include "vo/interview_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>
#include <string>

#include "vo/patch_kernels.h"

namespace rovo {

void InterviewMatchOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("InterviewMatchOptions.") + what);
  };
  require(max_y_distance_px >= 0.0, "max_y_distance_px must be >= 0");
  require(max_descriptor_distance >= 0, "max_descriptor_distance must be >= 0");
  require(max_orientation_diff_deg >= 0.0, "max_orientation_diff_deg must be >= 0");
  require(max_epipolar_angle_deg >= 0.0, "max_epipolar_angle_deg must be >= 0");
  require(zncc_patch_px >= 1, "zncc_patch_px must be >= 1");
  require(max_ratio > 0.0 && max_ratio <= 1.0, "max_ratio must be in (0, 1]");
  require(uniqueness_range_deg >= 0.0, "uniqueness_range_deg must be >= 0");
  require(uniqueness_exclusion_px >= 0.0, "uniqueness_exclusion_px must be >= 0");
}

void SubpixelMatchOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("SubpixelMatchOptions.") + what);
  };
  require(window_px >= 3, "window_px must be >= 3");
  require(max_iterations >= 1, "max_iterations must be >= 1");
  require(epsilon_px >= 0.0, "epsilon_px must be >= 0");
  require(max_shift_px >= 0.0, "max_shift_px must be >= 0");
  require(max_round_trip_px >= 0.0, "max_round_trip_px must be >= 0");
}

double EpipolarAngle(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& centre_b,
                     const Eigen::Vector3d& bearing_b) {
  const Eigen::Vector3d baseline = centre_b - centre_a;
  const Eigen::Vector3d na = baseline.cross(bearing_a);
  const Eigen::Vector3d nb = baseline.cross(bearing_b);
  const double na_norm = na.norm(), nb_norm = nb.norm();
  if (na_norm < 1e-12 || nb_norm < 1e-12) return 0.5 * M_PI;
  const double angle_b = std::asin(std::min(1.0, std::abs(na.dot(bearing_b)) / (na_norm * bearing_b.norm())));
  const double angle_a = std::asin(std::min(1.0, std::abs(nb.dot(bearing_a)) / (nb_norm * bearing_a.norm())));
  return std::max(angle_a, angle_b);
}

std::optional<Eigen::Vector2d> ClosestRayParameters(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& bearing_a,
                                                    const Eigen::Vector3d& centre_b, const Eigen::Vector3d& bearing_b) {
  // la - c lb = p, c la - lb = q with c = d_a . d_b, p = w . d_a, q = w . d_b, w = c_b - c_a.
  const Eigen::Vector3d w = centre_b - centre_a;
  const double c = bearing_a.dot(bearing_b);
  const double denominator = 1.0 - c * c;
  if (denominator < 1e-12) return std::nullopt;
  const double p = w.dot(bearing_a), q = w.dot(bearing_b);
  return Eigen::Vector2d((p - c * q) / denominator, (c * p - q) / denominator);
}

bool PositiveDisparity(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& bearing_a,
                       const Eigen::Vector3d& centre_b, const Eigen::Vector3d& bearing_b) {
  const auto lambdas = ClosestRayParameters(centre_a, bearing_a, centre_b, bearing_b);
  return lambdas && lambdas->x() > 0 && lambdas->y() > 0;
}

std::optional<double> RectifiedY(const Eigen::Vector3d& bearing, const Eigen::Vector3d& up, const Eigen::Vector3d& m) {
  const double along = bearing.dot(m);
  if (along <= 1e-9) return std::nullopt;
  return -bearing.dot(up) / along;
}

std::optional<double> Zncc(const cv::Mat& image_a, cv::Point2f a, const cv::Mat& image_b, cv::Point2f b, int patch_px) {
  const float half = 0.5f * patch_px + 1.0f;
  const auto inside = [half](const cv::Mat& image, cv::Point2f p) {
    return p.x >= half && p.y >= half && p.x < image.cols - half && p.y < image.rows - half;
  };
  if (!inside(image_a, a) || !inside(image_b, b)) return std::nullopt;
  cv::Mat pa, pb;
  cv::getRectSubPix(image_a, cv::Size(patch_px, patch_px), a, pa, CV_32F);
  cv::getRectSubPix(image_b, cv::Size(patch_px, patch_px), b, pb, CV_32F);
  const int n = patch_px * patch_px;
  double sa = 0, sb = 0;
  const float* va = pa.ptr<float>();
  const float* vb = pb.ptr<float>();
  for (int i = 0; i < n; ++i) sa += va[i], sb += vb[i];
  const double ma = sa / n, mb = sb / n;
  double ab = 0, aa = 0, bb = 0;
  for (int i = 0; i < n; ++i) {
    const double da = va[i] - ma, db = vb[i] - mb;
    ab += da * db;
    aa += da * da;
    bb += db * db;
  }
  if (aa < 1e-6 * n || bb < 1e-6 * n) return std::nullopt;
  return ab / std::sqrt(aa * bb);
}

namespace {

// A reference patch for ZNCC against many candidate patches: the 8-bit values of the
// patch_px x patch_px pixels around the nearest pixel of a point, with their sum and sum of squares.
// ZNCC in integer sums (exact, no per-candidate copy):
//   zncc = (n S_ab - S_a S_b) / sqrt((n S_aa - S_a^2) (n S_bb - S_b^2)),  n = patch_px^2.
struct ReferencePatch {
  std::vector<uint8_t> values;  // row-major
  // For side <= kPatchRowPixels: the values as int16 in rows of kPatchRowPixels, zero beyond `side` (the
  // form PatchSumsAgainst takes).
  std::vector<int16_t> padded;
  int side = 0;
  int64_t sum = 0, variance_n2 = 0;  // S_a and n S_aa - S_a^2
};

// Top-left corner of the patch around the nearest pixel of p; false when the patch leaves the image.
bool PatchCorner(const cv::Mat& image, const Eigen::Vector2d& p, int side, int* x0, int* y0) {
  const int half = side / 2;
  const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
  if (x < half || y < half || x + half >= image.cols || y + half >= image.rows) return false;
  *x0 = x - half;
  *y0 = y - half;
  return true;
}

// A patch is flat when its variance is below 1e-6 grey levels^2 (n S_aa - S_a^2 < 1e-6 n^2).
bool Flat(int64_t variance_n2, int n) { return static_cast<double>(variance_n2) < 1e-6 * n * n; }

// False when the patch leaves the image or is flat.
bool LoadReference(const cv::Mat& image, const Eigen::Vector2d& p, int side, ReferencePatch* patch) {
  int x0, y0;
  if (!PatchCorner(image, p, side, &x0, &y0)) return false;
  patch->side = side;
  patch->values.resize(static_cast<size_t>(side) * side);
  int64_t sum = 0, sum2 = 0;
  uint8_t* out = patch->values.data();
  for (int r = 0; r < side; ++r) {
    const uint8_t* row = image.ptr<uint8_t>(y0 + r) + x0;
    for (int c = 0; c < side; ++c) {
      *out++ = row[c];
      sum += row[c];
      sum2 += row[c] * row[c];
    }
  }
  const int n = side * side;
  patch->sum = sum;
  patch->variance_n2 = n * sum2 - sum * sum;
  patch->padded.clear();
  if (side <= kPatchRowPixels) {
    patch->padded.assign(static_cast<size_t>(side) * kPatchRowPixels, 0);
    for (int r = 0; r < side; ++r) {
      std::copy_n(patch->values.data() + r * side, side, patch->padded.data() + r * kPatchRowPixels);
    }
  }
  return !Flat(patch->variance_n2, n);
}

// ZNCC of the reference with the patch around the nearest pixel of p in `image`; nullopt when that
// patch leaves the image or is flat.
std::optional<double> ZnccWithReference(const ReferencePatch& reference, const cv::Mat& image,
                                        const Eigen::Vector2d& p) {
  const int side = reference.side;
  int x0, y0;
  if (!PatchCorner(image, p, side, &x0, &y0)) return std::nullopt;
  int32_t ab = 0, sb = 0, sb2 = 0;  // at most 45^2 * 255^2 < 2^31
  if (!reference.padded.empty() && x0 + kPatchRowPixels <= image.cols) {
    const PatchSums sums = PatchSumsAgainst(reference.padded.data(), image, x0, y0, side);
    ab = sums.ab;
    sb = sums.b;
    sb2 = sums.bb;
  } else {
    const uint8_t* a = reference.values.data();
    for (int r = 0; r < side; ++r, a += side) {
      const uint8_t* row = image.ptr<uint8_t>(y0 + r) + x0;
      for (int c = 0; c < side; ++c) {
        const int32_t b = row[c];
        ab += a[c] * b;
        sb += b;
        sb2 += b * b;
      }
    }
  }
  const int n = side * side;
  const int64_t variance_n2 = int64_t{n} * sb2 - int64_t{sb} * sb;
  if (Flat(variance_n2, n)) return std::nullopt;
  const double covariance_n2 = static_cast<double>(int64_t{n} * ab - reference.sum * sb);
  return covariance_n2 / std::sqrt(static_cast<double>(reference.variance_n2) * static_cast<double>(variance_n2));
}

}  // namespace

std::vector<std::optional<double>> ZnccAtPixels(const cv::Mat& image_a, cv::Point a, const cv::Mat& image_b,
                                                const std::vector<cv::Point>& b, int patch_px) {
  if (patch_px > 45) throw std::invalid_argument("ZnccAtPixels: patch_px must be <= 45");
  std::vector<std::optional<double>> zncc(b.size());
  ReferencePatch reference;
  if (!LoadReference(image_a, Eigen::Vector2d(a.x, a.y), patch_px, &reference)) return zncc;
  for (size_t k = 0; k < b.size(); ++k)
    zncc[k] = ZnccWithReference(reference, image_b, Eigen::Vector2d(b[k].x, b[k].y));
  return zncc;
}

namespace {

constexpr int kKnot = 4;  // curve pixels exact every kKnot steps, linear between

// ZNCC of the reference patch every pixel (1 / f rad) along the epipolar curve through `along`
// (rotating towards `across`) within range_deg each side, with each sample's distance from
// `centre_px`; NaN where the curve leaves the view, the patch or positive disparity.
struct CurveSamples {
  int count = 0;
  std::vector<std::optional<Eigen::Vector2d>> knots;  // exact pixels every kKnot samples
  std::vector<float> score, distance;
};

CurveSamples SampleEpipolarCurve(const ReferencePatch& reference, const MatchView& view,
                                 const Eigen::Vector3d& centre_fixed, const Eigen::Vector3d& bearing_fixed,
                                 const Eigen::Vector3d& centre_moving, const Eigen::Vector3d& along,
                                 const Eigen::Vector3d& across, const Eigen::Vector2d& centre_px, double focal_px,
                                 double range_deg) {
  CurveSamples c;
  const double step = 1.0 / focal_px;
  const int half_steps = static_cast<int>(std::ceil(range_deg * M_PI / 180.0 / step / kKnot)) * kKnot;
  c.count = 2 * half_steps + 1;
  const auto direction = [&](int k) {
    const double angle = (k - half_steps) * step;
    return Eigen::Vector3d(std::cos(angle) * along + std::sin(angle) * across);
  };
  c.knots.resize(c.count / kKnot + 1);
  for (int k = 0; k < c.count; k += kKnot) {
    const Eigen::Vector3d d = direction(k);
    if (PositiveDisparity(centre_fixed, bearing_fixed, centre_moving, d))
      c.knots[k / kKnot] = view.pixel_from_direction_in_rig(d);
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  c.score.assign(c.count, nan);
  c.distance.assign(c.count, nan);
  for (int k = 0; k < c.count; ++k) {
    const int knot = k / kKnot;
    const auto& p0 = c.knots[knot];
    if (!p0) continue;
    Eigen::Vector2d px = *p0;
    if (k % kKnot != 0) {
      if (knot + 1 >= static_cast<int>(c.knots.size()) || !c.knots[knot + 1]) continue;
      const double t = static_cast<double>(k % kKnot) / kKnot;
      px = (1.0 - t) * *p0 + t * *c.knots[knot + 1];
    }
    const auto z = ZnccWithReference(reference, *view.image, px);
    if (!z) continue;
    c.score[k] = static_cast<float>(*z);
    c.distance[k] = static_cast<float>((px - centre_px).norm());
  }
  return c;
}

// Best ZNCC over the 3x3 pixels around px (a sampled peak may sit a pixel off the true one); -2: none.
double BestZnccAround(const ReferencePatch& reference, const cv::Mat& image, const Eigen::Vector2d& px) {
  double best = -2.0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if (const auto z = ZnccWithReference(reference, image, px + Eigen::Vector2d(dx, dy))) {
        best = std::max(best, *z);
      }
    }
  }
  return best;
}

}  // namespace

bool UniqueAlongEpipolarCurve(const cv::Mat& patch_image, cv::Point2f patch_centre, const Eigen::Vector3d& centre_fixed,
                              const Eigen::Vector3d& bearing_fixed, const MatchView& view,
                              const Eigen::Vector3d& centre_moving, const Eigen::Vector3d& bearing_moving,
                              double focal_px, const InterviewMatchOptions& options) {
  if (!view.pixel_from_direction_in_rig || view.image == nullptr) return true;
  ReferencePatch reference;
  if (options.zncc_patch_px > 45 ||  // keeps the integer sums of ZnccWithReference below 2^31
      !LoadReference(patch_image, Eigen::Vector2d(patch_centre.x, patch_centre.y), options.zncc_patch_px, &reference)) {
    return false;
  }
  // The plane through the baseline and the matched bearing: the epipolar plane of the fixed
  // feature when the extrinsics are right, and still through the match when they are off.
  Eigen::Vector3d normal = (centre_moving - centre_fixed).cross(bearing_moving);
  if (normal.norm() < 1e-12) return false;
  normal.normalize();
  const Eigen::Vector3d along = bearing_moving.normalized();
  const Eigen::Vector3d across = normal.cross(along);
  const auto centre_px = view.pixel_from_direction_in_rig(along);
  if (!centre_px) return false;
  const CurveSamples c = SampleEpipolarCurve(reference, view, centre_fixed, bearing_fixed, centre_moving, along, across,
                                             *centre_px, focal_px, options.uniqueness_range_deg);
  const std::vector<float>& score = c.score;
  const std::vector<float>& distance = c.distance;
  double z0 = BestZnccAround(reference, *view.image, *centre_px);
  for (int k = 0; k < c.count; ++k) {
    if (!std::isnan(score[k]) && distance[k] <= options.uniqueness_exclusion_px) z0 = std::max(z0, double(score[k]));
  }
  if (z0 < -1.0) return false;
  const double limit = z0 - options.uniqueness_margin;
  for (int k = 1; k + 1 < c.count; ++k) {
    if (std::isnan(score[k]) || std::isnan(score[k - 1]) || std::isnan(score[k + 1])) continue;
    if (distance[k] <= options.uniqueness_exclusion_px || score[k] < score[k - 1] || score[k] < score[k + 1]) continue;
    if (score[k] >= limit) return false;
    // Local maxima that could reach the limit are refined, when the refinement stays outside the
    // exclusion radius (1.5 px >= the 3x3 step).
    if (score[k] >= limit - 0.3 && distance[k] > options.uniqueness_exclusion_px + 1.5) {
      const int knot = k / kKnot;
      const double t = static_cast<double>(k % kKnot) / kKnot;
      const Eigen::Vector2d px =
          t == 0.0 ? *c.knots[knot] : Eigen::Vector2d((1.0 - t) * *c.knots[knot] + t * *c.knots[knot + 1]);
      if (BestZnccAround(reference, *view.image, px) >= limit) return false;
    }
  }
  return true;
}

double AngleDifferenceDeg(double a_deg, double b_deg) {
  double d = std::fmod(std::abs(a_deg - b_deg), 360.0);
  return d > 180.0 ? 360.0 - d : d;
}

namespace {

struct Candidate {
  int other = -1;
  int distance = std::numeric_limits<int>::max();
};

// Best and second-best admissible candidate per feature (by descriptor distance).
struct Best {
  Candidate first, second;
  void Offer(int other, int distance) {
    if (distance < first.distance) {
      second = first;
      first = {other, distance};
    } else if (distance < second.distance) {
      second = {other, distance};
    }
  }
};

}  // namespace

std::vector<InterviewMatch> MatchViews(const PairGeometry& pair, const MatchView& a, const MatchView& b,
                                       const InterviewMatchOptions& options) {
  options.Check();
  const std::vector<TrackedPoint>& pa = *a.points;
  const std::vector<TrackedPoint>& pb = *b.points;
  const int na = static_cast<int>(pa.size()), nb = static_cast<int>(pb.size());
  // Rectified y per feature (NaN when the feature faces away from the shared plane).
  const auto rectified = [&](const MatchView& view, int n) {
    std::vector<double> ys(n, std::numeric_limits<double>::quiet_NaN());
    for (int i = 0; i < n; ++i) {
      if (const auto y = RectifiedY(view.bearings_in_rig[i], pair.up_in_rig, pair.plane_normal_in_rig)) ys[i] = *y;
    }
    return ys;
  };
  const std::vector<double> ya = rectified(a, na), yb = rectified(b, nb);
  const double max_dy = options.max_y_distance_px / pair.focal_px;
  const double max_epipolar = options.max_epipolar_angle_deg * M_PI / 180.0;
  // Order b by rectified y so each a scans only the band |y_a - y_b| <= max_dy.
  std::vector<int> b_order;
  for (int j = 0; j < nb; ++j) {
    if (pb[j].has_descriptor && (!options.use_y_distance || !std::isnan(yb[j]))) b_order.push_back(j);
  }
  if (options.use_y_distance) {
    std::sort(b_order.begin(), b_order.end(), [&](int x, int y) { return yb[x] < yb[y]; });
  }
  std::vector<double> b_sorted_y;
  b_sorted_y.reserve(b_order.size());
  for (int j : b_order) b_sorted_y.push_back(options.use_y_distance ? yb[j] : 0.0);

  std::vector<Best> best_a(na), best_b(nb);
  for (int i = 0; i < na; ++i) {
    if (!pa[i].has_descriptor) continue;
    size_t begin = 0, end = b_order.size();
    if (options.use_y_distance) {
      if (std::isnan(ya[i])) continue;
      begin = std::lower_bound(b_sorted_y.begin(), b_sorted_y.end(), ya[i] - max_dy) - b_sorted_y.begin();
      end = std::upper_bound(b_sorted_y.begin(), b_sorted_y.end(), ya[i] + max_dy) - b_sorted_y.begin();
    }
    for (size_t k = begin; k < end; ++k) {
      const int j = b_order[k];
      if (AngleDifferenceDeg(pa[i].angle_deg, pb[j].angle_deg) > options.max_orientation_diff_deg) continue;
      const int distance = HammingDistance(pa[i].descriptor, pb[j].descriptor);
      if (distance > options.max_descriptor_distance) continue;
      if (EpipolarAngle(a.centre_in_rig, a.bearings_in_rig[i], b.centre_in_rig, b.bearings_in_rig[j]) > max_epipolar) {
        continue;
      }
      if (options.use_positive_disparity &&
          !PositiveDisparity(a.centre_in_rig, a.bearings_in_rig[i], b.centre_in_rig, b.bearings_in_rig[j]))
        continue;
      best_a[i].Offer(j, distance);
      best_b[j].Offer(i, distance);
    }
  }

  const auto passes_ratio = [&](const Best& best) {
    if (options.max_ratio >= 1.0 || best.second.other < 0) return true;
    return best.first.distance <= options.max_ratio * best.second.distance;
  };
  std::vector<InterviewMatch> matches;
  for (int i = 0; i < na; ++i) {
    const int j = best_a[i].first.other;
    if (j < 0 || !passes_ratio(best_a[i])) continue;
    if (options.use_mutual && (best_b[j].first.other != i || !passes_ratio(best_b[j]))) continue;
    InterviewMatch match{i, j, best_a[i].first.distance, 0.0};
    if (options.use_zncc) {
      const auto score = Zncc(*a.image, pa[i].px, *b.image, pb[j].px, options.zncc_patch_px);
      if (!score || *score < options.min_zncc) continue;
      match.zncc = *score;
      if (options.use_uniqueness &&
          (!UniqueAlongEpipolarCurve(*a.image, pa[i].px, a.centre_in_rig, a.bearings_in_rig[i], b, b.centre_in_rig,
                                     b.bearings_in_rig[j], pair.focal_px, options) ||
           !UniqueAlongEpipolarCurve(*b.image, pb[j].px, b.centre_in_rig, b.bearings_in_rig[j], a, a.centre_in_rig,
                                     a.bearings_in_rig[i], pair.focal_px, options))) {
        continue;
      }
    }
    matches.push_back(match);
  }
  return matches;
}

std::vector<std::optional<cv::Point2f>> RefineMatchPositions(const cv::Mat& image_from, const cv::Mat& image_to,
                                                             const std::vector<cv::Point2f>& from,
                                                             const std::vector<cv::Point2f>& to,
                                                             const SubpixelMatchOptions& options) {
  options.Check();
  if (from.size() != to.size()) throw std::invalid_argument("RefineMatchPositions: from and to differ in size");
  if (image_from.type() != CV_8UC1 || image_to.type() != CV_8UC1) {
    throw std::invalid_argument("RefineMatchPositions: images must be 8-bit gray");
  }
  std::vector<std::optional<cv::Point2f>> refined(to.size());
  const cv::Size window(options.window_px, options.window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, options.max_iterations,
                                  options.epsilon_px);
  // Equal-size patches around both points (the two views' images may differ in size); KLT on the
  // base level only: the start is within max_shift_px of the answer.
  const int half = options.window_px / 2 + static_cast<int>(std::ceil(options.max_shift_px)) + 2;
  const auto patch_at = [&](const cv::Mat& image, cv::Point2f centre, cv::Point* corner) -> std::optional<cv::Mat> {
    const int x0 = static_cast<int>(std::lround(centre.x)) - half, y0 = static_cast<int>(std::lround(centre.y)) - half;
    if (x0 < 0 || y0 < 0 || x0 + 2 * half + 1 > image.cols || y0 + 2 * half + 1 > image.rows) return std::nullopt;
    *corner = cv::Point(x0, y0);
    return image(cv::Rect(x0, y0, 2 * half + 1, 2 * half + 1)).clone();
  };
  const double max_shift2 = options.max_shift_px * options.max_shift_px;
  const double max_round2 = options.max_round_trip_px * options.max_round_trip_px;
  std::vector<cv::Point2f> start(1), forward(1), backward(1);
  std::vector<uint8_t> status_forward, status_backward;
  std::vector<float> error;
  for (size_t k = 0; k < to.size(); ++k) {
    cv::Point corner_from, corner_to;
    const auto patch_from = patch_at(image_from, from[k], &corner_from);
    const auto patch_to = patch_at(image_to, to[k], &corner_to);
    if (!patch_from || !patch_to) continue;
    const cv::Point2f offset_from(corner_from), offset_to(corner_to);
    start[0] = from[k] - offset_from;
    forward[0] = to[k] - offset_to;
    cv::calcOpticalFlowPyrLK(*patch_from, *patch_to, start, forward, status_forward, error, window, 0, criteria,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    if (!status_forward[0]) continue;
    backward[0] = start[0];
    cv::calcOpticalFlowPyrLK(*patch_to, *patch_from, forward, backward, status_backward, error, window, 0, criteria,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    if (!status_backward[0]) continue;
    const cv::Point2f result = forward[0] + offset_to;
    const cv::Point2f shift = result - to[k], round_trip = backward[0] - start[0];
    if (shift.dot(shift) > max_shift2 || round_trip.dot(round_trip) > max_round2) continue;
    refined[k] = result;
  }
  return refined;
}

}  // namespace rovo
