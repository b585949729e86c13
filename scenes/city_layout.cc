#include "scenes/city_layout.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "scenes/texture_gen.h"

namespace rovo {
namespace {

constexpr int kSamplesPerSpan = 16;
// Drive dynamics (m/s^2): comfortable urban driving.
constexpr double kMaxLateralAccel = 2.5;
constexpr double kMaxForwardAccel = 2.0;
constexpr double kMaxBrakeAccel = 2.5;
constexpr double kTurnSlowdown = 0.4;     // at least this fraction slower in a tight turn
constexpr double kTightTurnRadius = 8.0;  // metres
constexpr double kSpeedSmoothing = 4.0;   // Gaussian sigma over arc length, metres
constexpr double kMaxSpeed = 30.0;

const Eigen::Vector2i kDirs[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};

}  // namespace

uint64_t LayoutSeed(const std::string& preset, uint64_t seed) {
  const bool town = preset == "cloudy_urban" || preset == "sunset_urban" || preset == "night_street";
  return SubSeed(seed, town ? "town" : preset.c_str());
}

CityStyle StyleForPreset(const std::string& preset) {
  CityStyle s;
  if (preset == "dynamic_urban") {
    s.block_min_m = 110;
    s.block_max_m = 170;
    s.height_min_m = 10;
    s.height_max_m = 35;
    s.straight_preference = 0.7;
  } else if (preset == "cloudy_urban" || preset == "sunset_urban" || preset == "night_street") {
    s.block_min_m = 60;
    s.block_max_m = 90;
    s.height_min_m = 7;
    s.height_max_m = 22;
    s.straight_preference = 0.8;
  } else if (preset == "canyon_multifov") {
    s.block_min_m = 50;
    s.block_max_m = 80;
    s.road_width_m = 7.0;
    s.parking_lane_m = 0.0;
    s.sidewalk_width_m = 2.0;
    s.height_min_m = 25;
    s.height_max_m = 60;
    s.lot_width_min_m = 6;
    s.lot_width_max_m = 16;
    s.lot_depth_min_m = 12;
    s.lot_depth_max_m = 22;
    s.straight_preference = 0.6;
    s.trees = false;
    s.parked_cars = false;
    s.high_sun_along_streets = true;
  } else if (preset == "suburban_road") {
    // Wide lots with one low house each, far apart; no parking lane, few trees, sparse lights.
    s.block_min_m = 100;
    s.block_max_m = 150;
    s.road_width_m = 7.5;
    s.parking_lane_m = 0.0;
    s.sidewalk_width_m = 2.0;
    s.lot_width_min_m = 20;
    s.lot_width_max_m = 30;
    s.lot_depth_min_m = 20;
    s.lot_depth_max_m = 24;
    s.straight_preference = 0.8;
    s.parked_cars = false;
    s.tree_probability = 0.2;
    s.light_spacing_m = 40.0;
    s.houses = true;
    s.facade_textures = 6;
    s.storefront_textures = 0;
  }
  return s;
}

bool StreetGrid::OnRoad(const Eigen::Vector2d& p, double margin) const {
  const double half = 0.5 * road_width_m - margin;
  const bool in_x = p.x() >= MinX() - half && p.x() <= MaxX() + half;
  const bool in_y = p.y() >= MinY() - half && p.y() <= MaxY() + half;
  for (double x : xs)
    if (std::abs(p.x() - x) <= half && in_y) return true;
  for (double y : ys)
    if (std::abs(p.y() - y) <= half && in_x) return true;
  return false;
}

bool CityLayout::InsideBuilding(const Eigen::Vector2d& p, double margin) const {
  for (const BuildingPlan& b : buildings)
    if (b.footprint.Contains(p, margin)) return true;
  return false;
}

// ---- LanePath: uniform cubic B-spline --------------------------------------------------------
//   p(u) = sum_k B_k(u) P_{i+k}, u in [0, 1) on span i, with
//   B_0 = (1-u)^3/6, B_1 = (3u^3 - 6u^2 + 4)/6, B_2 = (-3u^3 + 3u^2 + 3u + 1)/6, B_3 = u^3/6.

LanePath::LanePath(std::vector<Eigen::Vector2d> control_points) : control_(std::move(control_points)) {
  if (control_.size() < 4) throw std::invalid_argument("LanePath: needs at least 4 control points");
  const int spans = static_cast<int>(control_.size()) - 3;
  const int n = spans * kSamplesPerSpan;
  s_.resize(n + 1);
  param_.resize(n + 1);
  Eigen::Vector2d prev;
  for (int k = 0; k <= n; ++k) {
    param_[k] = static_cast<double>(k) / kSamplesPerSpan;
    Eigen::Vector2d p;
    Eval(param_[k], &p, nullptr, nullptr);
    s_[k] = k == 0 ? 0.0 : s_[k - 1] + (p - prev).norm();
    prev = p;
  }
}

void LanePath::Eval(double param, Eigen::Vector2d* p, Eigen::Vector2d* d1, Eigen::Vector2d* d2) const {
  const int spans = static_cast<int>(control_.size()) - 3;
  int i = std::clamp(static_cast<int>(std::floor(param)), 0, spans - 1);
  const double u = std::clamp(param - i, 0.0, 1.0);
  const Eigen::Vector2d& a = control_[i];
  const Eigen::Vector2d& b = control_[i + 1];
  const Eigen::Vector2d& c = control_[i + 2];
  const Eigen::Vector2d& d = control_[i + 3];
  const double u2 = u * u, u3 = u2 * u, m = 1.0 - u;
  if (p) *p = (m * m * m * a + (3 * u3 - 6 * u2 + 4) * b + (-3 * u3 + 3 * u2 + 3 * u + 1) * c + u3 * d) / 6.0;
  if (d1) *d1 = (-m * m * a + (3 * u2 - 4 * u) * b + (-3 * u2 + 2 * u + 1) * c + u2 * d) / 2.0;
  if (d2) *d2 = m * a + (3 * u - 2) * b + (-3 * u + 1) * c + u * d;
}

double LanePath::ParamAt(double s) const {
  s = std::clamp(s, 0.0, Length());
  const auto it = std::upper_bound(s_.begin(), s_.end(), s);
  const size_t k = std::clamp<size_t>(static_cast<size_t>(it - s_.begin()), 1, s_.size() - 1);
  const double span = s_[k] - s_[k - 1];
  const double alpha = span > 0 ? (s - s_[k - 1]) / span : 0.0;
  return param_[k - 1] + alpha * (param_[k] - param_[k - 1]);
}

Eigen::Vector2d LanePath::Position(double s) const {
  Eigen::Vector2d p;
  Eval(ParamAt(s), &p, nullptr, nullptr);
  return p;
}

double LanePath::Heading(double s) const {
  Eigen::Vector2d d1;
  Eval(ParamAt(s), nullptr, &d1, nullptr);
  return std::atan2(d1.y(), d1.x());
}

double LanePath::Curvature(double s) const {
  Eigen::Vector2d d1, d2;
  Eval(ParamAt(s), nullptr, &d1, &d2);
  const double n = d1.norm();
  return (d1.x() * d2.y() - d1.y() * d2.x()) / (n * n * n);
}

// ---- routes ------------------------------------------------------------------------------------

GridRoute RandomRoute(const StreetGrid& grid, SceneRng& rng, double min_length_m, double straight_preference,
                      Eigen::Vector2i start, int start_dir) {
  const int nx = static_cast<int>(grid.xs.size()), ny = static_cast<int>(grid.ys.size());
  auto valid = [&](const Eigen::Vector2i& n) { return n.x() >= 0 && n.y() >= 0 && n.x() < nx && n.y() < ny; };
  auto edge_key = [&](const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
    const int ia = a.y() * nx + a.x(), ib = b.y() * nx + b.x();
    return std::min(ia, ib) * nx * ny + std::max(ia, ib);
  };
  std::vector<int> used(static_cast<size_t>(nx * ny * nx * ny), 0);
  GridRoute route{start};
  int dir = start_dir;
  if (!valid(start + kDirs[dir])) {
    for (int d = 0; d < 4; ++d)
      if (valid(start + kDirs[d])) dir = d;
  }
  double length = 0;
  route.push_back(start + kDirs[dir]);
  length += (grid.Node(route[1].x(), route[1].y()) - grid.Node(start.x(), start.y())).norm();
  used[edge_key(route[0], route[1])]++;
  while (length < min_length_m) {
    const Eigen::Vector2i cur = route.back();
    double weights[4] = {0, 0, 0, 0}, total = 0;
    for (int d = 0; d < 4; ++d) {
      if (d == (dir + 2) % 4 || !valid(cur + kDirs[d])) continue;
      double w = d == dir ? straight_preference : 0.5 * (1.0 - straight_preference);
      w /= 1.0 + 6.0 * used[edge_key(cur, cur + kDirs[d])];
      weights[d] = w;
      total += w;
    }
    assert(total > 0);  // a grid of >= 2x2 nodes always has a non-reversing exit
    double pick = rng.Uniform() * total;
    int next = -1;
    for (int d = 0; d < 4; ++d) {
      if (weights[d] <= 0) continue;
      next = d;
      pick -= weights[d];
      if (pick < 0) break;
    }
    dir = next;
    const Eigen::Vector2i n = cur + kDirs[dir];
    used[edge_key(cur, n)]++;
    length += (grid.Node(n.x(), n.y()) - grid.Node(cur.x(), cur.y())).norm();
    route.push_back(n);
  }
  return route;
}

LanePath PathAlongRoute(const StreetGrid& grid, const GridRoute& route, double lane_offset_m) {
  assert(route.size() >= 2);
  std::vector<Eigen::Vector2d> nodes;
  for (const auto& n : route) nodes.push_back(grid.Node(n.x(), n.y()));
  // Offset polyline: the corner of two offset lines is p + o (r_in + r_out) / (1 + r_in . r_out).
  std::vector<Eigen::Vector2d> offset(nodes.size()), dir_in(nodes.size()), dir_out(nodes.size());
  for (size_t k = 0; k < nodes.size(); ++k) {
    dir_in[k] = (nodes[k > 0 ? k : 1] - nodes[k > 0 ? k - 1 : 0]).normalized();
    dir_out[k] = (k + 1 < nodes.size()) ? (nodes[k + 1] - nodes[k]).normalized() : dir_in[k];
    const Eigen::Vector2d r_in(dir_in[k].y(), -dir_in[k].x()), r_out(dir_out[k].y(), -dir_out[k].x());
    offset[k] = nodes[k] + lane_offset_m * (r_in + r_out) / (1.0 + r_in.dot(r_out));
  }
  // Turn radii: a right turn keeps its arc's midpoint >= kTurnCurbClearance inside the curb lines,
  // i.e. o + R (1 - 1/sqrt(2)) <= w/2 - clearance; a left turn is concentric (R + 2 o).
  const double k45 = 1.0 - 1.0 / std::sqrt(2.0);
  const double r_right =
      std::clamp((0.5 * grid.road_width_m - kTurnCurbClearance - std::abs(lane_offset_m)) / k45, 2.0, 6.0);
  const double r_left = r_right + 2.0 * std::abs(lane_offset_m);
  // Line-arc-line polyline (C1), densely sampled.
  std::vector<Eigen::Vector2d> dense{offset.front()};
  for (size_t k = 1; k + 1 < offset.size(); ++k) {
    const Eigen::Vector2d& din = dir_in[k];
    const Eigen::Vector2d& dout = dir_out[k];
    const double cross = din.x() * dout.y() - din.y() * dout.x();
    const double angle = std::atan2(std::abs(cross), din.dot(dout));
    if (angle < 1e-6) {
      dense.push_back(offset[k]);
      continue;
    }
    const bool left = (cross > 0) == (lane_offset_m >= 0);
    double radius = left ? r_left : r_right;
    const double room = 0.45 * std::min((offset[k] - offset[k - 1]).norm(), (offset[k + 1] - offset[k]).norm());
    radius = std::min(radius, room / std::tan(0.5 * angle));
    const double tangent = radius * std::tan(0.5 * angle);
    const Eigen::Vector2d a = offset[k] - tangent * din;
    const Eigen::Vector2d normal = cross > 0 ? Eigen::Vector2d(-din.y(), din.x()) : Eigen::Vector2d(din.y(), -din.x());
    const Eigen::Vector2d centre = a + radius * normal;
    const int steps = std::max(4, static_cast<int>(std::ceil(radius * angle / 0.2)));
    for (int i = 0; i <= steps; ++i) {
      const double phi = (cross > 0 ? 1.0 : -1.0) * angle * i / steps;
      const Eigen::Vector2d rel = a - centre;
      dense.push_back(centre + Eigen::Vector2d(std::cos(phi) * rel.x() - std::sin(phi) * rel.y(),
                                               std::sin(phi) * rel.x() + std::cos(phi) * rel.y()));
    }
  }
  dense.push_back(offset.back());
  // Control points every kControlSpacing metres of arc length along it.
  std::vector<Eigen::Vector2d> control{dense.front()};
  double carry = 0;
  for (size_t k = 0; k + 1 < dense.size(); ++k) {
    const Eigen::Vector2d a = dense[k], b = dense[k + 1];
    const double len = (b - a).norm();
    double at = kControlSpacing - carry;
    while (at <= len) {
      control.push_back(a + (b - a) * (at / len));
      at += kControlSpacing;
    }
    carry = len - (at - kControlSpacing);
  }
  return LanePath(std::move(control));
}

// ---- drive timing ------------------------------------------------------------------------------

namespace {

// Arc length sampled every `ds` metres over [lo_s, hi_s], with the path's |curvature| dilated by the
// speed smoothing radius and the Gaussian kernel that smooths the speed.
struct DriveGrid {
  double ds = 0.25, lo_s = 0.0;
  int n = 0, half = 0;  // samples; kernel half-width in samples
  std::vector<double> grid_s, curv, kernel;
};

DriveGrid MakeDriveGrid(const LanePath& path, double lo_s, double hi_s) {
  DriveGrid g;
  const double ds = g.ds;
  g.lo_s = lo_s;
  const int n = g.n = static_cast<int>(std::ceil((hi_s - lo_s) / ds)) + 1;
  std::vector<double>&grid_s = g.grid_s, &curv = g.curv;
  grid_s.resize(n);
  curv.resize(n);
  for (int i = 0; i < n; ++i) {
    grid_s[i] = std::min(hi_s, lo_s + i * ds);
    curv[i] = std::abs(path.Curvature(grid_s[i]));
  }
  const int half = g.half = static_cast<int>(std::ceil(3 * kSpeedSmoothing / ds));
  // Dilate |curvature| by the smoothing radius: the speed cap is then flat over each turn and the
  // Gaussian smoothing below cannot raise the speed inside a turn above the cap.
  {
    const int reach = 2 * half / 3;  // 2 sigma: the kernel's tails beyond carry 5% of its weight
    std::vector<double> dilated(n, 0.0);
    for (int i = 0; i < n; ++i)
      for (int k = std::max(0, i - reach); k <= std::min(n - 1, i + reach); ++k)
        dilated[i] = std::max(dilated[i], curv[k]);
    curv.swap(dilated);
  }
  g.kernel.resize(2 * half + 1);
  for (int k = -half; k <= half; ++k) g.kernel[k + half] = std::exp(-0.5 * std::pow(k * ds / kSpeedSmoothing, 2));
  return g;
}

// Speed per grid sample for a top speed: capped in turns and by lateral acceleration, limited by
// the forward and braking accelerations, then Gaussian-smoothed.
std::vector<double> Speeds(const DriveGrid& g, double top) {
  const int n = g.n, half = g.half;
  const double ds = g.ds;
  const std::vector<double>&curv = g.curv, &kernel = g.kernel;
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) {
    const double tight = std::clamp(curv[i] * kTightTurnRadius, 0.0, 1.0);
    v[i] = std::min(top * (1.0 - kTurnSlowdown * tight), std::sqrt(kMaxLateralAccel / std::max(curv[i], 1e-9)));
  }
  for (int i = 1; i < n; ++i) v[i] = std::min(v[i], std::sqrt(v[i - 1] * v[i - 1] + 2 * kMaxForwardAccel * ds));
  for (int i = n - 2; i >= 0; --i) v[i] = std::min(v[i], std::sqrt(v[i + 1] * v[i + 1] + 2 * kMaxBrakeAccel * ds));
  std::vector<double> smooth(n);
  for (int i = 0; i < n; ++i) {
    double sum = 0, wsum = 0;
    for (int k = -half; k <= half; ++k) {
      const int j = std::clamp(i + k, 0, n - 1);
      sum += kernel[k + half] * v[j];
      wsum += kernel[k + half];
    }
    smooth[i] = sum / wsum;
  }
  return smooth;
}

// Cumulative time from the grid's start (trapezoid on 1/v).
std::vector<double> Times(const DriveGrid& g, const std::vector<double>& v) {
  const int n = g.n;
  const std::vector<double>& grid_s = g.grid_s;
  std::vector<double> t(n, 0.0);
  for (int i = 1; i < n; ++i) t[i] = t[i - 1] + (grid_s[i] - grid_s[i - 1]) * 0.5 * (1.0 / v[i] + 1.0 / v[i - 1]);
  return t;
}

// Time at arc length s, interpolated in the grid.
double TimeAt(const DriveGrid& g, const std::vector<double>& t, double s) {
  const int n = g.n;
  const std::vector<double>& grid_s = g.grid_s;
  const double x = (s - g.lo_s) / g.ds;
  const int i = std::clamp(static_cast<int>(std::floor(x)), 0, n - 2);
  const double a = std::clamp((s - grid_s[i]) / std::max(1e-12, grid_s[i + 1] - grid_s[i]), 0.0, 1.0);
  return t[i] + a * (t[i + 1] - t[i]);
}

// Samples arc length, speed and longitudinal acceleration at each frame: frame f at time
// t0 + f / frame_rate * scale on the grid's clock, speeds divided by `scale`.
void SampleDrive(const DriveGrid& g, const std::vector<double>& v, const std::vector<double>& t, double t0,
                 double scale, int frames, double frame_rate, DriveProfile* profile) {
  const int n = g.n;
  const std::vector<double>& grid_s = g.grid_s;
  profile->s.assign(frames, 0.0);
  profile->speed.assign(frames, 0.0);
  profile->accel_longitudinal.assign(frames, 0.0);
  int i = 0;
  for (int f = 0; f < frames; ++f) {
    const double target = t0 + f / frame_rate * scale;
    while (i < n - 2 && t[i + 1] < target) ++i;
    const double a = std::clamp((target - t[i]) / std::max(1e-12, t[i + 1] - t[i]), 0.0, 1.0);
    profile->s[f] = grid_s[i] + a * (grid_s[i + 1] - grid_s[i]);
    profile->speed[f] = (v[i] + a * (v[i + 1] - v[i])) / scale;
    profile->accel_longitudinal[f] =
        profile->speed[f] * (v[i + 1] - v[i]) / (scale * std::max(1e-12, grid_s[i + 1] - grid_s[i]));
  }
}

}  // namespace

