#include "vo/bilinear_remap.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/imgproc.hpp>

#include "datasets/rig.h"
#include "vo/hybrid_projection.h"

namespace rovo {
namespace {

// Uniform noise with saturated blocks, so that the largest sums occur.
cv::Mat Noise(int width, int height, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image(height, width, CV_8UC1);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  for (int k = 0; k < 6; ++k) {
    const int x = rng.uniform(0, width - 4), y = rng.uniform(0, height - 4);
    image(cv::Rect(x, y, 4, 4)).setTo(k % 2 == 0 ? 255 : 0);
  }
  return image;
}

cv::Mat OpenCvRemap(const cv::Mat& src, const cv::Mat& map_fixed, const cv::Mat& map_frac) {
  cv::Mat out;
  cv::remap(src, out, map_fixed, map_frac, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
}

void ExpectSameAsOpenCv(const cv::Mat& src, const cv::Mat& map_fixed, const cv::Mat& map_frac) {
  const cv::Mat expected = OpenCvRemap(src, map_fixed, map_frac);
  cv::Mat out;
  RemapBilinearGray(src, map_fixed, map_frac, &out);
  ASSERT_EQ(out.size(), expected.size());
  ASSERT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(out != expected), 0);
}

// Maps whose rows hold every fraction entry in turn (column c: entry (c + row) % 1024) at random
// source positions in [x_min, x_max] x [y_min, y_max].
void RandomMaps(int rows, int cols, cv::Rect2i positions, uint64_t seed, cv::Mat* map_fixed, cv::Mat* map_frac) {
  cv::RNG rng(seed);
  map_fixed->create(rows, cols, CV_16SC2);
  map_frac->create(rows, cols, CV_16UC1);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      map_fixed->at<cv::Vec2s>(y, x) =
          cv::Vec2s(static_cast<int16_t>(rng.uniform(positions.x, positions.x + positions.width)),
                    static_cast<int16_t>(rng.uniform(positions.y, positions.y + positions.height)));
      map_frac->at<uint16_t>(y, x) = static_cast<uint16_t>((x + y) % 1024);
    }
  }
}

TEST(BilinearRemap, EveryWeightEntryGivesOpenCvsPixels) {
  // 1024 columns x 2000 rows: each entry at 2000 random positions inside the image. A weight off by one
  // changes the sum by a tap's value, which moves a pixel across a rounding step about once in 250.
  const cv::Mat src = Noise(97, 61, 1);
  cv::Mat map_fixed, map_frac;
  RandomMaps(2000, 1024, cv::Rect2i(0, 0, src.cols - 1, src.rows - 1), 2, &map_fixed, &map_frac);
  ExpectSameAsOpenCv(src, map_fixed, map_frac);
}

TEST(BilinearRemap, BordersAndOutsideGiveOpenCvsPixels) {
  // Positions from 3 pixels outside to 3 beyond the far edges: taps outside count as 0, as in OpenCV.
  const cv::Mat src = Noise(40, 30, 3);
  cv::Mat map_fixed, map_frac;
  RandomMaps(64, 1024, cv::Rect2i(-3, -3, src.cols + 6, src.rows + 6), 4, &map_fixed, &map_frac);
  ExpectSameAsOpenCv(src, map_fixed, map_frac);
}

TEST(BilinearRemap, LastRowsAndColumnsOfARegionAtTheBuffersEnd) {
  // A region at the bottom-right of its parent and a continuous image: the taps of the last row and
  // column, where 4-byte reads would pass the buffer's end.
  const cv::Mat parent = Noise(80, 50, 5);
  const cv::Mat region = parent(cv::Rect(37, 21, 43, 29));
  const cv::Mat continuous = Noise(43, 29, 6);
  for (const cv::Mat* src : {&region, &continuous}) {
    cv::Mat map_fixed, map_frac;
    RandomMaps(16, 1024, cv::Rect2i(src->cols - 4, src->rows - 4, 4, 4), 7, &map_fixed, &map_frac);
    ExpectSameAsOpenCv(*src, map_fixed, map_frac);
  }
}

TEST(BilinearRemap, WidthsOffTheStepAndFractionIndicesAbove1023) {
  // OpenCV keeps the low 10 bits of map_frac; rows of 1 to 40 pixels end in the one-by-one loop.
  const cv::Mat src = Noise(50, 40, 8);
  cv::RNG rng(9);
  for (int width = 1; width <= 40; ++width) {
    cv::Mat map_fixed, map_frac;
    RandomMaps(5, width, cv::Rect2i(-1, -1, src.cols, src.rows), 10 + width, &map_fixed, &map_frac);
    for (int x = 0; x < width; ++x) map_frac.at<uint16_t>(0, x) = static_cast<uint16_t>(rng.uniform(0, 65536));
    ExpectSameAsOpenCv(src, map_fixed, map_frac);
  }
}

TEST(BilinearRemap, HybridProjectionMapsGiveOpenCvsWarp) {
  // The front-end's own maps (a full-size rovo4 camera: outside the image circle and at its rim).
  const Rig rig = MakeRigPreset("rovo4");
  const auto projections = HybridProjection::ForRig(rig);
  const Camera& camera = rig.cameras[1].camera;
  const cv::Mat src = Noise(camera.width, camera.height, 11);
  ExpectSameAsOpenCv(src, projections[1].map_fixed(), projections[1].map_frac());
}

TEST(BilinearRemap, WritesARegionInPlace) {
  const cv::Mat src = Noise(60, 40, 12);
  cv::Mat map_fixed, map_frac;
  RandomMaps(8, 300, cv::Rect2i(0, 0, src.cols - 1, src.rows - 1), 13, &map_fixed, &map_frac);
  cv::Mat whole(20, 300, CV_8UC1, cv::Scalar(7));
  cv::Mat band = whole.rowRange(5, 13);
  const uint8_t* before = band.data;
  RemapBilinearGray(src, map_fixed, map_frac, &band);
  EXPECT_EQ(band.data, before);
  EXPECT_EQ(cv::countNonZero(whole.rowRange(5, 13) != OpenCvRemap(src, map_fixed, map_frac)), 0);
  EXPECT_EQ(cv::countNonZero(whole.rowRange(0, 5) != 7), 0);
  EXPECT_EQ(cv::countNonZero(whole.rowRange(13, 20) != 7), 0);
}

TEST(BilinearRemap, OtherTypesGoToOpenCv) {
  // Colour images and float maps are OpenCV's.
  cv::Mat colour(30, 40, CV_8UC3);
  cv::randu(colour, 0, 256);
  cv::Mat map_fixed, map_frac;
  RandomMaps(10, 50, cv::Rect2i(-2, -2, 44, 34), 14, &map_fixed, &map_frac);
  cv::Mat expected, out;
  cv::remap(colour, expected, map_fixed, map_frac, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  RemapBilinearGray(colour, map_fixed, map_frac, &out);
  EXPECT_EQ(cv::norm(out, expected, cv::NORM_INF), 0);

  cv::Mat map_x(10, 50, CV_32FC1), map_y(10, 50, CV_32FC1);
  cv::randu(map_x, -2.0, 42.0);
  cv::randu(map_y, -2.0, 32.0);
  const cv::Mat gray = Noise(40, 30, 15);
  cv::remap(gray, expected, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  RemapBilinearGray(gray, map_x, map_y, &out);
  EXPECT_EQ(cv::countNonZero(out != expected), 0);
}

}  // namespace
}  // namespace rovo
