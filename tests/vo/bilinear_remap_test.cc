#include "vo/bilinear_remap.h"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "datasets/rig.h"
#include "vo/cpu_dispatch.h"
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

// One row per position: 16-pixel blocks (the AVX2 step) all at `positions[r]`, fractions 0, 67, 134, ...
void BlockMaps(const std::vector<cv::Vec2s>& positions, cv::Mat* map_fixed, cv::Mat* map_frac) {
  const int cols = 64;  // four blocks
  map_fixed->create(static_cast<int>(positions.size()), cols, CV_16SC2);
  map_frac->create(static_cast<int>(positions.size()), cols, CV_16UC1);
  for (int y = 0; y < map_fixed->rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      map_fixed->at<cv::Vec2s>(y, x) = positions[static_cast<size_t>(y)];
      map_frac->at<uint16_t>(y, x) = static_cast<uint16_t>((67 * (x + cols * y)) % 1024);
    }
  }
}

TEST(BilinearRemap, BlocksAtTheLimitsOfTheGathers) {
  // Whole blocks at the last position the gathers serve (cols - 2, rows - 3) and just beyond it, where
  // the pixels take OpenCV's border rule.
  const cv::Mat src = Noise(45, 33, 16);
  const int c = src.cols, r = src.rows;
  cv::Mat map_fixed, map_frac;
  BlockMaps({{0, 0},
             {static_cast<int16_t>(c - 2), static_cast<int16_t>(r - 3)},
             {static_cast<int16_t>(c - 1), static_cast<int16_t>(r - 3)},
             {static_cast<int16_t>(c - 2), static_cast<int16_t>(r - 2)},
             {static_cast<int16_t>(c - 1), static_cast<int16_t>(r - 1)},
             {-1, 0},
             {0, -1},
             {static_cast<int16_t>(c), 0}},
            &map_fixed, &map_frac);
  if (CpuHasAvx2()) {
    EXPECT_TRUE(RemapBilinearGrayApplies(src, map_fixed, map_frac, cv::Mat()));
  }
  ExpectSameAsOpenCv(src, map_fixed, map_frac);
}

TEST(BilinearRemap, GathersStayInsideAnImageThatEndsAtAnUnreadablePage) {
  // A 64 x 64 continuous image filling one page, followed by a page that may not be read: every block
  // at the gathers' last position (and beyond it, where the pixels go one by one) reads inside.
  const long page = sysconf(_SC_PAGESIZE);
  ASSERT_EQ(page % 64, 0);
  const int side = 64;
  const size_t bytes = static_cast<size_t>(side) * side;
  const size_t span = (bytes + static_cast<size_t>(page) - 1) / static_cast<size_t>(page) * static_cast<size_t>(page);
  void* base =
      mmap(nullptr, span + static_cast<size_t>(page), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(base, MAP_FAILED);
  uint8_t* guard = static_cast<uint8_t*>(base) + span;
  ASSERT_EQ(mprotect(guard, static_cast<size_t>(page), PROT_NONE), 0);
  cv::Mat src(side, side, CV_8UC1, guard - bytes);  // its last byte just before the guard
  Noise(side, side, 17).copyTo(src);
  cv::Mat map_fixed, map_frac;
  BlockMaps({{side - 2, side - 3}, {side - 2, side - 2}, {side - 1, side - 1}}, &map_fixed, &map_frac);
  ExpectSameAsOpenCv(src, map_fixed, map_frac);
  munmap(base, span + static_cast<size_t>(page));
}

TEST(BilinearRemap, AppliesOnlyWhereItComputes) {
  const cv::Mat gray = Noise(40, 30, 18);
  cv::Mat map_fixed, map_frac;
  RandomMaps(4, 20, cv::Rect2i(0, 0, 39, 29), 19, &map_fixed, &map_frac);
  EXPECT_EQ(RemapBilinearGrayApplies(gray, map_fixed, map_frac, cv::Mat()), CpuHasAvx2());
  EXPECT_FALSE(RemapBilinearGrayApplies(cv::Mat(30, 40, CV_8UC3), map_fixed, map_frac, cv::Mat()));
  EXPECT_FALSE(RemapBilinearGrayApplies(gray, cv::Mat(4, 20, CV_32FC2), map_frac, cv::Mat()));
  EXPECT_FALSE(RemapBilinearGrayApplies(gray, map_fixed, map_frac.colRange(0, 10), cv::Mat()));
  EXPECT_FALSE(RemapBilinearGrayApplies(gray, cv::Mat(), cv::Mat(), cv::Mat()));
  EXPECT_FALSE(RemapBilinearGrayApplies(gray, map_fixed, map_frac, gray));
  EXPECT_FALSE(RemapBilinearGrayApplies(cv::Mat(2, 40000, CV_8UC1), map_fixed, map_frac, cv::Mat()));
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
