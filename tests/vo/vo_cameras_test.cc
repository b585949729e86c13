// Which dataset cameras the VO uses (VoIoOptions::cameras) and the dataset restricted to them.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "datasets/dataset_cameras.h"
#include "datasets/rig.h"
#include "vo/vo_options.h"

namespace rovo {
namespace {

std::string Message(const std::string& cameras, const Rig& rig) {
  try {
    VoCameraIndices(cameras, rig);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(VoCameras, AutoTakesTheFisheyeRing) {
  EXPECT_EQ(VoCameraIndices("auto", MakeRigPreset("rovo4_stereo")), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(VoCameraIndices("auto", MakeRigPreset("rovo4_mono")), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(VoCameraIndices("auto", MakeRigPreset("rovo4")), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(VoCameraIndices("all", MakeRigPreset("rovo4_stereo")), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  // A rig of narrow lenses only: all of them.
  Rig narrow = MakeRigPreset("rovo4_stereo");
  narrow.cameras.erase(narrow.cameras.begin(), narrow.cameras.begin() + 4);
  EXPECT_EQ(VoCameraIndices("auto", narrow), (std::vector<int>{0, 1}));
}

TEST(VoCameras, ExplicitListsAreChecked) {
  const Rig rig = MakeRigPreset("rovo4_stereo");
  EXPECT_EQ(VoCameraIndices("0,1,2,3", rig), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(VoCameraIndices("0,2", rig), (std::vector<int>{0, 2}));
  EXPECT_NE(Message("0,9", rig).find("camera 9 does not exist"), std::string::npos) << Message("0,9", rig);
  EXPECT_NE(Message("1,2", rig).find("must include camera 0"), std::string::npos);
  EXPECT_NE(Message("0,2,1", rig).find("must increase"), std::string::npos);
  EXPECT_NE(Message("0,x", rig).find("`x` is not a camera index"), std::string::npos);
  EXPECT_NE(Message("0,1x", rig).find("--cameras"), std::string::npos);
}

TEST(DatasetCameras, SubsetKeepsNamesExtrinsicsAndPerturbedSets) {
  DatasetInfo info;
  info.rig = MakeRigPreset("rovo4_stereo");
  info.perturbed.push_back(PerturbExtrinsics(info.rig, 5.0, 0.0, 11));
  const DatasetInfo subset = SelectDatasetCameras(info, {5, 4}, "--cameras");
  ASSERT_EQ(subset.rig.NumCameras(), 2);
  EXPECT_EQ(subset.rig.cameras[0].name, "cam5");
  EXPECT_EQ(subset.rig.cameras[1].name, "cam4");
  ASSERT_EQ(subset.perturbed[0].cam_from_rig.size(), 2u);
  EXPECT_TRUE(subset.perturbed[0].cam_from_rig[0].translation.isApprox(info.perturbed[0].cam_from_rig[5].translation));
  EXPECT_EQ(subset.perturbed[0].seed, 11u);
  EXPECT_THROW(SelectDatasetCameras(info, {4, 4}, "--cameras"), std::invalid_argument);
  EXPECT_THROW(SelectDatasetCameras(info, {6}, "--cameras"), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
