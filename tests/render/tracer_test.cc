#include "render/tracer.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>

#include "datasets/rig.h"
#include "tests/render/box_scene.h"

namespace rovo {
namespace {

using testing::IntersectCube;
using testing::IntersectRoom;
using testing::MakeBoxScene;

// Small cameras of the three models.
Camera TestCamera(CameraModelId model) {
  switch (model) {
    case CameraModelId::kEquidistant:
      return MakeRigPreset("omnimvs4").Scaled(0.2).cameras[0].camera;
    case CameraModelId::kOcam:
      return MakeRigPreset("rovo4").Scaled(0.1).cameras[0].camera;
    case CameraModelId::kDoubleSphere: {
      Camera cam;
      cam.model = CameraModelId::kDoubleSphere;
      cam.width = 160;
      cam.height = 150;
      cam.params = {44.0, 44.0, 79.5, 74.5, -0.18, 0.59};
      cam.max_fov_deg = 195.0;
      cam.Check("double sphere test camera");
      return cam;
    }
    case CameraModelId::kExtendedUnified: {
      Camera cam;
      cam.model = CameraModelId::kExtendedUnified;
      cam.width = 160;
      cam.height = 150;
      cam.params = {52.0, 52.0, 79.5, 74.5, 0.62, 1.1};
      cam.max_fov_deg = 195.0;
      cam.Check("extended unified test camera");
      return cam;
    }
  }
  return {};
}

// World_from_cam of camera `c` of the omnimvs4 rig at `frame` of the box scene.
Rigid3 WorldFromCam(const Scene& scene, int frame, int c) {
  const Rig rig = MakeRigPreset("omnimvs4");
  return scene.rig_trajectory[frame].world_from_rig * rig.cameras[c].cam_from_rig.Inverse();
}

class GeometryTest : public ::testing::TestWithParam<CameraModelId> {};

// Every valid pixel's depth equals the analytic ray length to the room within 1 mm and its mask
// names the right face; known points on the faces reproject within 0.5 px of their pixel centre.
TEST_P(GeometryTest, DepthAndFaceMatchAnalyticRoom) {
  const Scene scene = MakeBoxScene(3, false);
  const Camera camera = TestCamera(GetParam());
  Tracer tracer(scene);
  tracer.SetFrame(1);
  const CameraRays rays = CameraRays::Make(camera);
  ASSERT_GT(rays.num_valid, camera.width * camera.height / 3);
  for (int c = 0; c < 4; ++c) {
    const Rigid3 world_from_cam = WorldFromCam(scene, 1, c);
    ShadeSettings settings;
    settings.spp = 1;
    settings.want_depth = true;
    settings.want_mask = true;
    CameraImage image;
    tracer.Render(rays, world_from_cam, settings, &image);
    ASSERT_EQ(image.width, camera.width);
    int checked = 0;
    double max_err = 0.0;
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        const size_t i = static_cast<size_t>(y) * camera.width + x;
        if (!rays.valid[i]) {
          EXPECT_EQ(image.depth[i], 0.0f);
          EXPECT_EQ(image.mask[i], 0);
          EXPECT_EQ(image.rgb[3 * i] | image.rgb[3 * i + 1] | image.rgb[3 * i + 2], 0);
          continue;
        }
        const std::optional<Eigen::Vector3d> bearing = camera.Unproject(Eigen::Vector2d(x, y));
        ASSERT_TRUE(bearing.has_value());
        double t = 0;
        int face = 0;
        ASSERT_TRUE(IntersectRoom(world_from_cam.translation, world_from_cam.rotation * *bearing, &t, &face));
        max_err = std::max(max_err, std::abs(image.depth[i] - t));
        EXPECT_NEAR(image.depth[i], t, 1e-3) << "pixel " << x << "," << y;
        // Pixels whose ray passes within 2 mm of a room edge may see either face.
        const Eigen::Vector3d hit = world_from_cam.translation + t * (world_from_cam.rotation * *bearing);
        bool near_edge = false;
        for (int a = 0; a < 3; ++a) {
          for (double plane : {testing::kRoomMin[a], testing::kRoomMax[a]}) {
            if (std::abs(hit[a] - plane) < 2e-3 && (face - 1) / 2 != (a == 2 ? 0 : a == 0 ? 1 : 2)) near_edge = true;
          }
        }
        if (!near_edge) {
          EXPECT_EQ(image.mask[i], face) << "pixel " << x << "," << y;
        }
        ++checked;
        EXPECT_GT(image.rgb[3 * i] + image.rgb[3 * i + 1] + image.rgb[3 * i + 2], 0);
      }
    }
    EXPECT_EQ(checked, rays.num_valid);
    EXPECT_LT(max_err, 1e-3);

