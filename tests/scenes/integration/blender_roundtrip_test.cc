// Blender round trip: a scene built with bpy (tests/scenes/blender/make_roundtrip_scene.py) is
// exported (scenes/blender/export_scene.py), rendered with `rovo render --depth` and with Cycles
// (scenes/blender/cycles_reference.py), and the two depth maps are compared pixel by pixel.
// Depth is the ray length in metres in both (Cycles: the Depth pass of a panoramic camera is
// |hit - camera position|). Agreement proves that lens, axes, extrinsics, trajectory, geometry
// (scale baking, instances, animation) and the exporter agree with Blender.
//
// Needs `blender` (Debian package) and `oiiotool` (openimageio-tools) on PATH.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "datasets/image_file.h"
#include "datasets/rig_json.h"
#include "scenes/scene.h"
#include "tests/scenes/integration/shell_log.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;
using testing::Quote;
using testing::RunShell;
using testing::Tail;

constexpr int kImageSize = 192;  // square: Cycles' fisheye normalises u and v separately
constexpr int kFrames = 2;
constexpr int kCameras = 4;

// One float channel of an EXR (by exact name, or the first channel when `channel` is empty).
std::vector<float> ReadExrChannel(const std::string& path, const std::string& channel, int* width, int* height) {
  FloatImage exr = ReadExr(path);
  const int index = channel.empty() ? 0 : exr.Channel(channel);
  if (index < 0 || exr.planes.empty()) throw std::runtime_error(path + ": no channel " + channel);
  *width = exr.width;
  *height = exr.height;
  return std::move(exr.planes[static_cast<size_t>(index)]);
}

// The pipeline's folders; Run() makes the scene, exports it and renders it both ways.
struct RoundTrip {
  std::string work, log, blend, exported, cycles, dataset;

  // Returns "" on success, else which step failed with the log's tail.
  std::string Run() {
    work = (fs::path(::testing::TempDir()) / ("rovo_blender_roundtrip_" + std::to_string(getpid()))).string();
    fs::remove_all(work);
    fs::create_directories(work);
    log = work + "/log.txt";
    blend = work + "/roundtrip.blend";
    exported = work + "/exported";
    cycles = work + "/cycles";
    dataset = work + "/dataset";
    const std::string src = ROVO_SOURCE_DIR;
    const std::string blender = "blender -b --factory-startup ";
    if (RunShell("command -v blender", log) != 0) return "blender is not on PATH (Debian package `blender`)";
    struct Step {
      std::string name, command;
    };
    const std::vector<Step> steps = {
        {"make scene", blender + "--python-exit-code 1 --python " +
                           Quote(src + "/tests/scenes/blender/make_roundtrip_scene.py") + " -- " + Quote(blend) +
                           " --size " + std::to_string(kImageSize) + " --frames " + std::to_string(kFrames)},
        {"export", blender + Quote(blend) + " --python-exit-code 1 --python " +
                       Quote(src + "/scenes/blender/export_scene.py") + " -- " + Quote(exported)},
        {"cycles", blender + Quote(blend) + " --python-exit-code 1 --python " +
                       Quote(src + "/scenes/blender/cycles_reference.py") + " -- " + Quote(cycles) +
                       " --samples 16 --threads 2"},
        {"rovo render", Quote(ROVO_BINARY) + " render --scene " + Quote(exported) + " --rig " +
                            Quote(exported + "/rig.json") + " --out " + Quote(dataset) +
                            " --depth --spp 1 --threads 2 --quiet"},
    };
    for (const Step& step : steps) {
      if (RunShell(step.command, log) != 0) return step.name + " failed:\n" + Tail(log);
    }
    return "";
  }
};