bool PlanDrive(const LanePath& path, double s_begin, double length, int frames, double frame_rate,
               DriveProfile* profile) {
  const double pad = 4 * kSpeedSmoothing;
  const double lo_s = std::max(0.0, s_begin - pad), hi_s = std::min(path.Length(), s_begin + length + pad);
  if (s_begin < 0 || s_begin + length > path.Length()) return false;
  const DriveGrid g = MakeDriveGrid(path, lo_s, hi_s);
  const double duration = (frames - 1) / frame_rate;
  auto drive_time = [&](double top) {
    const std::vector<double> t = Times(g, Speeds(g, top));
    return TimeAt(g, t, s_begin + length) - TimeAt(g, t, s_begin);
  };
  // Bisect the top speed so that the drive takes `duration`.
  double lo = 0.05, hi = kMaxSpeed;
  if (drive_time(hi) > duration) return false;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (drive_time(mid) > duration ? lo : hi) = mid;
  }
  const std::vector<double> v = Speeds(g, hi);
  const std::vector<double> t = Times(g, v);
  const double t0 = TimeAt(g, t, s_begin);
  // Rescale time so the last frame lands exactly at s_begin + length.
  const double scale = (TimeAt(g, t, s_begin + length) - t0) / duration;
  SampleDrive(g, v, t, t0, scale, frames, frame_rate, profile);
  profile->s.front() = s_begin;
  profile->s.back() = s_begin + length;
  return true;
}

