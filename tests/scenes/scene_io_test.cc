#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "datasets/io.h"
#include "scenes/scene.h"
#include "tests/scenes/scratch_dir.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;

using test::FreshDir;

// A small scene exercising every field: two textures, per-triangle materials, a mesh without UVs,
// a static and a dynamic object, non-trivial quaternions.
Scene MakeTestScene() {
  Scene scene;
  scene.metadata.generator = "test";
  scene.metadata.generator_version = "9.9";
  scene.metadata.preset = "unit";
  scene.metadata.seed = 0xFFFFFFFFFFFFFFF1ull;  // needs all 64 bits
  scene.frame_rate = 10.0;
  scene.rig_preset = "rovo4";
  scene.lighting.preset = "sunset";
  scene.lighting.direction_to_sun = {0.1, -0.7, 0.123456789};
  scene.lighting.ambient = 0.123f;
  for (int k = 0; k < 2; ++k) {
    Texture t;
    t.name = "tex" + std::to_string(k);
    t.width = 7 + k;
    t.height = 5;
    for (int i = 0; i < t.width * t.height * 3; ++i) t.rgb.push_back(static_cast<uint8_t>((i * 37 + k * 11) % 256));
    scene.textures.push_back(t);
  }
  scene.materials.push_back({"m0", {0.1f, 0.2f, 0.3f}, 0});
  scene.materials.push_back({"m1", {0.9f, 0.5f, 1.0f / 3.0f}, 1});
  scene.materials.push_back({"m2", {0.5f, 0.5f, 0.5f}, -1});
  Mesh quad;
  quad.name = "quad";
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.1f}, {0, 1, 1.0f / 7.0f}};
  quad.uvs = {{0, 0}, {1, 0}, {1, 1}, {-0.25f, 3.5f}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  quad.triangle_materials = {0, 1};
  quad.material = 0;
  Mesh tri;
  tri.name = "tri";
  tri.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  tri.triangles = {{0, 1, 2}};
  tri.material = 2;
  scene.meshes = {quad, tri};
  const int frames = 4;
  for (int i = 0; i < frames; ++i) {
    StampedPose p;
    p.timestamp = i / scene.frame_rate;
    p.world_from_rig = Rigid3::FromAxisAngle(Eigen::Vector3d(0.01 * i, -0.02, 0.3 + i / 3.0),
                                             Eigen::Vector3d(i * 1.1, 0.1 / 3.0, 2.0));
    scene.rig_trajectory.push_back(p);
  }
  Object building;
  building.name = "building";
  building.mesh = 0;
  building.world_from_object = Rigid3::FromAxisAngle(Eigen::Vector3d(0, 0, 1.0 / 3.0), Eigen::Vector3d(5, 6, 7));
  Object car;
  car.name = "car";
  car.mesh = 1;
  car.id = 3;
  for (int i = 0; i < frames; ++i) {
    car.world_from_object_per_frame.push_back(
        Rigid3::FromAxisAngle(Eigen::Vector3d(0, 0, 0.2 * i), Eigen::Vector3d(i / 7.0, 1, 0)));
  }
  scene.objects = {building, car};
  return scene;
}

