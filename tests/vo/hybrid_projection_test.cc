#include "vo/hybrid_projection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <string>

#include "datasets/rig.h"

namespace rovo {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Double-sphere lens scaled so that 110 deg off-axis lands `radius_px` from the centre.
Camera DoubleSphereCamera(int width, int height, double radius_px) {
  Camera camera;
  camera.model = CameraModelId::kDoubleSphere;
  camera.width = width;
  camera.height = height;
  camera.max_fov_deg = 220.0;
  camera.params = {1.0, 1.0, 0.0, 0.0, -0.2, 0.6};
  const Eigen::Vector3d edge(std::sin(110 * kDeg), 0.0, std::cos(110 * kDeg));
  const auto uv = camera.Project(edge);
  EXPECT_TRUE(uv.has_value());
  const double f = radius_px / uv->x();
  camera.params = {f, f, 0.5 * (width - 1), 0.5 * (height - 1), -0.2, 0.6};
  return camera;
}

// A ring rig of n cameras facing outwards at equal yaw steps, all with the given lens.
Rig RingRig(int n, double radius_m, const Camera& camera, double first_yaw_deg = 0.0) {
  Rig rig;
  for (int i = 0; i < n; ++i) {
    const double yaw = first_yaw_deg + 360.0 * i / n;
    RigCamera rc;
    rc.name = "cam" + std::to_string(i);
    rc.camera = camera;
    rc.cam_from_rig = CamFromRigFromMount(
        yaw, 0.0, Eigen::Vector3d(radius_m * std::cos(yaw * kDeg), radius_m * std::sin(yaw * kDeg), 0.0));
    rig.cameras.push_back(rc);
  }
  return rig;
}

struct NamedRig {
  std::string name;
  Rig rig;
};

std::vector<NamedRig> TestRigs() {
  std::vector<NamedRig> rigs;
  rigs.push_back({"rovo4 (ocam)", MakeRigPreset("rovo4").Scaled(0.5)});
  rigs.push_back({"omnimvs4 (equidistant)", MakeRigPreset("omnimvs4")});
  rigs.push_back({"ring3 (double sphere)", RingRig(3, 0.5, DoubleSphereCamera(640, 600, 290))});
  return rigs;
}

// Round trip warped -> bearing -> fisheye -> bearing -> warped over the valid area, every model.
TEST(HybridProjection, RoundTripBelowFiveHundredthsOfAPixel) {
  for (const NamedRig& named : TestRigs()) {
    const auto projections = HybridProjection::ForRig(named.rig);
    for (size_t c = 0; c < projections.size(); ++c) {
      const HybridProjection& p = projections[c];
      double worst = 0.0;
      int checked = 0;
      for (int v = 0; v < p.height(); v += 5) {
        for (int u = 0; u < p.width(); u += 5) {
          if (u + 1 >= p.width() || v + 1 >= p.height()) continue;
          const cv::Mat& mask = p.valid_mask();
          if (!mask.at<uint8_t>(v, u) || !mask.at<uint8_t>(v + 1, u + 1) || !mask.at<uint8_t>(v, u + 1) ||
              !mask.at<uint8_t>(v + 1, u)) {
            continue;
          }
          const Eigen::Vector2d warped(u + 0.25, v + 0.75);
          const auto bearing = p.BearingFromWarped(warped);
          ASSERT_TRUE(bearing.has_value()) << named.name;
          EXPECT_NEAR(bearing->norm(), 1.0, 1e-12);
          const auto fisheye = p.camera().Project(*bearing);
          ASSERT_TRUE(fisheye.has_value()) << named.name;
          const auto bearing_back = p.camera().Unproject(*fisheye);
          ASSERT_TRUE(bearing_back.has_value()) << named.name << " fisheye " << fisheye->transpose();
          const auto warped_back = p.WarpedFromBearing(*bearing_back);
          ASSERT_TRUE(warped_back.has_value()) << named.name;
          worst = std::max(worst, (*warped_back - warped).norm());
          ++checked;
        }
      }
      EXPECT_GT(checked, 1000) << named.name << " camera " << c;
      EXPECT_LT(worst, 0.05) << named.name << " camera " << c;
    }
  }
}

// The float maps (interpolated between exact nodes) agree with FisheyeFromWarped within 0.02 px at
// every pixel, valid exactly where the exact function lands in the image, and the valid area is a
// large part of the image; for every camera of both rigs.
TEST(HybridProjection, MapsMatchExactFunctions) {
  for (const char* rig_name : {"omnimvs4", "rovo4"}) {
    const Rig rig = MakeRigPreset(rig_name).Scaled(0.5);
    const auto projections = HybridProjection::ForRig(rig);
    for (const HybridProjection& p : projections) {
      int valid = 0;
      double worst = 0.0;
      for (int v = 0; v < p.height(); ++v) {
        for (int u = 0; u < p.width(); ++u) {
          const auto uv = p.FisheyeFromWarped(Eigen::Vector2d(u, v));
          const bool inside =
              uv && uv->x() >= 0 && uv->y() >= 0 && uv->x() <= p.camera().width - 1 && uv->y() <= p.camera().height - 1;
          ASSERT_EQ(p.valid_mask().at<uint8_t>(v, u) != 0, inside) << rig_name << " " << u << "," << v;
          if (!inside) continue;
          ++valid;
          worst = std::max(worst, (Eigen::Vector2d(p.map_x().at<float>(v, u), p.map_y().at<float>(v, u)) - *uv).norm());
        }
      }
      EXPECT_LT(worst, 0.02) << rig_name;
      EXPECT_GT(valid, 0.8 * p.width() * p.height()) << rig_name;
    }
  }
}

// Bands of rows warped one by one (the front-end warps them in parallel) are the whole warp's pixels;
// a band outside the image leaves the buffer alone, a buffer of the wrong size is refused.
TEST(HybridProjection, WarpRowsInBandsIsTheWholeWarp) {
  const Rig rig = MakeRigPreset("rovo4").Scaled(0.25);
  const HybridProjection p = HybridProjection::ForRig(rig)[1];
  cv::Mat fisheye(rig.cameras[1].camera.height, rig.cameras[1].camera.width, CV_8UC1);
  cv::RNG(4).fill(fisheye, cv::RNG::UNIFORM, 0, 256);
  cv::Mat whole;
  p.Warp(fisheye, &whole);
  cv::Mat bands(p.height(), p.width(), CV_8UC1, cv::Scalar(7));
  for (int first = 0; first < p.height(); first += 13) {
    p.WarpRows(fisheye, first, std::min(first + 13, p.height()), &bands);
  }
  EXPECT_EQ(cv::norm(whole, bands, cv::NORM_INF), 0.0);
  const cv::Mat before = bands.clone();
  p.WarpRows(cv::Mat::zeros(fisheye.size(), CV_8UC1), p.height(), p.height() + 5, &bands);
  EXPECT_EQ(cv::norm(before, bands, cv::NORM_INF), 0.0);
  cv::Mat small(p.height() - 1, p.width(), CV_8UC1);
  EXPECT_THROW(p.WarpRows(fisheye, 0, 1, &small), std::invalid_argument);
}

// No jumps: along rows and columns the fisheye position changes smoothly (second difference <= 0.5
// px) everywhere, in particular across the plane/cylinder seams; the first difference across each
// seam matches the one next to it.
TEST(HybridProjection, SeamsAreContinuous) {
  for (const NamedRig& named : TestRigs()) {
    const auto projections = HybridProjection::ForRig(named.rig);
    for (size_t c = 0; c < projections.size(); ++c) {
      const HybridProjection& p = projections[c];
      const auto at = [&](int u, int v) {
        return Eigen::Vector2d(p.map_x().at<float>(v, u), p.map_y().at<float>(v, u));
      };
      const auto valid = [&](int u, int v) { return p.valid_mask().at<uint8_t>(v, u) != 0; };
      double worst_second = 0.0;
      for (int v = 1; v + 1 < p.height(); v += 3) {
        for (int u = 1; u + 1 < p.width(); ++u) {
          if (!valid(u - 1, v) || !valid(u, v) || !valid(u + 1, v)) continue;
          worst_second = std::max(worst_second, (at(u + 1, v) - 2 * at(u, v) + at(u - 1, v)).norm());
        }
      }
      for (int u = 1; u + 1 < p.width(); u += 3) {
        for (int v = 1; v + 1 < p.height(); ++v) {
          if (!valid(u, v - 1) || !valid(u, v) || !valid(u, v + 1)) continue;
          worst_second = std::max(worst_second, (at(u, v + 1) - 2 * at(u, v) + at(u, v - 1)).norm());
        }
      }
      EXPECT_LT(worst_second, 0.5) << named.name << " camera " << c;
      for (double seam : {p.left_seam_u(), p.right_seam_u()}) {
        const int u = static_cast<int>(std::floor(seam));
        if (u < 2 || u + 3 >= p.width()) continue;
        for (int v = 0; v < p.height(); v += 7) {
          if (!valid(u - 1, v) || !valid(u + 2, v)) continue;
          const double across = (at(u + 1, v) - at(u, v)).norm();
          const double before = (at(u, v) - at(u - 1, v)).norm();
          const double after = (at(u + 2, v) - at(u + 1, v)).norm();
          EXPECT_LT(std::abs(across - 0.5 * (before + after)), 0.05) << named.name << " v " << v;
        }
      }
    }
  }
}

// Neighbouring views are rectified in their overlap: a point there has the same warped row in
// both views (cameras in the rig plane, same focal length).
TEST(HybridProjection, OverlapIsRectified) {
  for (const NamedRig& named : TestRigs()) {
    const auto projections = HybridProjection::ForRig(named.rig);
    const Rig& rig = named.rig;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    for (int a = 0; a < rig.NumCameras(); ++a) {
      const int b = projections[a].layout().right_neighbour;
      ASSERT_EQ(projections[b].layout().left_neighbour, a) << named.name;
      ASSERT_NEAR(projections[a].focal_px(), projections[b].focal_px(), 1e-6);
      const Eigen::Vector3d m = projections[a].layout().right_normal_in_rig;
      EXPECT_LT(AngleBetween(m, projections[b].layout().left_normal_in_rig), 1e-9) << named.name;
      int checked = 0;
      for (int k = 0; k < 2000 && checked < 100; ++k) {
        // Points in front of the shared plane, 3-30 m away.
        const Eigen::Vector3d tangent = m.cross(Eigen::Vector3d::UnitZ());
        const Eigen::Vector3d point_in_rig = (5.0 + 25.0 * std::abs(uniform(rng))) * m + 10.0 * uniform(rng) * tangent +
                                             3.0 * uniform(rng) * Eigen::Vector3d::UnitZ();
        const auto pa = projections[a].WarpedFromBearing(rig.cameras[a].cam_from_rig * point_in_rig);
        const auto pb = projections[b].WarpedFromBearing(rig.cameras[b].cam_from_rig * point_in_rig);
        if (!pa || !pb || !projections[a].InWarpedImage(*pa) || !projections[b].InWarpedImage(*pb)) continue;
        if (pa->x() < projections[a].right_seam_u() || pb->x() > projections[b].left_seam_u()) continue;
        EXPECT_NEAR(pa->y(), pb->y(), 1e-6) << named.name;
        EXPECT_GT(pa->x(), pb->x() - projections[a].width()) << named.name;
        ++checked;
      }
      EXPECT_GT(checked, 20) << named.name << " pair " << a << "-" << b;
    }
  }
}

TEST(HybridProjection, LayoutOfRovo4) {
  const Rig rig = MakeRigPreset("rovo4");
  const auto layouts = ComputeHybridLayouts(rig);
  ASSERT_EQ(layouts.size(), 4u);
  // Cameras 0 (front-left, yaw 45) and 1 (front-right, yaw -45) share the forward-facing plane.
  EXPECT_EQ(layouts[0].right_neighbour, 1);
  EXPECT_EQ(layouts[1].left_neighbour, 0);
  EXPECT_EQ(layouts[0].left_neighbour, 3);
  EXPECT_LT(AngleBetween(layouts[0].right_normal_in_rig, Eigen::Vector3d::UnitX()), 1e-9);
  EXPECT_LT(AngleBetween(layouts[0].left_normal_in_rig, Eigen::Vector3d::UnitY()), 1e-9);
  EXPECT_LT(AngleBetween(layouts[2].up_in_rig, Eigen::Vector3d::UnitZ()), 1e-9);
}

TEST(HybridProjection, TwoCameraAndFiveCameraRigs) {
  const Rig omni = MakeRigPreset("omnimvs4");
  const Camera lens = omni.cameras[0].camera;
  // Two cameras back to back on the y axis, looking left and right: one shared plane each side.
  Rig two;
  for (int i = 0; i < 2; ++i) {
    RigCamera rc;
    rc.name = "cam" + std::to_string(i);
    rc.camera = lens;
    rc.cam_from_rig = CamFromRigFromMount(i == 0 ? 90.0 : -90.0, 0.0, Eigen::Vector3d(0, i == 0 ? 0.3 : -0.3, 0));
    two.cameras.push_back(rc);
  }
  const auto layouts = ComputeHybridLayouts(two);
  EXPECT_EQ(layouts[0].left_neighbour, 1);
  EXPECT_EQ(layouts[0].right_neighbour, 1);
  EXPECT_LT(AngleBetween(layouts[0].up_in_rig, Eigen::Vector3d::UnitZ()), 1e-9);
  const auto projections = HybridProjection::ForRig(two);
  EXPECT_GT(projections[0].width(), projections[0].height());
  const auto bearing = projections[0].BearingFromWarped(Eigen::Vector2d(projections[0].width() / 2.0, 100.0));
  ASSERT_TRUE(bearing.has_value());

  const Rig five = RingRig(5, 0.4, lens, 10.0);
  const auto five_projections = HybridProjection::ForRig(five);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(five_projections[i].layout().left_neighbour, (i + 1) % 5);
    EXPECT_EQ(five_projections[i].layout().right_neighbour, (i + 4) % 5);
  }
}

