#include "scenes/city.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "datasets/io.h"
#include "scenes/city_layout.h"
#include "scenes/rng.h"
#include "scenes/texture_gen.h"
#include "tests/scenes/scratch_dir.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;

using test::FreshDir;

TEST(ScenePresets, TableOneOrderAndLookup) {
  const auto& presets = ScenePresets();
  ASSERT_EQ(presets.size(), 5u);
  EXPECT_EQ(presets[0].name, "static_urban");
  EXPECT_EQ(presets[0].frames, 3000);
  EXPECT_EQ(presets[1].name, "dynamic_urban");
  EXPECT_TRUE(presets[1].traffic);
  EXPECT_EQ(FindScenePreset("sunset_urban").lighting, SceneLighting::kSunset);
  EXPECT_EQ(FindScenePreset("cloudy_urban").lighting, SceneLighting::kCloudy);
  try {
    FindScenePreset("nope");
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("canyon_multifov"), std::string::npos) << e.what();
  }
}

TEST(GenerateScene, SameSeedSameHashAndBytes) {
  const Scene a = GenerateScene("dynamic_urban", 7, true);
  const Scene b = GenerateScene("dynamic_urban", 7, true);
  EXPECT_EQ(SceneHash(a), SceneHash(b));
  const std::string da = FreshDir("det_a"), db = FreshDir("det_b");
  SaveScene(a, da);
  SaveScene(b, db);
  for (const char* f :
       {"scene.json", "geometry.bin", "motion.bin", "trajectory.tum", "textures/000.png", "textures/012.png"}) {
    EXPECT_EQ(ReadFile(da + "/" + f), ReadFile(db + "/" + f)) << f;
  }
  // The saved scene loads back to the same content.
  EXPECT_EQ(SceneHash(LoadScene(da)), SceneHash(a));
  EXPECT_EQ(a.metadata.seed, 7u);
  EXPECT_EQ(a.metadata.preset, "dynamic_urban");
  EXPECT_FALSE(a.metadata.generator_version.empty());
}

TEST(GenerateScene, DifferentSeedsDiffer) {
  const Scene a = GenerateScene("cloudy_urban", 1, true);
  const Scene b = GenerateScene("cloudy_urban", 2, true);
  EXPECT_NE(SceneHash(a), SceneHash(b));
  EXPECT_NE(a.textures[0].rgb, b.textures[0].rgb);
  EXPECT_NE(a.meshes.size() > 0 ? a.meshes.back().positions : std::vector<Eigen::Vector3f>{},
            b.meshes.size() > 0 ? b.meshes.back().positions : std::vector<Eigen::Vector3f>{});
  const CityLayout la = MakeCityLayout(FindScenePreset("static_urban"), 1, false);
  const CityLayout lb = MakeCityLayout(FindScenePreset("static_urban"), 2, false);
  EXPECT_NE(la.grid.xs, lb.grid.xs);
  EXPECT_GT((la.trajectory.back().world_from_rig.translation - lb.trajectory.back().world_from_rig.translation).norm(),
            1.0);
}

TEST(GenerateScene, CloudyAndSunsetShareStreets) {
  const Scene cloudy = GenerateScene("cloudy_urban", 3, true);
  const Scene sunset = GenerateScene("sunset_urban", 3, true);
  ASSERT_EQ(cloudy.meshes.size(), sunset.meshes.size());
  for (size_t i = 0; i < cloudy.meshes.size(); ++i) EXPECT_EQ(cloudy.meshes[i].positions, sunset.meshes[i].positions);
  ASSERT_EQ(cloudy.rig_trajectory.size(), sunset.rig_trajectory.size());
  EXPECT_EQ(cloudy.rig_trajectory.back().world_from_rig.translation,
            sunset.rig_trajectory.back().world_from_rig.translation);
  EXPECT_NE(SceneHash(cloudy), SceneHash(sunset));
  // Overcast: weak sun, bright sky; sunset: low sun.
  EXPECT_LT(cloudy.lighting.sun_radiance.maxCoeff(), 0.2f * sunset.lighting.sun_radiance.maxCoeff());
  EXPECT_GT(cloudy.lighting.ambient, 2.0f * sunset.lighting.ambient);
  const Eigen::Vector3d sun = sunset.lighting.direction_to_sun.normalized();
  EXPECT_LT(std::asin(sun.z()) * 180 / M_PI, 12.0);
  EXPECT_GT(std::asin(sun.z()) * 180 / M_PI, 3.0);
  EXPECT_GT(sunset.lighting.sun_radiance.x(), 2.0f * sunset.lighting.sun_radiance.z());  // warm
}