void ExpectScenesEqual(const Scene& a, const Scene& b) {
  EXPECT_EQ(a.metadata.seed, b.metadata.seed);
  EXPECT_EQ(a.metadata.generator_version, b.metadata.generator_version);
  ASSERT_EQ(a.textures.size(), b.textures.size());
  for (size_t i = 0; i < a.textures.size(); ++i) EXPECT_EQ(a.textures[i].rgb, b.textures[i].rgb);
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    EXPECT_EQ(a.meshes[i].positions, b.meshes[i].positions);
    EXPECT_EQ(a.meshes[i].uvs, b.meshes[i].uvs);
    EXPECT_EQ(a.meshes[i].triangles, b.meshes[i].triangles);
    EXPECT_EQ(a.meshes[i].triangle_materials, b.meshes[i].triangle_materials);
  }
  ASSERT_EQ(a.rig_trajectory.size(), b.rig_trajectory.size());
  for (size_t i = 0; i < a.rig_trajectory.size(); ++i) {
    EXPECT_EQ(a.rig_trajectory[i].timestamp, b.rig_trajectory[i].timestamp);
    EXPECT_EQ(a.rig_trajectory[i].world_from_rig.translation, b.rig_trajectory[i].world_from_rig.translation);
    EXPECT_EQ(a.rig_trajectory[i].world_from_rig.rotation.coeffs(),
              b.rig_trajectory[i].world_from_rig.rotation.coeffs());
  }
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].id, b.objects[i].id);
    EXPECT_EQ(a.objects[i].IsDynamic(), b.objects[i].IsDynamic());
    EXPECT_EQ(a.objects[i].world_from_object.rotation.coeffs(), b.objects[i].world_from_object.rotation.coeffs());
  }
  EXPECT_EQ(a.lighting.direction_to_sun, b.lighting.direction_to_sun);
  EXPECT_EQ(a.lighting.ambient, b.lighting.ambient);
  EXPECT_EQ(SceneHash(a), SceneHash(b));
}

TEST(SceneIo, RoundTripIsExact) {
  const Scene scene = MakeTestScene();
  const std::string dir = FreshDir("roundtrip");
  SaveScene(scene, dir);
  const Scene loaded = LoadScene(dir);
  ExpectScenesEqual(scene, loaded);
  // Saving the loaded scene again gives the same bytes.
  const std::string dir2 = FreshDir("roundtrip2");
  SaveScene(loaded, dir2);
  for (const char* f :
       {"scene.json", "geometry.bin", "motion.bin", "trajectory.tum", "textures/000.png", "textures/001.png"}) {
    EXPECT_EQ(ReadFile(dir + "/" + f), ReadFile(dir2 + "/" + f)) << f;
  }
  // No temporary files are left behind.
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
  }
}

TEST(SceneIo, HashSeesEveryKindOfChange) {
  const Scene base = MakeTestScene();
  const std::string h = SceneHash(base);
  EXPECT_EQ(h.size(), 16u);
  Scene s = base;
  s.textures[1].rgb[4] ^= 1;
  EXPECT_NE(SceneHash(s), h);
  s = base;
  s.meshes[0].positions[2].z() += 1e-6f;
  EXPECT_NE(SceneHash(s), h);
  s = base;
  s.objects[1].world_from_object_per_frame[2].translation.x() += 1e-9;
  EXPECT_NE(SceneHash(s), h);
  s = base;
  s.rig_trajectory[3].world_from_rig.translation.y() += 1e-9;
  EXPECT_NE(SceneHash(s), h);
  s = base;
  s.materials[2].base_color.x() = 0.51f;
  EXPECT_NE(SceneHash(s), h);
  s = base;
  s.lighting.exposure = 2.0f;
  EXPECT_NE(SceneHash(s), h);
  s = base;
  s.metadata.generator_version = "other";  // deliberately not part of the content hash
  EXPECT_EQ(SceneHash(s), h);
}