    // Known points: a 0.5 m grid on every face.
    const Rigid3 cam_from_world = world_from_cam.Inverse();
    int points = 0;
    for (int a = 0; a < 3; ++a) {
      for (int side = 0; side < 2; ++side) {
        const int b = (a + 1) % 3, d = (a + 2) % 3;
        for (double sb = testing::kRoomMin[b] + 0.25; sb < testing::kRoomMax[b]; sb += 0.5) {
          for (double sd = testing::kRoomMin[d] + 0.25; sd < testing::kRoomMax[d]; sd += 0.5) {
            Eigen::Vector3d p;
            p[a] = side == 0 ? testing::kRoomMin[a] : testing::kRoomMax[a];
            p[b] = sb;
            p[d] = sd;
            const std::optional<Eigen::Vector2d> uv = camera.Project(cam_from_world * p);
            if (!uv || !camera.InFov(cam_from_world * p)) continue;
            const int px = static_cast<int>(std::lround(uv->x())), py = static_cast<int>(std::lround(uv->y()));
            if (px < 0 || py < 0 || px >= camera.width || py >= camera.height) continue;
            const size_t i = static_cast<size_t>(py) * camera.width + px;
            if (!rays.valid[i]) continue;
            const int face = (a == 2 ? 1 : a == 0 ? 3 : 5) + side;
            EXPECT_EQ(image.mask[i], face) << "point " << p.transpose();
            // The rendered hit at that pixel reprojects to the pixel centre, which is within
            // 0.5 px (per axis) of the known point's projection.
            const Eigen::Vector3d hit_in_cam = image.depth[i] * rays.bearing[i].cast<double>();
            const std::optional<Eigen::Vector2d> uv_hit = camera.Project(hit_in_cam);
            ASSERT_TRUE(uv_hit.has_value());
            EXPECT_LT((*uv_hit - Eigen::Vector2d(px, py)).norm(), 0.01);
            EXPECT_LE((*uv_hit - *uv).cwiseAbs().maxCoeff(), 0.51);
            ++points;
          }
        }
      }
    }
    EXPECT_GT(points, 50);
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, GeometryTest,
                         ::testing::Values(CameraModelId::kEquidistant, CameraModelId::kDoubleSphere,
                                           CameraModelId::kOcam),
                         [](const ::testing::TestParamInfo<CameraModelId>& info) {
                           return CameraModelName(info.param);
                         });

TEST(TracerTest, DynamicObjectFollowsItsPerFrameTransform) {
  const Scene scene = MakeBoxScene(3, true);
  const Camera camera = TestCamera(CameraModelId::kEquidistant);
  const CameraRays rays = CameraRays::Make(camera);
  Tracer tracer(scene);
  std::vector<uint16_t> masks[2];
  for (int k = 0; k < 2; ++k) {
    const int frame = 2 * k;
    tracer.SetFrame(frame);
    const Rigid3 world_from_cam = WorldFromCam(scene, frame, 0);  // camera 0 looks along +x
    ShadeSettings settings;
    settings.want_depth = true;
    settings.want_mask = true;
    CameraImage image;
    tracer.Render(rays, world_from_cam, settings, &image);
    int mover_pixels = 0;
    for (size_t i = 0; i < image.mask.size(); ++i) {
      if (!rays.valid[i]) continue;
      const Eigen::Vector3d dir =
          world_from_cam.rotation * rays.camera.Unproject(Eigen::Vector2d(i % camera.width, i / camera.width)).value();
      double t_room = 0, t_cube = 0;
      int face = 0;
      ASSERT_TRUE(IntersectRoom(world_from_cam.translation, dir, &t_room, &face));
      const bool cube =
          IntersectCube(world_from_cam.translation, dir, testing::MoverCentre(frame), testing::kMoverHalf, &t_cube) &&
          t_cube < t_room;
      const double t = cube ? t_cube : t_room;
      EXPECT_NEAR(image.depth[i], t, 1e-3)
          << "frame " << frame << " pixel " << i % camera.width << "," << i / camera.width << " cube " << cube;
      if (cube && std::abs(image.depth[i] - t) < 1e-3) {
        EXPECT_EQ(image.mask[i], 7);
        ++mover_pixels;
      }
    }
    EXPECT_GT(mover_pixels, 20) << "frame " << frame;
    masks[k] = image.mask;
  }
  EXPECT_NE(masks[0], masks[1]);
}

TEST(TracerTest, ImagesAreIdenticalForOneAndTwoThreads) {
  const Scene scene = MakeBoxScene(2, true);
  const Camera camera = TestCamera(CameraModelId::kOcam);
  const CameraRays rays = CameraRays::Make(camera);
  Tracer tracer(scene);
  tracer.SetFrame(1);
  ShadeSettings settings;
  settings.spp = 4;
  settings.want_depth = true;
  settings.want_mask = true;
  settings.vignetting = 0.3f;
  CameraImage images[2];
  for (int k = 0; k < 2; ++k) {
    tbb::task_arena arena(k + 1);
    arena.execute([&] { tracer.Render(rays, WorldFromCam(scene, 1, 2), settings, &images[k]); });
  }
  EXPECT_EQ(images[0].rgb, images[1].rgb);
  EXPECT_EQ(images[0].depth, images[1].depth);
  EXPECT_EQ(images[0].mask, images[1].mask);
}

// Open ground plane, a floating occluder between a ground point and the sun, a camera looking down.
TEST(TracerTest, SunShadowsAreDarkerAndMissesShowTheSky) {
  Scene scene;
  Material ground;
  ground.name = "ground";
  ground.base_color = Eigen::Vector3f(0.5f, 0.5f, 0.5f);
  scene.materials.push_back(ground);
  scene.meshes.push_back(testing::MakeQuad("ground", Eigen::Vector3f(-50, -50, 0), Eigen::Vector3f(50, -50, 0),
                                           Eigen::Vector3f(50, 50, 0), Eigen::Vector3f(-50, 50, 0), 0));
  scene.meshes[0].uvs.clear();
  scene.meshes.push_back(testing::MakeCube("occluder", 0.4f, 0));
  const Eigen::Vector3d sun = Eigen::Vector3d(0.3, 0.2, 0.9).normalized();
  scene.lighting.direction_to_sun = sun;
  const Eigen::Vector3d shadowed(1.0, 0.0, 0.0), lit(-1.0, 0.5, 0.0);
  Object g;
  g.name = "ground";
  g.mesh = 0;
  scene.objects.push_back(g);
  Object o;
  o.name = "occluder";
  o.mesh = 1;
  o.world_from_object = Rigid3(Eigen::Quaterniond::Identity(), shadowed + sun * (1.5 / sun.z()));
  scene.objects.push_back(o);
  StampedPose pose;
  scene.rig_trajectory.push_back(pose);

  Eigen::Matrix3d world_from_cam_rot;
  world_from_cam_rot.col(0) = Eigen::Vector3d(1, 0, 0);
  world_from_cam_rot.col(1) = Eigen::Vector3d(0, -1, 0);
  world_from_cam_rot.col(2) = Eigen::Vector3d(0, 0, -1);
  const Rigid3 world_from_cam(world_from_cam_rot, Eigen::Vector3d(0, 0, 3));
  const Camera camera = TestCamera(CameraModelId::kEquidistant);
  const CameraRays rays = CameraRays::Make(camera);
  Tracer tracer(scene);
  ShadeSettings settings;
  settings.want_depth = true;
  settings.want_mask = true;
  CameraImage image;
  tracer.Render(rays, world_from_cam, settings, &image);
  auto luminance_at = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d uv = camera.Project(world_from_cam.Inverse() * p).value();
    const size_t i = static_cast<size_t>(std::lround(uv.y())) * camera.width + std::lround(uv.x());
    return image.rgb[3 * i] + image.rgb[3 * i + 1] + image.rgb[3 * i + 2];
  };
  EXPECT_LT(luminance_at(shadowed), 0.7 * luminance_at(lit));
  EXPECT_GT(luminance_at(shadowed), 0);  // ambient light: shadows are not black

