// The harder worlds through Blender and back: each preset's quick form (first 3 frames) is imported
// into Blender (scenes/blender/import_scene.py) with an equidistant rig on rovo4's mounts, saved,
// exported again (scenes/blender/export_scene.py) and compared with the original:
//   - content: trajectory, lighting, every object's triangles in the world (positions, UVs,
//     materials with their colours, textures, emission and highlight) at every frame, every light
//     (world position at every frame, intensity, range, spot cone, the object it rides on);
//   - rovo renders of the original and of the round-tripped scene (colour and depth);
//   - Cycles' depth of the imported .blend against rovo's (lens, rig, trajectory and geometry);
//   - light units: with the ambient term and the lights' range cut-off off in rovo and the world
//     light off in Cycles, the mean luminance of rovo's and Cycles' images of the lit presets
//     agree over the matte surfaces (point/spot lights, emission).
//
// Needs `blender` (Debian package) on PATH.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "datasets/image_file.h"
#include "datasets/io.h"
#include "datasets/rig_json.h"
#include "scenes/city.h"
#include "scenes/scene.h"
#include "tests/scenes/integration/shell_log.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;
using testing::Quote;
using testing::RunShell;
using testing::Tail;

constexpr int kImageSize = 160;
constexpr int kFrames = 3;

// rovo4's camera mounts with 220-degree equidistant lenses in Cycles' exact mapping.
Rig EquidistantRovo4() {
  Rig rig = MakeRigPreset("rovo4");
  const double fov = 220.0 * M_PI / 180.0;
  for (RigCamera& c : rig.cameras) {
    Camera cam;
    cam.model = CameraModelId::kEquidistant;
    cam.width = cam.height = kImageSize;
    cam.params = {kImageSize / fov, kImageSize / fov, kImageSize / 2.0 - 0.5, kImageSize / 2.0 - 0.5, 0, 0, 0, 0};
    cam.max_fov_deg = 220.0;
    cam.Check("test camera");
    c.camera = cam;
  }
  return rig;
}

// One float channel of an image (PNG: RGB decoded to [0, 1], channel `index`; EXR: by name, or
// the first channel when `channel` is empty).
std::vector<float> ReadChannel(const std::string& path, const std::string& channel, int index = 0) {
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".png") == 0) {
    const Image8 png = ReadPng8(path, {3, true});
    std::vector<float> data(static_cast<size_t>(png.width) * png.height);
    for (size_t i = 0; i < data.size(); ++i) data[i] = png.pixels[3 * i + static_cast<size_t>(index)] / 255.0f;
    return data;
  }
  FloatImage exr = ReadExr(path);
  if (!channel.empty()) index = exr.Channel(channel);
  if (index < 0 || index >= static_cast<int>(exr.planes.size()))
    throw std::runtime_error(path + ": no channel " + channel);
  return std::move(exr.planes[static_cast<size_t>(index)]);
}

struct Pipeline {
  std::string preset, work, log, original, rig, blend, exported;

  std::string Step(const std::string& name, const std::string& command) {
    return RunShell(command, log) == 0 ? "" : name + " failed:\n" + Tail(log);
  }

  // Generate, import, export. Returns "" or the failing step with the log's tail.
  std::string Run() {
    work = (fs::path(::testing::TempDir()) / ("rovo_blender_" + preset + "_" + std::to_string(getpid()))).string();
    fs::remove_all(work);
    fs::create_directories(work);
    log = work + "/log.txt";
    original = work + "/original";
    rig = work + "/rig.json";
    blend = work + "/imported.blend";
    exported = work + "/exported";
    if (RunShell("command -v blender", log) != 0) return "blender is not on PATH (Debian package `blender`)";
    SaveScene(GenerateScene(preset, 0, true), original);
    WriteRigJson(rig, EquidistantRovo4(), "rovo4 mounts, equidistant 220 deg");
    const std::string src = ROVO_SOURCE_DIR;
    std::string e =
        Step("import", "blender -b --factory-startup --python-exit-code 1 --python " +
                           Quote(src + "/scenes/blender/import_scene.py") + " -- " + Quote(original) + " " +
                           Quote(blend) + " --rig " + Quote(rig) + " --frames 0:" + std::to_string(kFrames));
    if (!e.empty()) return e;
    return Step("export", "blender -b " + Quote(blend) + " --python-exit-code 1 --python " +
                              Quote(src + "/scenes/blender/export_scene.py") + " -- " + Quote(exported));
  }