// Every preset: quick scenes generate with the right frame count and path length; full-form drives
// (the layout, without textures) too.
TEST(GenerateScene, EveryPresetLengthAndFramesWithinFivePercent) {
  for (const ScenePreset& p : ScenePresets()) {
    SCOPED_TRACE(p.name);
    const Scene quick = GenerateScene(p.name, 11, true);
    ASSERT_EQ(static_cast<int>(quick.rig_trajectory.size()), p.quick_frames);
    EXPECT_NEAR(PathLength(quick.rig_trajectory), QuickPathLength(p), 0.05 * QuickPathLength(p));
    EXPECT_NEAR(quick.rig_trajectory.back().timestamp, (p.quick_frames - 1) / 10.0, 1e-9);
    EXPECT_EQ(quick.rig_preset, p.rig_preset);
    size_t moving = 0;
    for (const Object& o : quick.objects) moving += o.IsDynamic() ? 1 : 0;
    EXPECT_EQ(moving > 0, p.traffic);

    const CityLayout full = MakeCityLayout(p, 11, false);
    ASSERT_EQ(static_cast<int>(full.trajectory.size()), p.frames);
    EXPECT_NEAR(PathLength(full.trajectory), p.path_length_m, 0.05 * p.path_length_m);
  }
}

// Kinematics of the full-form drives: bounded acceleration and jerk, heading along the motion,
// rig height, on the road and never inside a building.
TEST(RigDrive, SmoothOnTheRoadAndOutsideBuildings) {
  for (const ScenePreset& p : ScenePresets()) {
    for (uint64_t seed : {1u, 5u}) {
      SCOPED_TRACE(p.name + " seed " + std::to_string(seed));
      const CityLayout L = MakeCityLayout(p, seed, false);
      const Trajectory& tr = L.trajectory;
      const double dt = 1.0 / p.frame_rate;
      double max_accel = 0, max_jerk = 0, min_heading_dot = 1;
      for (size_t k = 0; k < tr.size(); ++k) {
        const Eigen::Vector3d x = tr[k].world_from_rig.translation;
        ASSERT_TRUE(L.grid.OnRoad(x.head<2>(), kTurnCurbClearance - 0.1)) << "frame " << k << " at " << x.transpose();
        ASSERT_FALSE(L.InsideBuilding(x.head<2>(), 1.5)) << "frame " << k;
        EXPECT_NEAR(x.z(), kRigHeight, 0.01);
        if (k >= 1 && k + 1 < tr.size()) {
          const Eigen::Vector3d v = tr[k + 1].world_from_rig.translation - tr[k - 1].world_from_rig.translation;
          const Eigen::Vector3d forward = tr[k].world_from_rig.rotation * Eigen::Vector3d::UnitX();
          if (v.head<2>().norm() > 1e-3)
            min_heading_dot = std::min(min_heading_dot, forward.head<2>().normalized().dot(v.head<2>().normalized()));
          const Eigen::Vector3d up = tr[k].world_from_rig.rotation * Eigen::Vector3d::UnitZ();
          EXPECT_GT(up.z(), std::cos(3.0 * M_PI / 180));  // only small roll/pitch
        }
        if (k >= 1 && k + 1 < tr.size()) {
          const Eigen::Vector3d a =
              (tr[k + 1].world_from_rig.translation - 2 * x + tr[k - 1].world_from_rig.translation) / (dt * dt);
          max_accel = std::max(max_accel, a.norm());
        }
        if (k >= 2 && k + 1 < tr.size()) {
          const Eigen::Vector3d j = (tr[k + 1].world_from_rig.translation - 3 * x +
                                     3 * tr[k - 1].world_from_rig.translation - tr[k - 2].world_from_rig.translation) /
                                    (dt * dt * dt);
          max_jerk = std::max(max_jerk, j.norm());
        }
      }
      // Comfortable urban driving: |a| <= ~4 m/s^2 (lateral cap 3, brake 2), jerk well below 10 m/s^3.
      EXPECT_LT(max_accel, 4.0);
      EXPECT_LT(max_jerk, 8.0);
      EXPECT_GT(min_heading_dot, std::cos(5.0 * M_PI / 180));
    }
  }
}