void CheckExportedScene(const RoundTrip& rt) {
  const Scene scene = LoadScene(rt.exported);
  EXPECT_EQ(scene.metadata.preset, "blender");
  EXPECT_EQ(scene.frame_rate, 10.0);
  ASSERT_EQ(scene.rig_trajectory.size(), static_cast<size_t>(kFrames));
  EXPECT_NEAR(scene.rig_trajectory[1].timestamp, 0.1, 1e-12);
  // Rig Empty: (0, 0, 1.8) yaw 10 deg at Blender frame 1; halfway to (1.2, 0.3, 1.85) at frame 2.
  EXPECT_LT((scene.rig_trajectory[0].world_from_rig.translation - Eigen::Vector3d(0, 0, 1.8)).norm(), 1e-6);
  EXPECT_LT((scene.rig_trajectory[1].world_from_rig.translation - Eigen::Vector3d(0.6, 0.15, 1.825)).norm(), 1e-6);
  EXPECT_NEAR(RollPitchYawDegFromQuaternion(scene.rig_trajectory[0].world_from_rig.rotation).z(), 10.0, 1e-4);

  // room, 4 boxes (one moving), sphere, panel, 2 collection instances sharing one cone mesh.
  EXPECT_EQ(scene.objects.size(), 9u);
  EXPECT_EQ(scene.meshes.size(), 8u);
  int dynamic = 0, cones = 0;
  for (const Object& object : scene.objects) {
    if (object.IsDynamic()) {
      ++dynamic;
      EXPECT_EQ(object.name, "mover");
      EXPECT_EQ(object.id, 1);
      ASSERT_EQ(object.world_from_object_per_frame.size(), static_cast<size_t>(kFrames));
      EXPECT_LT((object.world_from_object_per_frame[1].translation - Eigen::Vector3d(3.0, 0.0, 0.8)).norm(), 1e-6);
    } else {
      EXPECT_EQ(object.id, 0);
    }
    if (object.name.rfind("cone[", 0) == 0) ++cones;
  }
  EXPECT_EQ(dynamic, 1);
  EXPECT_EQ(cones, 2);

  // The room is a 2 m cube scaled (12, 9, 3.5) at (1, -0.5, 3): the scale is baked into the mesh.
  const Object* room = nullptr;
  for (const Object& object : scene.objects) {
    if (object.name == "room") room = &object;
  }
  ASSERT_NE(room, nullptr);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const Eigen::Vector3f& p : scene.meshes[room->mesh].positions) {
    const Eigen::Vector3d w = room->world_from_object * p.cast<double>();
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  EXPECT_LT((lo - Eigen::Vector3d(-11.0, -9.5, -0.5)).norm(), 1e-5);
  EXPECT_LT((hi - Eigen::Vector3d(13.0, 8.5, 6.5)).norm(), 1e-5);
  EXPECT_FALSE(scene.meshes[room->mesh].triangle_materials.empty());  // wall + floor slots

  // Two generated 64x64 checker textures; sun and sky from the .blend.
  ASSERT_EQ(scene.textures.size(), 2u);
  EXPECT_EQ(scene.textures[0].width, 64);
  EXPECT_NEAR(scene.lighting.sun_radiance.x(), 3.0, 1e-5);
  EXPECT_NEAR(scene.lighting.sky_zenith.z(), 0.7, 1e-6);

  const Rig rig = ReadRigJson(rt.exported + "/rig.json");
  ASSERT_EQ(rig.NumCameras(), kCameras);
  const double fov = 220.0 * M_PI / 180.0;
  for (const RigCamera& cam : rig.cameras) {
    EXPECT_EQ(cam.camera.width, kImageSize);
    EXPECT_NEAR(cam.camera.params[0], kImageSize / fov, 1e-4);
    EXPECT_NEAR(cam.camera.params[2], kImageSize / 2.0 - 0.5, 1e-12);
    EXPECT_NEAR(cam.camera.max_fov_deg, 220.0, 1e-4);
    // Cameras 0.2 m from the rig centre, optical axes 5 deg above the horizon.
    EXPECT_NEAR(CameraPositionInRig(cam.cam_from_rig).head<2>().norm(), 0.2, 1e-6);
    EXPECT_NEAR(CameraPitchDeg(cam.cam_from_rig), 5.0, 1e-4);
  }
  EXPECT_NEAR(CameraYawDeg(rig.cameras[0].cam_from_rig), 45.0, 1e-4);
  EXPECT_NEAR(CameraYawDeg(rig.cameras[1].cam_from_rig), 135.0, 1e-4);
}