// ---- layout ------------------------------------------------------------------------------------

double QuickPathLength(const ScenePreset& preset) {
  return preset.path_length_m * (preset.quick_frames - 1) / std::max(1, preset.frames - 1);
}

namespace {

// Facade texture counts of a preset's style (GenerateScene makes the same numbers).
struct FacadeCounts {
  int facades = 0, storefronts = 0;
  uint64_t texture_seed = 0;
};

// One building on the lot [a, b] of strip `side` (0 south, 1 north, 2 west, 3 east) of `lots`.
BuildingPlan PlanBuilding(const CityStyle& st, const Box2& lots, int side, double a, double b, double depth,
                          const FacadeCounts& counts, SceneRng& rng) {
  const bool along_x = side < 2;
  const double d = depth * rng.Uniform(0.7, 1.0);
  BuildingPlan p;
  switch (side) {
    case 0:
      p.footprint = {{a, lots.min.y()}, {b, lots.min.y() + d}}, p.facing = {0, -1};
      break;
    case 1:
      p.footprint = {{a, lots.max.y() - d}, {b, lots.max.y()}}, p.facing = {0, 1};
      break;
    case 2:
      p.footprint = {{lots.min.x(), a}, {lots.min.x() + d, b}}, p.facing = {-1, 0};
      break;
    default:
      p.footprint = {{lots.max.x() - d, a}, {lots.max.x(), b}}, p.facing = {1, 0};
      break;
  }
  static const Eigen::Vector3f kPalette[] = {{1.0f, 0.93f, 0.8f}, {0.95f, 0.7f, 0.55f}, {0.85f, 0.85f, 0.85f},
                                             {0.8f, 0.88f, 1.0f}, {1.0f, 0.85f, 0.55f}, {1.0f, 1.0f, 1.0f},
                                             {0.75f, 0.6f, 0.5f}, {0.9f, 1.0f, 0.85f},  {1.0f, 0.8f, 0.8f}};
  // Whole storeys: a 4 m shop floor, 3.2 m upper floors, a 0.4 m parapet.
  const double h = rng.Uniform(st.height_min_m, st.height_max_m) * (rng.Bernoulli(0.1) ? 1.5 : 1.0);
  p.height = kStorefrontHeightMetres +
             std::max(1L, std::lround((h - kStorefrontHeightMetres) / kFloorHeightMetres)) * kFloorHeightMetres + 0.4;
  p.facade = rng.UniformInt(0, counts.facades - 1);
  p.storefront = rng.UniformInt(0, counts.storefronts - 1);
  const Eigen::Vector3f base = kPalette[rng.UniformInt(0, 8)];
  for (int c = 0; c < 3; ++c) p.tint[c] = std::min(1.0f, base[c] * static_cast<float>(rng.Uniform(0.85, 1.08)));
  const int bays = FacadeBays(counts.texture_seed, p.facade);
  p.u_offset = rng.UniformInt(0, bays - 1) * kFacadeTileMetres / bays;
  if (p.height > 12 && rng.Bernoulli(0.3)) {
    p.has_setback = true;
    Box2 up = p.footprint;
    const double back = rng.Uniform(2.0, 4.0);
    // Step back from the street side; keep 1 m from the lot's side walls.
    if (p.facing.x() < 0) up.min.x() += back;
    if (p.facing.x() > 0) up.max.x() -= back;
    if (p.facing.y() < 0) up.min.y() += back;
    if (p.facing.y() > 0) up.max.y() -= back;
    if (along_x)
      up.min.x() += 1.0, up.max.x() -= 1.0;
    else
      up.min.y() += 1.0, up.max.y() -= 1.0;
    p.upper_footprint = up;
    p.upper_height = p.height + rng.UniformInt(1, 3) * kFloorHeightMetres;
    if ((up.max - up.min).minCoeff() < 3.0) p.has_setback = false;
  }
  return p;
}

// One detached house on the lot [a, b] of strip `side` (as PlanBuilding) whose strip is `depth`
// deep: house_width wide, centred in the lot with some jitter, set back from the lot's street edge.
BuildingPlan PlanHouse(const CityStyle& st, const Box2& lots, int side, double a, double b, double depth,
                       const FacadeCounts& counts, SceneRng& rng) {
  const double width = std::min(b - a - 4.0, rng.Uniform(st.house_width_min_m, st.house_width_max_m));
  const double slack = b - a - width;
  const double a0 = a + slack * rng.Uniform(0.3, 0.7), a1 = a0 + width;
  const double setback = rng.Uniform(st.setback_min_m, st.setback_max_m);
  const double deep = std::min(depth - setback - 1.0, rng.Uniform(st.house_depth_min_m, st.house_depth_max_m));
  const double n0 = setback, n1 = setback + deep;  // distances from the street edge of the strip
  BuildingPlan p;
  p.house = true;
  switch (side) {
    case 0:
      p.footprint = {{a0, lots.min.y() + n0}, {a1, lots.min.y() + n1}}, p.facing = {0, -1};
      break;
    case 1:
      p.footprint = {{a0, lots.max.y() - n1}, {a1, lots.max.y() - n0}}, p.facing = {0, 1};
      break;
    case 2:
      p.footprint = {{lots.min.x() + n0, a0}, {lots.min.x() + n1, a1}}, p.facing = {-1, 0};
      break;
    default:
      p.footprint = {{lots.max.x() - n1, a0}, {lots.max.x() - n0, a1}}, p.facing = {1, 0};
      break;
  }
  static const Eigen::Vector3f kHouseColours[] = {{0.92f, 0.9f, 0.84f},  {0.85f, 0.8f, 0.7f},   {0.8f, 0.84f, 0.86f},
                                                  {0.93f, 0.88f, 0.78f}, {0.75f, 0.78f, 0.72f}, {0.95f, 0.95f, 0.93f}};
  p.height = rng.Bernoulli(0.6) ? 2 * kHouseStoreyMetres : kHouseStoreyMetres;
  p.facade = rng.UniformInt(0, counts.facades - 1);
  p.tint = kHouseColours[rng.UniformInt(0, 5)];
  return p;
}

// Blocks between the street lines `ex` x `ey` (block edges) and their buildings: four strips of
// lots per block; south and north span the full width, west and east fill between them.
void PlanBlocks(CityLayout* L, const std::vector<double>& ex, const std::vector<double>& ey, const FacadeCounts& counts,
                SceneRng& rng) {
  const CityStyle& st = L->style;
  const double hw = 0.5 * st.road_width_m;
  for (size_t bx = 0; bx + 1 < ex.size(); ++bx) {
    for (size_t by = 0; by + 1 < ey.size(); ++by) {
      Box2 block{{ex[bx] + hw, ey[by] + hw}, {ex[bx + 1] - hw, ey[by + 1] - hw}};
      L->blocks.push_back(block);
      const Box2 lots{block.min.array() + st.sidewalk_width_m, block.max.array() - st.sidewalk_width_m};
      const Eigen::Vector2d size = lots.max - lots.min;
      const double depth = std::min(rng.Uniform(st.lot_depth_min_m, st.lot_depth_max_m), 0.5 * size.minCoeff() - 0.5);
      for (int side = 0; side < 4; ++side) {
        const bool along_x = side < 2;
        const double a0 = along_x ? lots.min.x() : lots.min.y() + depth;
        const double a1 = along_x ? lots.max.x() : lots.max.y() - depth;
        double a = a0;
        while (a1 - a > 1.0) {
          double w = rng.Uniform(st.lot_width_min_m, st.lot_width_max_m);
          if (a1 - (a + w) < st.lot_width_min_m) w = a1 - a;
          const double b = a + w;
          if (st.houses) {
            if (w > 12.0) L->buildings.push_back(PlanHouse(st, lots, side, a, b, depth, counts, rng));
            a = b;
            continue;
          }
          const bool gap = st.trees && rng.Bernoulli(0.07);
          const BuildingPlan p = PlanBuilding(st, lots, side, a, b, depth, counts, rng);
          if (!gap && w > 2.0) L->buildings.push_back(p);
          a = b;
        }
      }
    }
  }
}

// The rig's drive: start near the centre; retry routes until the timing is feasible.
void PlanRigDrive(CityLayout* L, int streets, double length, double tail, double first_edge, int frames,
                  SceneRng& rng) {
  const CityStyle& st = L->style;
  const StreetGrid& g = L->grid;
  const Eigen::Vector2i centre(streets / 2, streets / 2);
  for (int attempt = 0; attempt < 50; ++attempt) {
    const int dir = rng.UniformInt(0, 3);
    L->route = RandomRoute(g, rng, length + tail + first_edge, st.straight_preference, centre, dir);
    L->rig_path = PathAlongRoute(g, L->route, 0.5 * (st.road_width_m - 2 * st.parking_lane_m) * 0.5);
    // Start 12 m after the first intersection (short quick drives then stay on one straight block).
    L->path_begin_s = 12.0;
    if (L->path_begin_s + length + tail > L->rig_path.Length()) continue;
    if (PlanDrive(L->rig_path, L->path_begin_s, length, frames, L->preset.frame_rate, &L->drive)) break;
    L->drive.s.clear();
  }
  if (L->drive.s.empty()) throw std::runtime_error("MakeCityLayout: no feasible drive for preset " + L->preset.name);
}

// Rig poses: yaw along the path, body roll/pitch from the accelerations, small vibrations.
void MakeRigTrajectory(CityLayout* L, uint64_t seed, int frames) {
  SceneRng vib(SubSeed(seed, "vibration"));
  double amp[6], freq[6], phase[6];
  for (int k = 0; k < 6; ++k) {
    amp[k] = vib.Uniform(0.05, 0.12);  // degrees
    freq[k] = vib.Uniform(0.3, 1.3);   // Hz
    phase[k] = vib.Uniform(0, 2 * M_PI);
  }
  const double bob_freq = vib.Uniform(0.8, 1.2), bob_phase = vib.Uniform(0, 2 * M_PI);
  L->trajectory.resize(frames);
  for (int f = 0; f < frames; ++f) {
    const double t = f / L->preset.frame_rate, s = L->drive.s[f];
    const Eigen::Vector2d xy = L->rig_path.Position(s);
    const double yaw = L->rig_path.Heading(s);
    const double v = L->drive.speed[f];
    const double lateral = v * v * L->rig_path.Curvature(s);
    double roll = 0.3 * lateral, pitch = -0.3 * L->drive.accel_longitudinal[f];
    for (int k = 0; k < 3; ++k) roll += amp[k] * std::sin(2 * M_PI * freq[k] * t + phase[k]);
    for (int k = 3; k < 6; ++k) pitch += amp[k] * std::sin(2 * M_PI * freq[k] * t + phase[k]);
    const double z = kRigHeight + 0.004 * std::sin(2 * M_PI * bob_freq * t + bob_phase);
    StampedPose& p = L->trajectory[f];
    p.timestamp = t;
    p.world_from_rig =
        Rigid3(QuaternionFromRollPitchYawDeg(roll, pitch, yaw * 180.0 / M_PI), Eigen::Vector3d(xy.x(), xy.y(), z));
  }
}

}  // namespace