TEST(RigDrive, TurnsAtIntersectionsAndSlowsDown) {
  const CityLayout L = MakeCityLayout(FindScenePreset("static_urban"), 1, false);
  double total_turn = 0, v_straight = 0, v_turn = 1e9;
  const Trajectory& tr = L.trajectory;
  for (size_t k = 1; k < tr.size(); ++k) {
    total_turn += std::abs(RotationDistanceDeg(tr[k - 1].world_from_rig.rotation, tr[k].world_from_rig.rotation));
    const double kappa = std::abs(L.rig_path.Curvature(L.drive.s[k]));
    if (kappa < 1e-4) v_straight = std::max(v_straight, L.drive.speed[k]);
    if (kappa > 0.08) v_turn = std::min(v_turn, L.drive.speed[k]);
  }
  EXPECT_GT(total_turn, 4 * 80.0);  // several turns over 2 km
  EXPECT_LT(v_turn, 0.75 * v_straight);
}

TEST(LanePath, StraightControlPointsGiveAStraightPath) {
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i <= 10; ++i) pts.emplace_back(1.5 * i, 2.0);
  const LanePath path(pts);
  for (double s = 0; s <= path.Length(); s += 0.37) {
    EXPECT_NEAR(path.Position(s).y(), 2.0, 1e-12);
    EXPECT_NEAR(path.Curvature(s), 0.0, 1e-9);
    EXPECT_NEAR(path.Heading(s), 0.0, 1e-12);
  }
  EXPECT_NEAR(path.Length(), 12.0, 1e-9);  // spans 1.5 .. 13.5 (the B-spline starts at the 2nd point)
}

// A right and a left turn on a 2x3 grid: curvature continuous, radii as designed, lane kept.
TEST(LanePath, TurnsAreC2WithCarLikeRadii) {
  StreetGrid grid;
  grid.xs = {0, 80};
  grid.ys = {0, 80, 160};
  grid.road_width_m = 10;
  const GridRoute route = {{0, 0}, {0, 1}, {1, 1}, {1, 2}};  // north, right turn east, left turn north
  const LanePath path = PathAlongRoute(grid, route, 1.75);
  double prev = path.Curvature(0), max_step = 0, max_left = 0, max_right = 0;
  for (double s = 0.05; s < path.Length(); s += 0.05) {
    const double k = path.Curvature(s);
    max_step = std::max(max_step, std::abs(k - prev));
    max_left = std::max(max_left, k);
    max_right = std::max(max_right, -k);
    prev = k;
    EXPECT_TRUE(grid.OnRoad(path.Position(s), kTurnCurbClearance - 0.05)) << path.Position(s).transpose();
  }
  EXPECT_NEAR(1.0 / max_right, 6.0, 0.6);  // right turn radius 6 m
  EXPECT_NEAR(1.0 / max_left, 9.5, 1.0);   // left turn 6 + 2 * 1.75 m
  EXPECT_LT(max_step, 0.005);              // no curvature jumps at 5 cm resolution
  // Right-hand traffic: on the first (northbound) leg the path is 1.75 m east of the centre line.
  EXPECT_NEAR(path.Position(20).x(), 1.75, 1e-9);
  EXPECT_NEAR(path.Heading(20), M_PI / 2, 1e-9);
}