  std::string Render(const std::string& scene, const std::string& out, const std::string& rig_arg) {
    return Step("rovo render " + out, Quote(ROVO_BINARY) + " render --scene " + Quote(scene) + rig_arg +
                                          " --frames 0:" + std::to_string(kFrames) + " --out " + Quote(out) +
                                          " --depth --spp 1 --threads 2 --quiet");
  }
};

Rigid3 WorldFromObject(const Object& o, int frame) {
  return o.IsDynamic() ? o.world_from_object_per_frame[frame] : o.world_from_object;
}

double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a.inverse() * b).angle();
}

void ExpectNearVec(const Eigen::Vector3f& a, const Eigen::Vector3f& b, double rel, const std::string& what) {
  EXPECT_LE((a - b).norm(), rel * std::max(1.0f, b.norm())) << what << ": " << a.transpose() << " vs " << b.transpose();
}

// Trajectory, lighting and lights.
void CompareHeaderAndLights(const Scene& a, const Scene& b) {
  ASSERT_EQ(b.rig_trajectory.size(), static_cast<size_t>(kFrames));
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_LT((a.rig_trajectory[f].world_from_rig.translation - b.rig_trajectory[f].world_from_rig.translation).norm(),
              1e-4);
    EXPECT_LT(AngleBetween(a.rig_trajectory[f].world_from_rig.rotation, b.rig_trajectory[f].world_from_rig.rotation),
              1e-5);
    EXPECT_NEAR(a.rig_trajectory[f].timestamp, b.rig_trajectory[f].timestamp, 1e-9);
  }
  const Lighting &la = a.lighting, &lb = b.lighting;
  EXPECT_EQ(la.preset, lb.preset);
  ExpectNearVec(la.sun_radiance, lb.sun_radiance, 1e-6, "sun_radiance");
  if (la.sun_radiance.maxCoeff() > 0) {
    EXPECT_LT((la.direction_to_sun.normalized() - lb.direction_to_sun.normalized()).norm(), 1e-6);
  }
  ExpectNearVec(la.sky_zenith, lb.sky_zenith, 1e-6, "sky_zenith");
  ExpectNearVec(la.sky_horizon, lb.sky_horizon, 1e-6, "sky_horizon");
  ExpectNearVec(la.ground_albedo, lb.ground_albedo, 1e-6, "ground_albedo");
  EXPECT_NEAR(la.ambient, lb.ambient, 1e-6);
  EXPECT_EQ(la.exposure, lb.exposure);
  ASSERT_EQ(a.lights.size(), b.lights.size());
  std::map<std::string, const Light*> by_name;
  for (const Light& l : b.lights) by_name[l.name] = &l;
  for (const Light& la_l : a.lights) {
    ASSERT_EQ(by_name.count(la_l.name), 1u) << la_l.name;
    const Light& lb_l = *by_name[la_l.name];
    ExpectNearVec(la_l.intensity, lb_l.intensity, 1e-5, la_l.name + " intensity");
    EXPECT_NEAR(la_l.range, lb_l.range, 1e-5) << la_l.name;
    ASSERT_EQ(la_l.spot, lb_l.spot) << la_l.name;
    if (la_l.spot) {
      EXPECT_LT((la_l.spot_direction.normalized() - lb_l.spot_direction.normalized()).norm(), 1e-5) << la_l.name;
      EXPECT_NEAR(la_l.spot_angle_deg, lb_l.spot_angle_deg, 1e-4) << la_l.name;
      EXPECT_NEAR(la_l.spot_blend, lb_l.spot_blend, 1e-6) << la_l.name;
    }
    ASSERT_EQ(la_l.object >= 0, lb_l.object >= 0) << la_l.name;
    if (la_l.object >= 0) {
      EXPECT_EQ(a.objects[la_l.object].name, b.objects[lb_l.object].name) << la_l.name;
    }
    for (int f = 0; f < kFrames; ++f) {
      const Eigen::Vector3d pa =
          la_l.object >= 0 ? WorldFromObject(a.objects[la_l.object], f) * la_l.position : la_l.position;
      const Eigen::Vector3d pb =
          lb_l.object >= 0 ? WorldFromObject(b.objects[lb_l.object], f) * lb_l.position : lb_l.position;
      EXPECT_LT((pa - pb).norm(), 1e-4) << la_l.name << " frame " << f;
    }
  }
}