void CheckDepthAgainstCycles(const RoundTrip& rt) {
  long common = 0, agree = 0, hit_mismatch = 0, cycles_hits = 0;
  double sum_rel = 0.0;
  for (int frame = 0; frame < kFrames; ++frame) {
    for (int cam = 0; cam < kCameras; ++cam) {
      char name[32];
      std::snprintf(name, sizeof(name), "cam%d/%06d.exr", cam, frame);
      int w = 0, h = 0, cw = 0, ch = 0;
      const std::vector<float> ours = ReadExrChannel(rt.dataset + "/depth/" + name, "", &w, &h);
      const std::vector<float> ref = ReadExrChannel(rt.cycles + "/" + name, "ViewLayer.Depth.Z", &cw, &ch);
      ASSERT_EQ(w, cw);
      ASSERT_EQ(h, ch);
      long view_common = 0, view_agree = 0;
      for (size_t i = 0; i < ours.size(); ++i) {
        const bool ours_hit = ours[i] > 0.0f && std::isfinite(ours[i]);
        const bool ref_hit = ref[i] > 0.0f && ref[i] < 1e9f;  // Cycles: 1e10 = no hit / outside the lens
        cycles_hits += ref_hit;
        if (ours_hit != ref_hit) ++hit_mismatch;
        if (!ours_hit || !ref_hit) continue;
        const double rel = std::abs(static_cast<double>(ours[i]) - ref[i]) / ref[i];
        ++view_common;
        sum_rel += rel;
        if (rel <= 0.01) ++view_agree;
      }
      std::printf("frame %d cam%d: %ld/%ld commonly valid pixels agree within 1%%\n", frame, cam, view_agree,
                  view_common);
      common += view_common;
      agree += view_agree;
    }
  }
  const double fraction = static_cast<double>(agree) / std::max(common, 1L);
  const double mismatch = static_cast<double>(hit_mismatch) / std::max(cycles_hits, 1L);
  std::printf(
      "rovo render vs Cycles depth: %.4f of %ld commonly valid pixels agree within 1%% relative "
      "(mean relative difference %.2e); hit/no-hit disagree at %.4f of Cycles' hits\n",
      fraction, common, sum_rel / std::max(common, 1L), mismatch);
  // Not vacuous: most of the image circle sees geometry (the room is open only at the top).
  EXPECT_GT(common, static_cast<long>(0.4 * kFrames * kCameras * kImageSize * kImageSize));
  EXPECT_GE(fraction, 0.98);
  EXPECT_LE(mismatch, 0.02);
}

// Linear luminance of an 8-bit sRGB PNG (rovo) or of Cycles' Combined pass.
std::vector<float> Luminance(const std::string& path, bool cycles) {
  std::vector<float> rgb[3];
  int w = 0, h = 0;
  for (int c = 0; c < 3; ++c) {
    if (cycles) {
      rgb[c] = ReadExrChannel(path, std::string("ViewLayer.Combined.") + "RGB"[c], &w, &h);
    } else {
      const Image8 png = ReadPng8(path, {3, true});
      w = png.width;
      h = png.height;
      rgb[c].resize(static_cast<size_t>(w) * h);
      for (size_t i = 0; i < rgb[c].size(); ++i) {
        const float v = png.pixels[3 * i + static_cast<size_t>(c)] / 255.0f;
        rgb[c][i] = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
      }
    }
  }
  std::vector<float> y(rgb[0].size());
  for (size_t i = 0; i < y.size(); ++i) y[i] = 0.2126f * rgb[0][i] + 0.7152f * rgb[1][i] + 0.0722f * rgb[2][i];
  return y;
}