TEST(GenerateScene, TrafficIdsMotionAndClearance) {
  const Scene s = GenerateScene("dynamic_urban", 4, true);
  const size_t frames = s.rig_trajectory.size();
  std::set<int> ids;
  double closest = 1e9;
  int close_vehicles = 0;
  for (const Object& o : s.objects) {
    if (!o.IsDynamic()) {
      EXPECT_EQ(o.id, 0);
      continue;
    }
    EXPECT_GT(o.id, 0);
    EXPECT_TRUE(ids.insert(o.id).second) << "duplicate id " << o.id;
    ASSERT_EQ(o.world_from_object_per_frame.size(), frames);
    double nearest = 1e9;
    for (size_t f = 0; f < frames; ++f) {
      const Eigen::Vector3d d =
          o.world_from_object_per_frame[f].translation - s.rig_trajectory[f].world_from_rig.translation;
      if (o.world_from_object_per_frame[f].translation.z() < -50) continue;  // off its path, hidden
      nearest = std::min(nearest, d.head<2>().norm());
      // Moves smoothly: < 2 m per frame (20 m/s).
      if (f > 0 && o.world_from_object_per_frame[f - 1].translation.z() > -50) {
        EXPECT_LT(
            (o.world_from_object_per_frame[f].translation - o.world_from_object_per_frame[f - 1].translation).norm(),
            2.0);
      }
    }
    closest = std::min(closest, nearest);
    close_vehicles += nearest < 8.0 ? 1 : 0;
  }
  EXPECT_GE(ids.size(), 5u);
  EXPECT_EQ(*ids.begin(), 1);
  EXPECT_EQ(*ids.rbegin(), static_cast<int>(ids.size()));  // ids 1..N
  EXPECT_GT(closest, 2.5);                                 // never inside the rig's car
  EXPECT_GE(close_vehicles, 2);                            // some pass close (lead vehicle, oncoming)
}

// Texel density where VO tracks features: 1-3 cm per texel on facades, about 1 cm on roads.
TEST(GenerateScene, TexelDensity) {
  const Scene s = GenerateScene("static_urban", 1, true);
  auto density = [&](const std::string& mesh_name, double* lo, double* hi) {
    *lo = 1e9;
    *hi = 0;
    for (const Mesh& m : s.meshes) {
      if (m.name != mesh_name) continue;
      for (size_t t = 0; t < m.triangles.size(); ++t) {
        const int mat = m.triangle_materials.empty() ? m.material : m.triangle_materials[t];
        const int tex = s.materials[mat].texture;
        if (tex < 0) continue;
        // Facade and shop textures (details such as roofs and awnings have their own scales).
        const std::string& tex_name = s.textures[tex].name;
        if (mesh_name == "buildings" && tex_name.rfind("facade", 0) != 0 && tex_name.rfind("storefront", 0) != 0)
          continue;
        const auto& tri = m.triangles[t];
        const double area =
            0.5 * (m.positions[tri[1]] - m.positions[tri[0]]).cross(m.positions[tri[2]] - m.positions[tri[0]]).norm();
        Eigen::Vector2d e1 = (m.uvs[tri[1]] - m.uvs[tri[0]]).cast<double>(),
                        e2 = (m.uvs[tri[2]] - m.uvs[tri[0]]).cast<double>();
        e1.x() *= s.textures[tex].width, e2.x() *= s.textures[tex].width;
        e1.y() *= s.textures[tex].height, e2.y() *= s.textures[tex].height;
        const double texel_area = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
        if (area < 1e-6) continue;
        const double metres_per_texel = std::sqrt(area / texel_area);
        *lo = std::min(*lo, metres_per_texel);
        *hi = std::max(*hi, metres_per_texel);
      }
    }
  };
  double lo, hi;
  density("buildings", &lo, &hi);
  EXPECT_GE(lo, 0.01);
  EXPECT_LE(hi, 0.03);
  density("roads", &lo, &hi);
  EXPECT_GE(lo, 0.005);
  EXPECT_LE(hi, 0.015);
  density("sidewalks", &lo, &hi);
  EXPECT_LE(lo, 0.01);
}