CityLayout MakeCityLayout(const ScenePreset& preset, uint64_t seed, bool quick) {
  CityLayout L;
  L.preset = preset;
  L.style = StyleForPreset(preset.name);
  L.quick = quick;
  const CityStyle& st = L.style;
  const uint64_t layout_seed = LayoutSeed(preset.name, seed);
  SceneRng rng(SubSeed(layout_seed, "plan"));

  const int frames = quick ? preset.quick_frames : preset.frames;
  const double length = quick ? QuickPathLength(preset) : preset.path_length_m;
  const double tail = 80.0;  // path beyond the last frame (lead vehicles drive there)
  const double avg_block = 0.5 * (st.block_min_m + st.block_max_m) + st.road_width_m;
  const double need = (length + tail + avg_block) * 1.5 / avg_block;
  int streets = st.grid_streets_min;
  while (streets * (streets - 1) < need) ++streets;
  if (quick) streets = 5;  // the centre node's neighbours are inner nodes, so a quick drive can go straight

  StreetGrid& g = L.grid;
  g.road_width_m = st.road_width_m;
  g.sidewalk_width_m = st.sidewalk_width_m;
  g.parking_lane_m = st.parking_lane_m;
  for (auto* axis : {&g.xs, &g.ys}) {
    axis->push_back(0.0);
    for (int i = 1; i < streets; ++i)
      axis->push_back(axis->back() + st.road_width_m + rng.Uniform(st.block_min_m, st.block_max_m));
  }

  // Blocks: between streets, plus one ring outside (whose outer side faces open ground).
  auto edges = [&](const std::vector<double>& axis) {
    std::vector<double> e;
    e.push_back(axis.front() - st.road_width_m - rng.Uniform(st.block_min_m, st.block_max_m));
    e.insert(e.end(), axis.begin(), axis.end());
    e.push_back(axis.back() + st.road_width_m + rng.Uniform(st.block_min_m, st.block_max_m));
    return e;
  };
  const std::vector<double> ex = edges(g.xs), ey = edges(g.ys);
  FacadeCounts counts;
  counts.facades = quick ? std::max(4, st.facade_textures / 3) : st.facade_textures;
  counts.storefronts = quick ? std::max(3, st.storefront_textures / 2) : st.storefront_textures;
  counts.texture_seed = SubSeed(layout_seed, "textures");
  PlanBlocks(&L, ex, ey, counts, rng);

  PlanRigDrive(&L, streets, length, tail, avg_block, frames, rng);
  MakeRigTrajectory(&L, seed, frames);
  L.path_length_m = PathLength(L.trajectory);
  return L;
}

}  // namespace rovo