// Every object, in order: name, pose at every frame, and its mesh triangle by triangle (world
// positions, UVs, material colour, texture pixels, emission, highlight).
void CompareObjects(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.objects.size(), b.objects.size());
  size_t triangles = 0;
  for (size_t o = 0; o < a.objects.size(); ++o) {
    const Object &oa = a.objects[o], &ob = b.objects[o];
    ASSERT_EQ(oa.name, ob.name) << "object " << o;
    for (int f = 0; f < kFrames; ++f) {
      EXPECT_LT((WorldFromObject(oa, f).translation - WorldFromObject(ob, f).translation).norm(), 1e-4) << oa.name;
      EXPECT_LT(AngleBetween(WorldFromObject(oa, f).rotation, WorldFromObject(ob, f).rotation), 1e-5) << oa.name;
    }
    const Mesh &ma = a.meshes[oa.mesh], &mb = b.meshes[ob.mesh];
    ASSERT_EQ(ma.triangles.size(), mb.triangles.size()) << oa.name;
    ASSERT_EQ(ma.uvs.empty(), mb.uvs.empty()) << oa.name;
    const Rigid3 wa = WorldFromObject(oa, 0), wb = WorldFromObject(ob, 0);
    int bad = 0;
    for (size_t t = 0; t < ma.triangles.size() && bad < 5; ++t) {
      for (int k = 0; k < 3; ++k) {
        const int va = ma.triangles[t][k], vb = mb.triangles[t][k];
        const Eigen::Vector3d pa = wa * ma.positions[va].cast<double>(), pb = wb * mb.positions[vb].cast<double>();
        if ((pa - pb).norm() > 1e-4) ++bad;
        if (!ma.uvs.empty() && (ma.uvs[va] - mb.uvs[vb]).norm() > 1e-5) ++bad;
      }
      const Material& xa = a.materials[ma.triangle_materials.empty() ? ma.material : ma.triangle_materials[t]];
      const Material& xb = b.materials[mb.triangle_materials.empty() ? mb.material : mb.triangle_materials[t]];
      if (xa.name != xb.name || (xa.base_color - xb.base_color).norm() > 1e-6 ||
          (xa.emission - xb.emission).norm() > 1e-5 || std::abs(xa.specular - xb.specular) > 1e-6 ||
          std::abs(xa.shininess - xb.shininess) > 1e-4 || (xa.texture < 0) != (xb.texture < 0) ||
          (xa.texture >= 0 && a.textures[xa.texture].rgb != b.textures[xb.texture].rgb))
        ++bad;
    }
    EXPECT_EQ(bad, 0) << oa.name << ": triangles differ";
    triangles += ma.triangles.size();
  }
  std::printf("compared %zu objects, %zu triangles, %zu lights\n", a.objects.size(), triangles, a.lights.size());
}

// Per camera and frame: rovo's images of the original and the round-tripped scene.
void CompareRenders(const std::string& da, const std::string& db) {
  long channels = 0, off_by_more_than_one = 0, depth_pixels = 0, depth_bad = 0;
  for (int f = 0; f < kFrames; ++f)
    for (int c = 0; c < 4; ++c) {
      char name[32];
      std::snprintf(name, sizeof(name), "cam%d/%06d", c, f);
      for (int ch = 0; ch < 3; ++ch) {
        const std::vector<float> x = ReadChannel(da + "/" + name + ".png", "", ch);
        const std::vector<float> y = ReadChannel(db + "/" + name + ".png", "", ch);
        for (size_t i = 0; i < x.size(); ++i, ++channels) off_by_more_than_one += std::abs(x[i] - y[i]) * 255.0f > 1.5f;
      }
      const std::vector<float> x = ReadChannel(da + "/depth/" + name + ".exr", "");
      const std::vector<float> y = ReadChannel(db + "/depth/" + name + ".exr", "");
      for (size_t i = 0; i < x.size(); ++i) {
        if (x[i] <= 0.0f && y[i] <= 0.0f) continue;
        ++depth_pixels;
        depth_bad += std::abs(x[i] - y[i]) > 1e-3f * std::max(1.0f, x[i]);
      }
    }
  std::printf(
      "rovo renders, original vs round trip: %ld of %ld channels differ by more than 1 level; depth differs "
      "(> 0.1%%) at %ld of %ld pixels\n",
      off_by_more_than_one, channels, depth_bad, depth_pixels);
  EXPECT_LE(off_by_more_than_one, channels / 500);  // 0.2%: edges where float32 transforms move a hit
  EXPECT_LE(depth_bad, depth_pixels / 500);
}