  // The 220-degree lens looking down sees the sky near its rim: no hit, depth 0, sky colour.
  int sky_pixels = 0;
  for (size_t i = 0; i < image.depth.size(); ++i) {
    if (!rays.valid[i]) continue;
    const Eigen::Vector3d dir = world_from_cam.rotation * rays.bearing[i].cast<double>();
    if (dir.z() > 0.05) {
      EXPECT_EQ(image.depth[i], 0.0f);
      EXPECT_GT(image.rgb[3 * i + 2], image.rgb[3 * i]);  // bluish
      ++sky_pixels;
    }
  }
  EXPECT_GT(sky_pixels, 100);
}

TEST(TracerTest, RejectsBadIndicesNamingTheCulprit) {
  Scene scene = MakeBoxScene(1, false);
  scene.meshes[2].triangles[0][1] = 99;
  try {
    Tracer tracer(scene);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("wall_xm"), std::string::npos) << e.what();
  }
  scene = MakeBoxScene(1, false);
  scene.materials[1].texture = 42;
  EXPECT_THROW(Tracer{scene}, std::invalid_argument);
}

TEST(CameraRaysTest, SubPixelBearingsMatchUnproject) {
  const Camera camera = TestCamera(CameraModelId::kOcam);
  const CameraRays rays = CameraRays::Make(camera);
  double max_angle = 0.0;
  for (float v = 10.3f; v < camera.height - 10; v += 7.7f) {
    for (float u = 10.1f; u < camera.width - 10; u += 6.9f) {
      Eigen::Vector3f b;
      const std::optional<Eigen::Vector3d> exact = camera.Unproject(Eigen::Vector2d(u, v));
      if (!exact || !camera.InFov(*exact)) continue;
      ASSERT_TRUE(rays.SampleBearing(u, v, &b));
      max_angle = std::max(max_angle, AngleBetween(b.cast<double>(), *exact));
    }
  }
  // Far below a pixel (about 0.03 rad at this size).
  EXPECT_LT(max_angle, 1e-4);
}