// The facade relief (real geometry in front of the walls) must leave the painted windows open:
// every point of a relief face facing the street maps to wall texture, not into a window.
TEST(GenerateScene, FacadeReliefLinesUpWithPaintedWindows) {
  for (const char* preset : {"static_urban", "cloudy_urban"}) {
    const uint64_t seed = 4;
    const Scene s = GenerateScene(preset, seed, true);
    const CityLayout layout = MakeCityLayout(FindScenePreset(preset), seed, true);
    const uint64_t texture_seed = SubSeed(LayoutSeed(preset, seed), "textures");
    const Mesh* buildings = nullptr;
    for (const Mesh& m : s.meshes)
      if (m.name == "buildings") buildings = &m;
    ASSERT_NE(buildings, nullptr);
    std::map<std::string, int> kinds;  // triangles per detail material family
    int relief_faces = 0, checked_points = 0;
    for (size_t t = 0; t < buildings->triangles.size(); ++t) {
      const int mat = buildings->triangle_materials.empty() ? buildings->material : buildings->triangle_materials[t];
      const std::string& name = s.materials[mat].name;
      for (const char* family : {"awning_", "railing_", "roof_tiles_", "trim_", "rooftop_"})
        if (name.rfind(family, 0) == 0) ++kinds[family];
      const size_t suffix = name.find("_facade");
      if (suffix == std::string::npos) continue;
      const BuildingPlan& plan = layout.buildings[std::stoul(name.substr(9, suffix - 9))];
      const Eigen::Vector3i& tri = buildings->triangles[t];
      const Eigen::Vector3f a = buildings->positions[tri[0]], b = buildings->positions[tri[1]],
                            c = buildings->positions[tri[2]];
      const Eigen::Vector3f normal = (b - a).cross(c - a).normalized();
      if (std::abs(normal.z()) > 1e-3) continue;  // top/bottom of a relief block
      // A front face: its plane is parallel to the street side and at least 5 cm in front of the wall.
      const Eigen::Vector2d facing = plan.facing;
      if (std::abs(normal.head<2>().cast<double>().dot(facing)) < 0.999) continue;
      const Eigen::Vector2d on_wall = facing.x() + facing.y() > 0 ? plan.footprint.max : plan.footprint.min;
      const double offset = (a.head<2>().cast<double>() - on_wall).dot(facing);
      if (offset < 0.05) continue;
      ++relief_faces;
      const FacadeLayout fl = GetFacadeLayout(texture_seed, plan.facade);
      const int bay_px = 1024 / fl.bays, win_w_px = static_cast<int>(bay_px * fl.window_width_fraction);
      const int win_h_px = static_cast<int>(256 * fl.window_height_fraction), win_top_px = (256 - win_h_px) / 2 - 8;
      const Eigen::Vector2f ua = buildings->uvs[tri[0]], ub = buildings->uvs[tri[1]], uc = buildings->uvs[tri[2]];
      for (const Eigen::Vector3f& w :
           {Eigen::Vector3f(1.0f / 3, 1.0f / 3, 1.0f / 3), Eigen::Vector3f(0.9f, 0.05f, 0.05f),
            Eigen::Vector3f(0.05f, 0.9f, 0.05f), Eigen::Vector3f(0.05f, 0.05f, 0.9f)}) {
        const Eigen::Vector2f uv = w[0] * ua + w[1] * ub + w[2] * uc;
        const double x = (uv.x() - std::floor(uv.x())) * 1024, y = (uv.y() - std::floor(uv.y())) * 1024;
        const double x_in = std::fmod(x, bay_px) - (bay_px - win_w_px) / 2, y_in = std::fmod(y, 256.0) - win_top_px;
        const bool in_window = x_in > 2 && x_in < win_w_px - 2 && y_in > 2 && y_in < win_h_px - 2;
        EXPECT_FALSE(in_window) << preset << " " << name << " uv " << uv.transpose() << " px " << x << "," << y;
        ++checked_points;
      }
    }
    EXPECT_GT(relief_faces, 20) << preset;
    EXPECT_GT(checked_points, 80) << preset;
    EXPECT_GT(kinds["awning_"], 0) << preset;
    EXPECT_GT(kinds["railing_"], 0) << preset;
    EXPECT_GT(kinds["trim_"], 0) << preset;
    EXPECT_GT(kinds["rooftop_"], 0) << preset;
    if (std::string(preset) == "cloudy_urban") {
      EXPECT_GT(kinds["roof_tiles_"], 0);  // low town houses
    }
  }
}