// Runs LoadScene and returns the exception message ("" if it loaded).
std::string LoadError(const std::string& dir) {
  try {
    LoadScene(dir);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

void EditJson(const std::string& dir, const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = ReadJsonFile(dir + "/scene.json");
  edit(j);
  WriteJsonFileAtomic(dir + "/scene.json", j);
}

TEST(SceneIo, ErrorsNameFileAndField) {
  const Scene scene = MakeTestScene();
  {
    const std::string dir = FreshDir("malformed");
    SaveScene(scene, dir);
    WriteFileAtomic(dir + "/scene.json", "{\"format\": \"rovo-scene\", ");
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find(dir + "/scene.json"), std::string::npos) << err;
    EXPECT_NE(err.find("malformed JSON"), std::string::npos) << err;
  }
  {
    const std::string dir = FreshDir("missing_buffer");
    SaveScene(scene, dir);
    fs::remove(dir + "/geometry.bin");
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("scene.json"), std::string::npos) << err;
    EXPECT_NE(err.find("meshes[0].buffer"), std::string::npos) << err;
    EXPECT_NE(err.find("geometry.bin"), std::string::npos) << err;
  }
  {
    const std::string dir = FreshDir("short_buffer");
    SaveScene(scene, dir);
    EditJson(dir, [](nlohmann::json& j) { j["meshes"][1]["triangle_count"] = 1000; });
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("meshes[1].triangle_count"), std::string::npos) << err;  // checked before allocating
  }
  {
    const std::string dir = FreshDir("short_buffer_offset");
    SaveScene(scene, dir);
    EditJson(dir, [](nlohmann::json& j) { j["meshes"][1]["triangles_offset"] = 1 << 20; });
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("meshes[1].triangles_offset"), std::string::npos) << err;
  }
  {
    const std::string dir = FreshDir("missing_field");
    SaveScene(scene, dir);
    EditJson(dir, [](nlohmann::json& j) { j["objects"][0]["world_from_object"].erase("translation"); });
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("objects[0].world_from_object.translation: missing"), std::string::npos) << err;
  }
  {
    const std::string dir = FreshDir("bad_index");
    SaveScene(scene, dir);
    EditJson(dir, [](nlohmann::json& j) { j["materials"][0]["texture"] = 5; });
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("materials[0].texture"), std::string::npos) << err;
  }
  {
    const std::string dir = FreshDir("motion_frames");
    SaveScene(scene, dir);
    EditJson(dir, [](nlohmann::json& j) { j["objects"][1]["motion"]["frames"] = 3; });
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("objects[1].motion.frames"), std::string::npos) << err;
  }
  {
    const std::string dir = FreshDir("texture_size");
    SaveScene(scene, dir);
    EditJson(dir, [](nlohmann::json& j) { j["textures"][1]["width"] = 9; });
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("textures[1].file"), std::string::npos) << err;
  }
  {
    const std::string dir = FreshDir("bad_tum");
    SaveScene(scene, dir);
    WriteFileAtomic(dir + "/trajectory.tum", "0 1 2 3 0 0 0 1\n0.1 1 2 x\n");
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find("trajectory.tum: line 2"), std::string::npos) << err;
  }
}

// Lights (a world-fixed point light and a spot riding on the dynamic object) and the optional
// material fields round-trip exactly; a scene without them keeps its scene.json keys and hash.
Scene WithLights(Scene scene) {
  scene.materials[1].emission = {2.0f, 1.5f, 1.0f / 3.0f};
  scene.materials[2].specular = 0.25f;
  scene.materials[2].shininess = 80.0f;
  Light bulb;
  bulb.name = "bulb";
  bulb.position = {1.0 / 3.0, -2.0, 2.9};
  bulb.intensity = {0.1f, 0.2f, 0.3f};
  bulb.range = 7.5;
  Light headlight;
  headlight.name = "car_headlight";
  headlight.position = {2.3, 0.6, 0.65};
  headlight.intensity = {0.3f, 0.3f, 0.28f};
  headlight.object = 1;
  headlight.spot = true;
  headlight.spot_direction = {1.0, 0.0, -0.06};
  headlight.spot_angle_deg = 55.0;
  headlight.spot_blend = 0.6;
  scene.lights = {bulb, headlight};
  return scene;
}