TEST(HybridProjection, RejectsDegenerateRigs) {
  Rig rig = MakeRigPreset("omnimvs4");
  for (RigCamera& c : rig.cameras) {
    c.cam_from_rig = Rigid3(c.cam_from_rig.rotation, Eigen::Vector3d::Zero());
  }
  EXPECT_THROW(ComputeHybridLayouts(rig), std::invalid_argument);
  Rig one = MakeRigPreset("omnimvs4");
  one.cameras.resize(1);
  EXPECT_THROW(ComputeHybridLayouts(one), std::invalid_argument);
}

TEST(HybridProjection, LayoutChangeMeasuresCameraRotation) {
  const Rig rig = MakeRigPreset("omnimvs4");
  const auto layouts = ComputeHybridLayouts(rig);
  EXPECT_NEAR(HybridLayoutChangeDeg(layouts[2], rig.cameras[2].cam_from_rig, layouts[2], rig.cameras[2].cam_from_rig),
              0.0, 1e-9);
  // Rotate camera 2 by 3 degrees about its own y axis (yaw): its layout axes move by ~3 deg in
  // its own frame.
  std::vector<Rigid3> extrinsics = rig.Extrinsics();
  extrinsics[2] =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(3.0 * kDeg, Eigen::Vector3d::UnitY())), Eigen::Vector3d::Zero()) *
      extrinsics[2];
  const Rig moved = rig.WithExtrinsics(extrinsics);
  const auto moved_layouts = ComputeHybridLayouts(moved);
  const double change = HybridLayoutChangeDeg(layouts[2], rig.cameras[2].cam_from_rig, moved_layouts[2], extrinsics[2]);
  EXPECT_GT(change, 2.0);
  EXPECT_LT(change, 4.0);
}

