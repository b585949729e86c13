// The harder worlds (indoor_hall, suburban_road, night_street): they generate, load back, are
// deterministic, and have the properties the presets claim, each measured on the scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "datasets/io.h"
#include "datasets/rig.h"
#include "scenes/city.h"
#include "scenes/city_layout.h"
#include "scenes/indoor.h"
#include "scenes/texture_gen.h"
#include "tests/scenes/scratch_dir.h"

namespace rovo {
namespace {

using test::FreshDir;

TEST(HarderWorlds, ListedAfterTableOneAndFound) {
  ASSERT_EQ(ScenePresets().size(), 5u);  // Table I only: `rovo suite`'s default set is unchanged
  const std::vector<std::string> names = {"indoor_hall", "suburban_road", "night_street"};
  ASSERT_EQ(HarderScenePresets().size(), names.size());
  const std::vector<ScenePreset> all = AllScenePresets();
  ASSERT_EQ(all.size(), 8u);
  for (size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(HarderScenePresets()[i].name, names[i]);
    EXPECT_EQ(all[5 + i].name, names[i]);
    EXPECT_EQ(FindScenePreset(names[i]).name, names[i]);
    EXPECT_GT(FindScenePreset(names[i]).quick_frames, 0);
  }
  EXPECT_EQ(FindScenePreset("indoor_hall").world, SceneWorld::kIndoor);
  EXPECT_EQ(FindScenePreset("night_street").lighting, SceneLighting::kNight);
}

// Quick forms: frame count and path length as the preset says, the same bytes for the same seed,
// other scenes for other seeds, and the saved folder loads back to the same content.
TEST(HarderWorlds, GenerateDeterministicallyAndLoadBack) {
  for (const ScenePreset& p : HarderScenePresets()) {
    SCOPED_TRACE(p.name);
    const Scene a = GenerateScene(p.name, 3, true);
    ASSERT_EQ(static_cast<int>(a.rig_trajectory.size()), p.quick_frames);
    EXPECT_NEAR(PathLength(a.rig_trajectory), QuickPathLength(p), 0.05 * QuickPathLength(p));
    EXPECT_EQ(a.rig_preset, p.rig_preset);
    size_t moving = 0;
    for (const Object& o : a.objects) moving += o.IsDynamic() ? 1 : 0;
    EXPECT_EQ(moving > 0, p.traffic);
    const Scene b = GenerateScene(p.name, 3, true);
    EXPECT_EQ(SceneHash(a), SceneHash(b));
    EXPECT_NE(SceneHash(a), SceneHash(GenerateScene(p.name, 4, true)));
    const std::string da = FreshDir("harder_a_" + p.name), db = FreshDir("harder_b_" + p.name);
    SaveScene(a, da);
    SaveScene(b, db);
    for (const char* f : {"scene.json", "geometry.bin", "motion.bin", "trajectory.tum"})
      EXPECT_EQ(ReadFile(da + "/" + f), ReadFile(db + "/" + f)) << f;
    EXPECT_EQ(SceneHash(LoadScene(da)), SceneHash(a));
  }
}

// Full forms: the layouts (without textures) have the nominal frames and length.
TEST(HarderWorlds, FullFormLengths) {
  const ScenePreset& indoor = FindScenePreset("indoor_hall");
  const IndoorLayout L = MakeIndoorLayout(indoor, 1, false);
  ASSERT_EQ(static_cast<int>(L.trajectory.size()), indoor.frames);
  EXPECT_NEAR(PathLength(L.trajectory), indoor.path_length_m, 0.05 * indoor.path_length_m);
  for (const char* name : {"suburban_road", "night_street"}) {
    const ScenePreset& p = FindScenePreset(name);
    const CityLayout C = MakeCityLayout(p, 1, false);
    ASSERT_EQ(static_cast<int>(C.trajectory.size()), p.frames) << name;
    EXPECT_NEAR(PathLength(C.trajectory), p.path_length_m, 0.05 * p.path_length_m) << name;
  }
}

// ---- indoor_hall ----------------------------------------------------------------------------

// Smallest t > 0 at which the ray o + t d hits a triangle of the static objects (Moller-Trumbore).
double FirstHit(const Scene& scene, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const Object& obj : scene.objects) {
    if (obj.IsDynamic()) continue;
    const Mesh& mesh = scene.meshes[obj.mesh];
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const Eigen::Vector3d p0 = obj.world_from_object * mesh.positions[t[0]].cast<double>();
      const Eigen::Vector3d e1 = obj.world_from_object * mesh.positions[t[1]].cast<double>() - p0;
      const Eigen::Vector3d e2 = obj.world_from_object * mesh.positions[t[2]].cast<double>() - p0;
      const Eigen::Vector3d pv = d.cross(e2);
      const double det = e1.dot(pv);
      if (std::abs(det) < 1e-12) continue;
      const Eigen::Vector3d tv = o - p0;
      const double u = tv.dot(pv) / det;
      const Eigen::Vector3d qv = tv.cross(e1);
      const double v = d.dot(qv) / det;
      const double hit = e2.dot(qv) / det;
      if (u >= 0 && v >= 0 && u + v <= 1 && hit > 1e-6) best = std::min(best, hit);
    }
  }
  return best;
}