// The fixed pattern is N-rooks: for spp = N, every one of the N columns and N rows of the
// pixel's N x N grid holds exactly one sample, and all offsets lie in [-1/2, 1/2).
TEST(CameraRaysTest, SampleOffsetsAreNRooks) {
  EXPECT_EQ(CameraRays::SampleOffset(0, 1), Eigen::Vector2f::Zero());
  for (int spp : {2, 4, 8, 16}) {
    std::vector<int> columns(spp, 0), rows(spp, 0);
    for (int s = 0; s < spp; ++s) {
      const Eigen::Vector2f o = CameraRays::SampleOffset(s, spp);
      ASSERT_GE(o.x(), -0.5f);
      ASSERT_LT(o.x(), 0.5f);
      ASSERT_GE(o.y(), -0.5f);
      ASSERT_LT(o.y(), 0.5f);
      ++columns[static_cast<int>((o.x() + 0.5f) * spp)];
      ++rows[static_cast<int>((o.y() + 0.5f) * spp)];
    }
    for (int k = 0; k < spp; ++k) {
      EXPECT_EQ(columns[k], 1) << "spp " << spp << " column " << k;
      EXPECT_EQ(rows[k], 1) << "spp " << spp << " row " << k;
    }
  }
  // spp 2: the two diagonal quarter points.
  EXPECT_LT((CameraRays::SampleOffset(0, 2) - Eigen::Vector2f(-0.25f, -0.25f)).norm(), 1e-6f);
  EXPECT_LT((CameraRays::SampleOffset(1, 2) - Eigen::Vector2f(0.25f, 0.25f)).norm(), 1e-6f);
}

// Sample bearings precomputed by Make(camera, threads, spp) give the same image as bearings
// interpolated during the render, and MakeCameraRays shares tables between identical cameras.
TEST(CameraRaysTest, PrecomputedSamplesRenderTheSameImage) {
  const Scene scene = MakeBoxScene(2, true);
  const Camera camera = TestCamera(CameraModelId::kEquidistant);
  const CameraRays plain = CameraRays::Make(camera);
  EXPECT_EQ(plain.sample_spp, 0);
  Camera other = camera;
  other.params[0] *= 1.01;
  const RigCameraRays rays = MakeCameraRays({camera, other, camera}, 0, 2);
  ASSERT_EQ(rays.size(), 3u);
  ASSERT_EQ(rays[0]->sample_spp, 2);
  ASSERT_EQ(rays[0]->sample_bearing.size(), 2u);
  EXPECT_EQ(rays[2], rays[0]) << "one shared table";
  EXPECT_NE(rays[1]->bearing, rays[0]->bearing);
  // Many samples are not stored (memory), they are interpolated during the render.
  EXPECT_EQ(CameraRays::Make(camera, 0, CameraRays::kMaxPrecomputedSpp + 1).sample_spp, 0);
  Tracer tracer(scene);
  tracer.SetFrame(1);
  ShadeSettings settings;
  settings.spp = 2;
  CameraImage precomputed, on_the_fly;
  tracer.Render(*rays[0], WorldFromCam(scene, 1, 0), settings, &precomputed);
  tracer.Render(plain, WorldFromCam(scene, 1, 0), settings, &on_the_fly);
  EXPECT_EQ(precomputed.rgb, on_the_fly.rgb);
  // And 2 spp differs from the pixel centres (the samples are really off-centre).
  settings.spp = 1;
  CameraImage centres;
  tracer.Render(plain, WorldFromCam(scene, 1, 0), settings, &centres);
  EXPECT_NE(centres.rgb, precomputed.rgb);
}

}  // namespace
}  // namespace rovo