// Warp() (fixed-point remap) reproduces the float map's bilinear samples of a smooth image.
// The warp reaches vertical_fov_above_deg above and vertical_fov_below_deg below the rig plane
// (checked at the plane's tangent line, where y = -tan(elevation)); rows above and below differ.
TEST(HybridProjection, VerticalExtentsAboveAndBelowTheRigPlane) {
  const Rig rig = MakeRigPreset("rovo4").Scaled(0.5);
  const auto layouts = ComputeHybridLayouts(rig);
  HybridProjectionOptions options;
  options.vertical_fov_above_deg = 50.0;
  options.vertical_fov_below_deg = 25.0;
  const HybridProjection cut(rig.cameras[0].camera, rig.cameras[0].cam_from_rig, layouts[0], options);
  const HybridProjection full(rig.cameras[0].camera, rig.cameras[0].cam_from_rig, layouts[0]);
  ASSERT_NEAR(cut.focal_px(), full.focal_px(), 1e-9);
  EXPECT_EQ(cut.width(), full.width());
  const int rows_above = static_cast<int>(std::ceil(std::tan(50.0 * kDeg) * cut.focal_px()));
  const int rows_below = static_cast<int>(std::ceil(std::tan(25.0 * kDeg) * cut.focal_px()));
  EXPECT_EQ(cut.height(), rows_above + rows_below + 1);
  EXPECT_EQ(full.height(), 2 * rows_above + 1);
  const Eigen::Vector3d m = layouts[0].right_normal_in_rig, up = layouts[0].up_in_rig;
  const auto in_image = [&](const HybridProjection& p, double elevation_deg) {
    const Eigen::Vector3d d = std::cos(elevation_deg * kDeg) * m + std::sin(elevation_deg * kDeg) * up;
    const auto px = p.WarpedFromBearing(rig.cameras[0].cam_from_rig.RotationMatrix() * d);
    EXPECT_TRUE(px.has_value()) << elevation_deg;
    if (px) {
      EXPECT_NEAR(px->y(), rows_above - cut.focal_px() * std::tan(elevation_deg * kDeg), 1e-6);
    }
    return px && p.InWarpedImage(*px);
  };
  EXPECT_TRUE(in_image(cut, 49.5));
  EXPECT_FALSE(in_image(cut, 50.5));
  EXPECT_TRUE(in_image(cut, -24.5));
  EXPECT_FALSE(in_image(cut, -25.5));
  EXPECT_TRUE(in_image(full, -49.5));
  // The cut warp is the full one's top rows: the same fisheye source up to the maps' interpolation
  // between exact nodes (< 0.02 px each).
  for (int v = 0; v < cut.height(); v += 7) {
    for (int u = 0; u < cut.width(); u += 7) {
      ASSERT_NEAR(cut.map_x().at<float>(v, u), full.map_x().at<float>(v, u), 0.04) << u << "," << v;
      ASSERT_NEAR(cut.map_y().at<float>(v, u), full.map_y().at<float>(v, u), 0.04) << u << "," << v;
    }
  }
}