// canyon_multifov is a narrow urban canyon: facades close to both sides of the rig and tall
// compared with the street's width (static_urban, for contrast, is a wide street).
TEST(CityLayout, CanyonIsNarrowAndTall) {
  struct Profile {
    double median_width = 0, median_height = 0, both_sides_fraction = 0;
  };
  auto profile = [](const char* preset) {
    const CityLayout L = MakeCityLayout(FindScenePreset(preset), 2, false);
    std::vector<double> widths, heights;
    int samples = 0, both = 0;
    for (size_t f = 0; f < L.trajectory.size(); f += 10) {
      const Eigen::Vector2d p = L.trajectory[f].world_from_rig.translation.head<2>();
      const double yaw = L.rig_path.Heading(L.drive.s[f]);
      const Eigen::Vector2d left(-std::sin(yaw), std::cos(yaw));
      double width = 0;
      int hits = 0;
      for (double side : {1.0, -1.0}) {
        for (double d = 0.25; d < 25.0; d += 0.25) {
          const Eigen::Vector2d q = p + side * d * left;
          const BuildingPlan* hit = nullptr;
          for (const BuildingPlan& b : L.buildings)
            if (b.footprint.Contains(q)) hit = &b;
          if (!hit) continue;
          width += d;
          heights.push_back(hit->height);
          ++hits;
          break;
        }
      }
      ++samples;
      if (hits == 2) {
        ++both;
        widths.push_back(width);
      }
    }
    auto median = [](std::vector<double> v) {
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    Profile out;
    out.both_sides_fraction = static_cast<double>(both) / samples;
    if (!widths.empty()) out.median_width = median(widths);
    if (!heights.empty()) out.median_height = median(heights);
    return out;
  };
  const Profile canyon = profile("canyon_multifov"), wide = profile("static_urban");
  // Facade to facade: 7 m road + 2 x 2 m sidewalks = 11 m.
  EXPECT_GT(canyon.both_sides_fraction, 0.6);
  EXPECT_LE(canyon.median_width, 12.0);
  EXPECT_GE(canyon.median_height / canyon.median_width, 2.5);
  EXPECT_GE(wide.median_width, 15.0);
  EXPECT_LT(wide.median_height / wide.median_width, 1.5);
  std::printf(
      "canyon: facade-to-facade %.1f m, building height %.1f m (H/W %.1f), both sides within 25 m %.0f%%\n"
      "static_urban: %.1f m, %.1f m (H/W %.1f)\n",
      canyon.median_width, canyon.median_height, canyon.median_height / canyon.median_width,
      100 * canyon.both_sides_fraction, wide.median_width, wide.median_height, wide.median_height / wide.median_width);
}

TEST(Textures, TileSeamlesslyAndHaveDetail) {
  // Tileable: the step across the wrap (last column to first, last row to first) is no larger
  // than the largest step between neighbouring interior columns/rows.
  for (const Texture& t : {MakeRoadTexture(3, 0, 10.0, 1.5), MakeSidewalkTexture(3), MakeFacadeTexture(3, 1),
                           MakeFacadeTexture(3, 0), MakeStorefrontTexture(3, 0)}) {
    SCOPED_TRACE(t.name);
    auto px = [&](int x, int y) { return static_cast<double>(t.rgb[(static_cast<size_t>(y) * t.width + x) * 3 + 1]); };
    auto col_step = [&](int xa, int xb) {
      double d = 0;
      for (int y = 0; y < t.height; ++y) d += std::abs(px(xa, y) - px(xb, y));
      return d / t.height;
    };
    auto row_step = [&](int ya, int yb) {
      double d = 0;
      for (int x = 0; x < t.width; ++x) d += std::abs(px(x, ya) - px(x, yb));
      return d / t.width;
    };
    double max_col = 0, max_row = 0;
    for (int x = 0; x + 1 < t.width; ++x) max_col = std::max(max_col, col_step(x, x + 1));
    for (int y = 0; y + 1 < t.height; ++y) max_row = std::max(max_row, row_step(y, y + 1));
    EXPECT_LE(col_step(t.width - 1, 0), max_col);
    EXPECT_LE(row_step(t.height - 1, 0), max_row);
    // Detail: the standard deviation of green is well above flat.
    double sum = 0, sum2 = 0;
    const size_t n = static_cast<size_t>(t.width) * t.height;
    for (size_t i = 0; i < n; ++i) {
      sum += t.rgb[i * 3 + 1];
      sum2 += t.rgb[i * 3 + 1] * t.rgb[i * 3 + 1];
    }
    EXPECT_GT(std::sqrt(sum2 / n - (sum / n) * (sum / n)), 8.0);
  }
  // Facades in the pool are not alike.
  EXPECT_NE(MakeFacadeTexture(3, 0).rgb, MakeFacadeTexture(3, 4).rgb);
}

TEST(SceneCli, GenerateAndList) {
  const std::string out = FreshDir("cli");
  const std::string cmd = std::string(ROVO_BINARY) + " scene generate --preset cloudy_urban --quick --seed 5 --out " +
                          out + "/s > " + out + "/log.txt 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << ReadFile(out + "/log.txt");
  const std::string log = ReadFile(out + "/log.txt");
  EXPECT_NE(log.find("triangles"), std::string::npos) << log;
  EXPECT_NE(log.find("path"), std::string::npos) << log;
  const Scene loaded = LoadScene(out + "/s");
  EXPECT_EQ(SceneHash(loaded), SceneHash(GenerateScene("cloudy_urban", 5, true)));
  // `scene info` loads the folder and reports the same content hash, the path and the load time.
  const std::string info = std::string(ROVO_BINARY) + " scene info " + out + "/s > " + out + "/info.txt 2>&1";
  ASSERT_EQ(std::system(info.c_str()), 0) << ReadFile(out + "/info.txt");
  const std::string info_log = ReadFile(out + "/info.txt");
  EXPECT_NE(info_log.find(SceneHash(loaded)), std::string::npos) << info_log;
  EXPECT_NE(info_log.find("(preset: 69 m, 60 frames)"), std::string::npos) << info_log;
  EXPECT_NE(info_log.find("s load"), std::string::npos) << info_log;
  const std::string list = std::string(ROVO_BINARY) + " scene list > " + out + "/list.txt 2>&1";
  ASSERT_EQ(std::system(list.c_str()), 0);
  EXPECT_NE(ReadFile(out + "/list.txt").find("canyon_multifov"), std::string::npos);
  const std::string bad =
      std::string(ROVO_BINARY) + " scene generate --preset nope --out " + out + "/x > " + out + "/bad.txt 2>&1";
  EXPECT_NE(std::system(bad.c_str()), 0);
  EXPECT_NE(ReadFile(out + "/bad.txt").find("static_urban"), std::string::npos);
}

}  // namespace
}  // namespace rovo