TEST(SceneIo, LightsAndMaterialExtensionsRoundTrip) {
  const Scene plain = MakeTestScene();
  const Scene scene = WithLights(plain);
  const std::string dir = FreshDir("lights");
  SaveScene(scene, dir);
  const Scene loaded = LoadScene(dir);
  EXPECT_EQ(SceneHash(loaded), SceneHash(scene));
  ASSERT_EQ(loaded.lights.size(), 2u);
  const Light& h = loaded.lights[1];
  EXPECT_EQ(h.name, "car_headlight");
  EXPECT_EQ(h.object, 1);
  EXPECT_TRUE(h.spot);
  EXPECT_EQ(h.spot_direction, scene.lights[1].spot_direction);
  EXPECT_EQ(h.spot_angle_deg, 55.0);
  EXPECT_EQ(h.spot_blend, 0.6);
  EXPECT_EQ(loaded.lights[0].position, scene.lights[0].position);
  EXPECT_EQ(loaded.lights[0].range, 7.5);
  EXPECT_FALSE(loaded.lights[0].spot);
  EXPECT_EQ(loaded.materials[1].emission, scene.materials[1].emission);
  EXPECT_EQ(loaded.materials[2].specular, 0.25f);
  EXPECT_EQ(loaded.materials[2].shininess, 80.0f);
  // Every light and material field enters the hash.
  Scene moved = scene;
  moved.lights[1].spot_blend = 0.5;
  EXPECT_NE(SceneHash(moved), SceneHash(scene));
  moved = scene;
  moved.materials[1].emission.x() = 2.5f;
  EXPECT_NE(SceneHash(moved), SceneHash(scene));
  EXPECT_NE(SceneHash(plain), SceneHash(scene));
  // Without lights or emission the file has no such keys (older readers and hashes unchanged).
  const std::string plain_dir = FreshDir("no_lights");
  SaveScene(plain, plain_dir);
  const nlohmann::json j = nlohmann::json::parse(ReadFile(plain_dir + "/scene.json"));
  EXPECT_FALSE(j.contains("lights"));
  EXPECT_FALSE(j["materials"][0].contains("emission"));
  EXPECT_FALSE(j["materials"][0].contains("specular"));
  EXPECT_TRUE(LoadScene(plain_dir).lights.empty());
}

TEST(SceneIo, LightErrorsNameFileAndField) {
  const Scene scene = WithLights(MakeTestScene());
  const std::vector<std::pair<std::function<void(nlohmann::json&)>, std::string>> cases = {
      {[](nlohmann::json& j) {
         j["lights"][0]["intensity"] = {0.1, -0.2, 0.3};
       },
       "lights[0].intensity: must not be negative"},
      {[](nlohmann::json& j) { j["lights"][1]["object"] = 2; }, "lights[1].object: value 2 outside [-1, 1]"},
      {[](nlohmann::json& j) { j["lights"][0]["range"] = -1.0; }, "lights[0].range"},
      {[](nlohmann::json& j) { j["lights"][1]["spot"]["angle_deg"] = 190.0; }, "lights[1].spot.angle_deg"},
      {[](nlohmann::json& j) {
         j["lights"][1]["spot"]["direction"] = {0, 0, 0};
       },
       "lights[1].spot.direction"},
      {[](nlohmann::json& j) { j["lights"][1]["spot"]["blend"] = 1.5; }, "lights[1].spot.blend"},
      {[](nlohmann::json& j) { j["lights"][0].erase("position"); }, "lights[0].position: missing"},
      {[](nlohmann::json& j) {
         j["materials"][1]["emission"] = {1.0, -1.0, 0.0};
       },
       "materials[1].emission"},
      {[](nlohmann::json& j) { j["materials"][2].erase("shininess"); }, "materials[2].shininess: missing"},
      {[](nlohmann::json& j) { j["materials"][2]["specular"] = 2.0; }, "materials[2].specular"},
  };
  for (size_t k = 0; k < cases.size(); ++k) {
    const std::string dir = FreshDir("light_error_" + std::to_string(k));
    SaveScene(scene, dir);
    EditJson(dir, cases[k].first);
    const std::string err = LoadError(dir);
    EXPECT_NE(err.find(dir + "/scene.json"), std::string::npos) << err;
    EXPECT_NE(err.find(cases[k].second), std::string::npos) << "case " << k << ": " << err;
  }
}

}  // namespace
}  // namespace rovo