TEST(HybridProjection, WarpSamplesTheFisheyeImage) {
  const auto projections = HybridProjection::ForRig(MakeRigPreset("omnimvs4"));
  const HybridProjection& p = projections[0];
  cv::Mat fisheye(p.camera().height, p.camera().width, CV_8UC1);
  for (int v = 0; v < fisheye.rows; ++v) {
    for (int u = 0; u < fisheye.cols; ++u) {
      fisheye.at<uint8_t>(v, u) = static_cast<uint8_t>(127.5 + 120.0 * std::sin(u * 0.05) * std::cos(v * 0.04));
    }
  }
  cv::Mat warped;
  p.Warp(fisheye, &warped);
  ASSERT_EQ(warped.cols, p.width());
  ASSERT_EQ(warped.rows, p.height());
  double worst = 0.0;
  for (int v = 0; v < p.height(); v += 4) {
    for (int u = 0; u < p.width(); u += 4) {
      if (!p.valid_mask().at<uint8_t>(v, u)) {
        continue;
      }
      const double x = p.map_x().at<float>(v, u), y = p.map_y().at<float>(v, u);
      const double expected = 127.5 + 120.0 * std::sin(x * 0.05) * std::cos(y * 0.04);
      worst = std::max(worst, std::abs(warped.at<uint8_t>(v, u) - expected));
    }
  }
  EXPECT_LT(worst, 2.5);
  cv::Mat wrong(10, 10, CV_8UC1);
  EXPECT_THROW(p.Warp(wrong, &warped), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