// Cycles' depth of the first frame against rovo's (the existing round trip's criterion).
void CompareCyclesDepth(const std::string& rovo_dataset, const std::string& cycles) {
  long common = 0, agree = 0, mismatch = 0, hits = 0;
  for (int c = 0; c < 4; ++c) {
    char name[32];
    std::snprintf(name, sizeof(name), "cam%d/%06d.exr", c, 0);
    const std::vector<float> ours = ReadChannel(rovo_dataset + "/depth/" + name, "");
    const std::vector<float> ref = ReadChannel(cycles + "/" + name, "ViewLayer.Depth.Z");
    for (size_t i = 0; i < ours.size(); ++i) {
      const bool a = ours[i] > 0.0f, b = ref[i] > 0.0f && ref[i] < 1e9f;
      hits += b;
      mismatch += a != b;
      if (!a || !b) continue;
      ++common;
      agree += std::abs(ours[i] - ref[i]) <= 0.01f * ref[i];
    }
  }
  std::printf("Cycles vs rovo depth: %ld of %ld common pixels within 1%%, hit/no-hit differ at %ld of %ld\n", agree,
              common, mismatch, hits);
  EXPECT_GT(common, 4L * kImageSize * kImageSize / 3);
  EXPECT_GE(agree, 0.98 * common);
  EXPECT_LE(mismatch, 0.02 * hits);
}

// Mean linear luminance over pixels that hit geometry in Cycles' first frame, except matte-free
// surfaces: rovo (PNG decoded, divided by the exposure) and Cycles (Combined divided by the film
// exposure). Hits below z = 2 cm (the road or floor) are left out: the indoor floor is glossy, and
// Cycles' Principled highlight is not rovo's Blinn-Phong one.
double MeanLuminanceRatio(const std::string& rovo_dataset, const std::string& cycles, double exposure, double film,
                          const Rigid3& world_from_rig) {
  double sum_rovo = 0.0, sum_cycles = 0.0;
  const Rig rig = EquidistantRovo4();
  for (int c = 0; c < 4; ++c) {
    char name[32];
    std::snprintf(name, sizeof(name), "cam%d/%06d", c, 0);
    std::vector<float> depth = ReadChannel(cycles + "/" + name + ".exr", "ViewLayer.Depth.Z");
    const Rigid3 world_from_cam = world_from_rig * rig.cameras[c].cam_from_rig.Inverse();
    for (int y = 0; y < kImageSize; ++y)
      for (int x = 0; x < kImageSize; ++x) {
        float& d = depth[static_cast<size_t>(y) * kImageSize + x];
        const std::optional<Eigen::Vector3d> b = rig.cameras[c].camera.Unproject(Eigen::Vector2d(x, y));
        if (!b || (world_from_cam * (d * b->normalized())).z() < 0.02) d = 0.0f;
      }
    const float w[3] = {0.2126f, 0.7152f, 0.0722f};
    for (int ch = 0; ch < 3; ++ch) {
      std::vector<float> ours = ReadChannel(rovo_dataset + "/" + name + ".png", "", ch);
      const std::vector<float> ref =
          ReadChannel(cycles + "/" + name + ".exr", std::string("ViewLayer.Combined.") + "RGB"[ch]);
      for (size_t i = 0; i < ours.size(); ++i) {
        if (!(depth[i] > 0.0f && depth[i] < 1e9f)) continue;
        const float v = ours[i];
        const float lin = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
        // Pixels rovo clips (lamps, panels) say nothing about the level: skip them on both sides.
        if (v >= 1.0f) continue;
        sum_rovo += w[ch] * lin / exposure;
        // Clipped at rovo's white level too: pixels on the edge of a lamp or panel (Cycles'
        // samples spread over the pixel) would otherwise dominate the sum.
        sum_cycles += w[ch] * std::min(ref[i] / film, 1.0 / exposure);
      }
    }
  }
  return sum_rovo / sum_cycles;
}

class BlenderPresetRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(BlenderPresetRoundTrip, ContentRendersAndCyclesAgree) {
  Pipeline p;
  p.preset = GetParam();
  const std::string error = p.Run();
  ASSERT_TRUE(error.empty()) << error;
  const Scene original = LoadScene(p.original);
  const Scene exported = LoadScene(p.exported);
  {
    SCOPED_TRACE("trajectory, lighting, lights");
    CompareHeaderAndLights(original, exported);
  }
  {
    SCOPED_TRACE("objects, meshes, materials");
    CompareObjects(original, exported);
  }
  ASSERT_TRUE(p.Render(p.original, p.work + "/render_original", " --rig " + Quote(p.rig)).empty()) << Tail(p.log);
  ASSERT_TRUE(p.Render(p.exported, p.work + "/render_exported", "").empty()) << Tail(p.log);
  {
    SCOPED_TRACE("rovo renders");
    CompareRenders(p.work + "/render_original", p.work + "/render_exported");
  }
  // Cycles, first frame, world light off (rovo's ambient term has no Cycles counterpart).
  const std::string cycles = p.work + "/cycles";
  const std::string no_world =
      "import bpy; [setattr(n.inputs[\"Strength\"], \"default_value\", 0.0) for n in "
      "bpy.context.scene.world.node_tree.nodes if n.type == \"BACKGROUND\"]";
  ASSERT_TRUE(p.Step("cycles", "blender -b " + Quote(p.blend) + " --python-exit-code 1 --python-expr " +
                                   Quote(no_world) + " --python " +
                                   Quote(std::string(ROVO_SOURCE_DIR) + "/scenes/blender/cycles_reference.py") +
                                   " -- " + Quote(cycles) + " --frames 1:2 --samples 32 --threads 2")
                  .empty())
      << Tail(p.log);
  {
    SCOPED_TRACE("Cycles depth");
    CompareCyclesDepth(p.work + "/render_original", cycles);
  }
  if (!original.lights.empty()) {
    SCOPED_TRACE("light units against Cycles");
    // Cycles has no range cut-off (Blender's custom distance is Eevee's): lift it in rovo too.
    nlohmann::json j = ReadJsonFile(p.exported + "/scene.json");
    j["lighting"]["ambient"] = 0.0;
    for (nlohmann::json& l : j["lights"]) l["range"] = 0.0;
    WriteJsonFileAtomic(p.exported + "/scene.json", j);
    ASSERT_TRUE(p.Render(p.exported, p.work + "/render_no_ambient", "").empty()) << Tail(p.log);
    // import_scene.py splits the exposure into film x 2^view with the film part at most 10; Cycles'
    // EXR holds the film part only.
    const double exposure = original.lighting.exposure;
    const double film = exposure > 10.0 ? exposure / std::exp2(std::ceil(std::log2(exposure / 10.0))) : exposure;
    const double ratio = MeanLuminanceRatio(p.work + "/render_no_ambient", cycles, exposure, film,
                                            original.rig_trajectory[0].world_from_rig);
    std::printf("%s: mean luminance rovo / Cycles over lit pixels (ambient and world light off): %.3f\n",
                p.preset.c_str(), ratio);
    EXPECT_NEAR(ratio, 1.0, 0.15);
  }
  if (!::testing::Test::HasFailure()) fs::remove_all(p.work);
}

INSTANTIATE_TEST_SUITE_P(HarderWorlds, BlenderPresetRoundTrip,
                         ::testing::Values("indoor_hall", "suburban_road", "night_street"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace rovo