// The ceiling is over the whole walk, the walk crosses the hall and enters the corridor, and the
// cart keeps clear of the walls.
TEST(IndoorHall, CeilingOverTheWalkThroughHallAndCorridor) {
  const ScenePreset& p = FindScenePreset("indoor_hall");
  for (const bool quick : {true, false}) {
    SCOPED_TRACE(quick ? "quick" : "full");
    const IndoorLayout L = MakeIndoorLayout(p, 2, quick);
    const Scene scene = GenerateScene(p.name, 2, quick);
    int in_hall = 0, in_corridor = 0;
    for (size_t f = 0; f < scene.rig_trajectory.size(); f += quick ? 4 : 25) {
      const Eigen::Vector3d x = scene.rig_trajectory[f].world_from_rig.translation;
      EXPECT_NEAR(x.z(), kIndoorRigHeight, 0.01);
      EXPECT_TRUE(L.OnFloor(x.head<2>(), 0.9)) << "frame " << f;
      const double up = FirstHit(scene, x, Eigen::Vector3d::UnitZ());
      const double ceiling = x.x() < kHallEndX ? kHallHeight : kCorridorHeight;
      EXPECT_NEAR(x.z() + up, ceiling, 0.2) << "frame " << f;  // the ceiling (or a panel just under it)
      (x.x() < kHallEndX ? in_hall : in_corridor)++;
    }
    EXPECT_GT(in_hall, 2);
    EXPECT_GT(in_corridor, 2);
  }
}

// People stand or walk near the path: each keeps >= 0.5 m from every camera at every frame and
// several come within 2 m of one; some walk (dynamic objects with mask ids); the mesh fits the
// radius the clearance assumes.
TEST(IndoorHall, PeopleWithinTwoMetresOfTheRig) {
  const ScenePreset& p = FindScenePreset("indoor_hall");
  const Rig rig = MakeRigPreset(p.rig_preset);
  for (const bool quick : {true, false}) {
    SCOPED_TRACE(quick ? "quick" : "full");
    const Scene scene = GenerateScene(p.name, 5, quick);
    int people = 0, close = 0, walking = 0;
    double nearest = 1e9;
    for (const Object& o : scene.objects) {
      if (o.name.rfind("person_", 0) != 0) continue;
      ++people;
      for (const Eigen::Vector3f& v : scene.meshes[o.mesh].positions)
        ASSERT_LE(v.head<2>().norm(), kPersonRadius + 1e-4) << o.name;
      if (o.IsDynamic()) {
        ++walking;
        EXPECT_GT(o.id, 0) << o.name;
      }
      double closest = 1e9;
      for (size_t f = 0; f < scene.rig_trajectory.size(); ++f) {
        const Eigen::Vector3d centre =
            (o.IsDynamic() ? o.world_from_object_per_frame[f] : o.world_from_object).translation;
        for (const RigCamera& c : rig.cameras) {
          const Eigen::Vector3d cam = scene.rig_trajectory[f].world_from_rig * CameraPositionInRig(c.cam_from_rig);
          closest = std::min(closest, (cam.head<2>() - centre.head<2>()).norm() - kPersonRadius);
        }
      }
      EXPECT_GE(closest, 0.5) << o.name;
      nearest = std::min(nearest, closest);
      close += closest <= 2.0;
    }
    std::printf("indoor_hall %s: %d people, %d walking, %d within 2 m of a camera (nearest %.2f m)\n",
                quick ? "quick" : "full", people, walking, close, nearest);
    EXPECT_GE(close, quick ? 3 : 20);
    EXPECT_GE(walking, 1);
  }
}