// Colour is not expected to match exactly (rovo's ambient term approximates Cycles' sky light, and
// Cycles at 16 spp is noisy), but textures, UV orientation and materials must line up: the
// normalised cross-correlation of the luminance over pixels that hit geometry in both is high
// (a texture flipped in v turns the wall checkers' correlation negative).
void CheckColourAgainstCycles(const RoundTrip& rt) {
  double worst = 1.0;
  for (int frame = 0; frame < kFrames; ++frame) {
    for (int cam = 0; cam < kCameras; ++cam) {
      char name[32];
      std::snprintf(name, sizeof(name), "cam%d/%06d", cam, frame);
      int w = 0, h = 0;
      const std::vector<float> depth = ReadExrChannel(rt.cycles + "/" + name + ".exr", "ViewLayer.Depth.Z", &w, &h);
      const std::vector<float> ours = Luminance(rt.dataset + "/" + name + ".png", false);
      const std::vector<float> ref = Luminance(rt.cycles + "/" + name + ".exr", true);
      ASSERT_EQ(ours.size(), ref.size());
      double n = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
      for (size_t i = 0; i < ours.size(); ++i) {
        if (!(depth[i] > 0.0f && depth[i] < 1e9f)) continue;
        n += 1;
        sa += ours[i];
        sb += ref[i];
        saa += double(ours[i]) * ours[i];
        sbb += double(ref[i]) * ref[i];
        sab += double(ours[i]) * ref[i];
      }
      const double cov = sab / n - (sa / n) * (sb / n);
      const double ncc = cov / std::sqrt((saa / n - (sa / n) * (sa / n)) * (sbb / n - (sb / n) * (sb / n)));
      std::printf("frame %d cam%d: luminance NCC %.3f over %.0f pixels\n", frame, cam, ncc, n);
      worst = std::min(worst, ncc);
    }
  }
  std::printf("rovo render vs Cycles colour: worst luminance NCC %.3f\n", worst);
  EXPECT_GT(worst, 0.8);
}

void CheckRigWithBlenderRayCast(const RoundTrip& rt) {
  // Independent of `rovo render`: Blender's own ray caster through the exported rig.json and
  // trajectory against the Cycles depth (lens mapping, camera axes, extrinsics, trajectory).
  const std::string command = "blender -b --factory-startup " + Quote(rt.blend) + " --python-exit-code 1 --python " +
                              Quote(std::string(ROVO_SOURCE_DIR) + "/tests/scenes/blender/check_lens_raycast.py") +
                              " -- " + Quote(rt.exported) + " " + Quote(rt.cycles) + " --stride 6 --min-agree 0.99";
  const std::string log = rt.work + "/raycast_log.txt";
  EXPECT_EQ(RunShell(command, log), 0) << Tail(log);
}

// One test (one pipeline run; CTest runs each gtest case in its own process): scene, export,
// Cycles and rovo renders take about a minute on 2 idle cores.
TEST(BlenderRoundTrip, ExportRenderAndCompareWithCycles) {
  RoundTrip rt;
  const std::string error = rt.Run();
  ASSERT_TRUE(error.empty()) << error;
  {
    SCOPED_TRACE("exported scene and rig");
    CheckExportedScene(rt);
  }
  {
    SCOPED_TRACE("depth vs Cycles");
    CheckDepthAgainstCycles(rt);
  }
  {
    SCOPED_TRACE("colour vs Cycles");
    CheckColourAgainstCycles(rt);
  }
  {
    SCOPED_TRACE("Blender ray cast through the exported rig");
    CheckRigWithBlenderRayCast(rt);
  }
  if (!::testing::Test::HasFailure()) fs::remove_all(rt.work);
}

}  // namespace
}  // namespace rovo