// Plain walls, a glossy floor, ceiling lights (glowing panels with a light under each), no sun.
TEST(IndoorHall, LitByCeilingLightsWithAGlossyFloor) {
  const Scene scene = GenerateScene("indoor_hall", 0, true);
  EXPECT_EQ(scene.lighting.sun_radiance.maxCoeff(), 0.0f);
  int panels = 0, glossy = 0;
  for (const Material& m : scene.materials) {
    panels += m.IsEmissive();
    glossy += m.specular > 0.0f && m.shininess > 0.0f;
  }
  EXPECT_GE(panels, 1);
  EXPECT_GE(glossy, 1);
  ASSERT_GE(scene.lights.size(), 40u);
  for (const Light& l : scene.lights) {
    EXPECT_LT(l.position.z(), kHallHeight) << l.name;
    EXPECT_GT(l.range, 0.0) << l.name;
    EXPECT_GT(l.intensity.minCoeff(), 0.0f) << l.name;
  }
}

// ---- night_street ---------------------------------------------------------------------------

// Street lamps and headlights, a dark sky and no sun, an exposure far above the day presets', the
// cloudy_urban streets, and a lamp within reach of the rig at every frame.
TEST(NightStreet, LampsHeadlightsAndADarkSky) {
  const Scene night = GenerateScene("night_street", 6, true);
  const Scene cloudy = GenerateScene("cloudy_urban", 6, true);
  const Scene sunny = GenerateScene("static_urban", 6, true);
  EXPECT_EQ(night.lighting.sun_radiance.maxCoeff(), 0.0f);
  const float night_sky = std::max(night.lighting.sky_zenith.maxCoeff(), night.lighting.sky_horizon.maxCoeff());
  const float day_sky = std::max(sunny.lighting.sky_zenith.maxCoeff(), sunny.lighting.sky_horizon.maxCoeff());
  EXPECT_LT(night_sky, 1e-3f * day_sky);
  EXPECT_GE(night.lighting.exposure, 500.0f * sunny.lighting.exposure);
  int lamps = 0, headlights = 0;
  std::vector<int> per_vehicle(night.objects.size(), 0);
  for (const Light& l : night.lights) {
    ASSERT_GE(l.object, 0) << l.name;
    const Object& o = night.objects[l.object];
    if (o.IsDynamic()) {
      ++headlights;
      ++per_vehicle[l.object];
      EXPECT_TRUE(l.spot) << l.name;
      EXPECT_GT(l.spot_direction.normalized().x(), 0.9) << l.name;  // forward
    } else {
      ++lamps;
      EXPECT_EQ(o.name.rfind("light_", 0), 0u) << l.name;
    }
  }
  EXPECT_GE(lamps, 50);
  for (size_t o = 0; o < night.objects.size(); ++o) {
    if (night.objects[o].IsDynamic()) {
      EXPECT_EQ(per_vehicle[o], 2) << night.objects[o].name;
    }
  }
  EXPECT_GE(headlights, 2);
  // The same streets as cloudy_urban.
  ASSERT_EQ(night.rig_trajectory.size(), cloudy.rig_trajectory.size());
  EXPECT_EQ(night.rig_trajectory.back().world_from_rig.translation,
            cloudy.rig_trajectory.back().world_from_rig.translation);
  // A lamp within its range of the rig at every frame.
  for (size_t f = 0; f < night.rig_trajectory.size(); f += 5) {
    double nearest = 1e9;
    for (const Light& l : night.lights) {
      const Object& o = night.objects[l.object];
      if (o.IsDynamic()) continue;
      nearest = std::min(
          nearest, (o.world_from_object * l.position - night.rig_trajectory[f].world_from_rig.translation).norm());
    }
    EXPECT_LT(nearest, 30.0) << "frame " << f;
  }
}

// ---- suburban_road --------------------------------------------------------------------------

// Strong-gradient texels per square metre of the textures on building walls: 8-bit luminance,
// central differences |dx| + |dy| > 24 (a corner or edge a feature detector can use).
double WallFeatureDensity(const Scene& scene, const std::string& suffix, double metres_per_texel_hint) {
  double strong = 0.0, area = 0.0;
  std::vector<bool> seen(scene.textures.size(), false);
  for (const Material& m : scene.materials) {
    if (m.texture < 0 || m.name.size() < suffix.size() ||
        m.name.compare(m.name.size() - suffix.size(), suffix.size(), suffix) != 0 || seen[m.texture])
      continue;
    seen[m.texture] = true;
    const Texture& t = scene.textures[m.texture];
    auto lum = [&](int x, int y) {
      const uint8_t* p = &t.rgb[(static_cast<size_t>(y) * t.width + x) * 3];
      return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    };
    for (int y = 1; y + 1 < t.height; ++y)
      for (int x = 1; x + 1 < t.width; ++x)
        strong += std::abs(lum(x + 1, y) - lum(x - 1, y)) + std::abs(lum(x, y + 1) - lum(x, y - 1)) > 24.0;
    area += static_cast<double>(t.width) * t.height * metres_per_texel_hint * metres_per_texel_hint;
  }
  return area > 0.0 ? strong / area : -1.0;
}

TEST(SuburbanRoad, PlainWallsLowHousesWideSpacing) {
  const Scene suburb = GenerateScene("suburban_road", 0, true);
  const Scene urban = GenerateScene("static_urban", 0, true);
  const double suburb_density = WallFeatureDensity(suburb, "_wall", kHouseWallTileMetres / 512.0);
  const double urban_density = WallFeatureDensity(urban, "_facade", kFacadeTileMetres / 1024.0);
  std::printf("strong-gradient texels per m^2 of wall texture: suburban_road %.1f, static_urban %.1f\n", suburb_density,
              urban_density);
  ASSERT_GE(suburb_density, 0.0);
  EXPECT_LT(suburb_density, 0.05 * urban_density);
  // Low houses set back from the road: the nearest wall from the rig and the height of the
  // buildings within 40 m of it.
  for (const char* name : {"suburban_road", "static_urban"}) {
    const CityLayout L = MakeCityLayout(FindScenePreset(name), 0, true);
    std::vector<double> nearest, heights;
    for (size_t f = 0; f < L.trajectory.size(); f += 5) {
      const Eigen::Vector2d x = L.trajectory[f].world_from_rig.translation.head<2>();
      double d = 1e9;
      for (const BuildingPlan& b : L.buildings) {
        const Eigen::Vector2d q = x.cwiseMax(b.footprint.min).cwiseMin(b.footprint.max);
        d = std::min(d, (q - x).norm());
        if ((q - x).norm() < 40.0) heights.push_back(b.height);
      }
      nearest.push_back(d);
    }
    std::sort(nearest.begin(), nearest.end());
    std::sort(heights.begin(), heights.end());
    const double median_wall = nearest[nearest.size() / 2], median_height = heights[heights.size() / 2];
    std::printf("%s: median distance from the rig to the nearest wall %.1f m, median building height %.1f m\n", name,
                median_wall, median_height);
    if (std::string(name) == "suburban_road") {
      EXPECT_GT(median_wall, 12.0);
      EXPECT_LT(median_height, 6.0);
    } else {
      EXPECT_LT(median_wall, 10.0);
      EXPECT_GT(median_height, 12.0);
    }
  }
}

}  // namespace
}  // namespace rovo
