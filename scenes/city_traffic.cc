// Vehicles of the street scenes: car meshes (parked and moving) and the traffic plan (a lead vehicle,
// oncoming traffic and cross traffic that never overlap the rig's car or each other).

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "scenes/city_internal.h"

namespace rovo::city_internal {

// ---- car meshes ----------------------------------------------------------------------------------

struct CarShape {
  const char* name;
  float length, width, body_top, cabin_top, cabin_length, cabin_shift;
};

namespace {

const CarShape kCarShapes[] = {{"sedan", 4.5f, 1.8f, 1.0f, 1.45f, 2.5f, -0.2f},
                               {"suv", 4.7f, 1.9f, 1.15f, 1.75f, 2.9f, -0.3f},
                               {"van", 5.0f, 2.0f, 1.25f, 2.1f, 3.9f, -0.4f},
                               {"compact", 3.8f, 1.7f, 0.95f, 1.45f, 2.1f, -0.2f}};
const Vec3f kCarColors[] = {{0.8f, 0.05f, 0.04f}, {0.05f, 0.1f, 0.45f}, {0.85f, 0.85f, 0.85f}, {0.04f, 0.04f, 0.045f},
                            {0.5f, 0.52f, 0.55f}, {0.9f, 0.6f, 0.05f},  {0.1f, 0.35f, 0.15f},  {0.6f, 0.3f, 0.15f}};
static_assert(sizeof(kCarShapes) / sizeof(kCarShapes[0]) == kNumCarShapes, "kNumCarShapes");
static_assert(sizeof(kCarColors) / sizeof(kCarColors[0]) == kNumCarColors, "kNumCarColors");

}  // namespace

CarFactory::CarFactory(Scene& scene, const CarTextures& tex) : scene_(scene), tex_(tex) {
  glass_ = AddMaterial(scene, "car_glass", {0.9f, 0.9f, 0.9f}, tex.glass);
  tyre_ = AddMaterial(scene, "car_tyre", {0.04f, 0.04f, 0.04f}, -1);
}

int CarFactory::Get(int shape, int color, bool lit) {
  const int key = (shape * kNumCarColors + color) * 2 + (lit ? 1 : 0);
  auto it = meshes_.find(key);
  if (it != meshes_.end()) return it->second;
  const CarShape& s = kCarShapes[shape];
  const std::string name = std::string("car_") + s.name + "_" + std::to_string(color) + (lit ? "_lit" : "");
  const Vec3f paint = kCarColors[color];
  const int side = AddMaterial(scene_, name + "_side", paint, tex_.side);
  const int end = AddMaterial(scene_, name + "_end", paint, tex_.end);
  const int top = AddMaterial(scene_, name + "_top", paint, -1);
  MeshBuilder b(name);
  const float hl = 0.5f * s.length, hw = 0.5f * s.width;
  const int body[5] = {end, end, side, side, top};
  b.Box({-hl, -hw, 0.3f}, {hl, hw, s.body_top}, body);
  const float c0 = s.cabin_shift - 0.5f * s.cabin_length, c1 = s.cabin_shift + 0.5f * s.cabin_length;
  const int cabin[5] = {glass_, glass_, glass_, glass_, top};
  b.Box({c0, -hw + 0.1f, s.body_top}, {c1, hw - 0.1f, s.cabin_top}, cabin);
  for (float wx : {-hl + 0.8f, hl - 0.8f})
    for (float wy : {-hw + 0.12f, hw - 0.34f}) b.Prism({wx, wy, 0.33f}, 0.33f, 0.0f, 0.22f, 8, tyre_, tyre_, true);
  if (lit) AddLamps(b, s);
  const int mesh = AddMesh(scene_, b.Finish());
  meshes_[key] = mesh;
  return mesh;
}

std::vector<Light> CarFactory::Headlights(int shape, int object, const std::string& name) {
  const CarShape& s = kCarShapes[shape];
  std::vector<Light> lights;
  for (const double side : {-1.0, 1.0}) {
    Light l;
    l.name = name + (side < 0 ? "_headlight_right" : "_headlight_left");
    l.position = Eigen::Vector3d(0.5 * s.length + 0.05, side * (0.5 * s.width - 0.35), 0.65);
    l.intensity = Eigen::Vector3f(0.3f, 0.3f, 0.28f);  // about 10 street lamps on axis
    l.range = 60.0;
    l.object = object;
    l.spot = true;
    l.spot_direction = Eigen::Vector3d(1.0, 0.0, -0.06);  // dipped beam, 3.4 degrees down
    l.spot_angle_deg = 55.0;
    l.spot_blend = 0.6;
    lights.push_back(l);
  }
  return lights;
}

// Glowing head lamps (front corners) and tail lamps (rear corners) of a lit car.
void CarFactory::AddLamps(MeshBuilder& b, const CarShape& s) {
  if (headlamp_ < 0) {
    headlamp_ = AddMaterial(scene_, "car_headlamp", {0.9f, 0.9f, 0.9f}, -1);
    scene_.materials[headlamp_].emission = {20.0f, 20.0f, 18.0f};
    taillamp_ = AddMaterial(scene_, "car_taillamp", {0.6f, 0.05f, 0.05f}, -1);
    scene_.materials[taillamp_].emission = {1.5f, 0.05f, 0.03f};
  }
  const float hl = 0.5f * s.length, hw = 0.5f * s.width;
  const int head[5] = {headlamp_, headlamp_, headlamp_, headlamp_, headlamp_};
  const int tail[5] = {taillamp_, taillamp_, taillamp_, taillamp_, taillamp_};
  for (const float side : {-1.0f, 1.0f}) {
    const float y0 = side * (hw - 0.35f) - 0.13f, y1 = y0 + 0.26f;
    b.Box({hl - 0.02f, y0, 0.58f}, {hl + 0.03f, y1, 0.72f}, head);
    b.Box({-hl - 0.03f, y0, 0.7f}, {-hl + 0.02f, y1, 0.82f}, tail);
  }
}

// ---- traffic plan --------------------------------------------------------------------------------

namespace {

// Oriented rectangle (car footprint) overlap by separating axes.
struct Footprint {
  Eigen::Vector2d centre;
  double yaw, half_length, half_width;
};
bool Overlap(const Footprint& a, const Footprint& b) {
  if ((a.centre - b.centre).norm() > a.half_length + a.half_width + b.half_length + b.half_width) return false;
  const Eigen::Vector2d axes[4] = {{std::cos(a.yaw), std::sin(a.yaw)},
                                   {-std::sin(a.yaw), std::cos(a.yaw)},
                                   {std::cos(b.yaw), std::sin(b.yaw)},
                                   {-std::sin(b.yaw), std::cos(b.yaw)}};
  const Eigen::Vector2d d = b.centre - a.centre;
  for (const Eigen::Vector2d& n : axes) {
    const double ra = a.half_length * std::abs(n.dot(axes[0])) + a.half_width * std::abs(n.dot(axes[1]));
    const double rb = b.half_length * std::abs(n.dot(axes[2])) + b.half_width * std::abs(n.dot(axes[3]));
    if (std::abs(d.dot(n)) > ra + rb) return false;
  }
  return true;
}

struct VehicleTrack {
  int shape = 0, color = 0;
  std::string kind;
  std::vector<Rigid3> world_from_object;  // per frame
  std::vector<bool> active;               // on its path (else parked out of sight)
};

// Pose of a vehicle at arc length s of a path; s outside the path hides it 100 m below the ground.
Rigid3 VehiclePose(const LanePath& path, double s, bool* active) {
  *active = s >= 0 && s <= path.Length();
  if (!*active) return Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -100));
  const Eigen::Vector2d p = path.Position(s);
  return PlaceYaw(p.x(), p.y(), path.Heading(s));
}

// Plans the moving vehicles in three steps that draw from one stream in a fixed order: a lead
// vehicle, oncoming traffic, cross traffic. A track is kept only if its footprint never overlaps the
// rig's car or an accepted track in any frame.
class TrafficPlanner {
 public:
  TrafficPlanner(const CityLayout& L, uint64_t seed, int frames, double rate)
      : L_(L), rng_(SubSeed(seed, "traffic")), frames_(frames), rate_(rate), rig_(frames) {
    for (int f = 0; f < frames; ++f) {
      const Rigid3& p = L.trajectory[f].world_from_rig;
      rig_[f] = {p.translation.head<2>(), L.rig_path.Heading(L.drive.s[f]), 2.6, 1.2};  // the rig's car, with margin
    }
    duration_ = (frames - 1) / rate;
    lane_ = 0.25 * (L.style.road_width_m - 2 * L.style.parking_lane_m);
  }

  // 1) A lead vehicle in the rig's lane, 12-35 m ahead (fills much of the front view).
  void AddLeadVehicle() {
    VehicleTrack v = NewTrack("lead");
    const double period = rng_.Uniform(30, 50), phase = rng_.Uniform(0, 2 * M_PI);
    for (int f = 0; f < frames_; ++f) {
      const double t = f / rate_;
      const double gap = 23.5 - 11.5 * std::cos(2 * M_PI * t / period + phase);
      bool active;
      v.world_from_object[f] = VehiclePose(L_.rig_path, L_.drive.s[f] + gap, &active);
      v.active[f] = active;
    }
    TryAccept(std::move(v));
  }

  // 2) Oncoming traffic on the rig's route, opposite lane, passing 3.5 m from the rig.
  void AddOncomingTraffic() {
    GridRoute reversed(L_.route.rbegin(), L_.route.rend());
    const LanePath back = PathAlongRoute(L_.grid, reversed, lane_);
    const double speed = rng_.Uniform(8, 11), spacing = rng_.Uniform(35, 55);
    for (double s0 = -speed * duration_; s0 < back.Length(); s0 += spacing * rng_.Uniform(0.8, 1.2)) {
      VehicleTrack v = NewTrack("oncoming");
      bool any = false;
      for (int f = 0; f < frames_; ++f) {
        bool active;
        v.world_from_object[f] = VehiclePose(back, s0 + speed * f / rate_, &active);
        v.active[f] = active;
        any = any || active;
      }
      if (any) TryAccept(std::move(v));
    }
  }

  // 3) Cross traffic: random routes through the grid at constant speed.
  void AddCrossTraffic() {
    SceneRng& rng = rng_;
    const double duration = duration_;
    const int candidates = L_.quick ? 12 : 60;
    const int nx = static_cast<int>(L_.grid.xs.size()), ny = static_cast<int>(L_.grid.ys.size());
    for (int c = 0; c < candidates; ++c) {
      const double speed = rng.Uniform(6, 11);
      const Eigen::Vector2i start(rng.UniformInt(0, nx - 1), rng.UniformInt(0, ny - 1));
      const GridRoute route = RandomRoute(L_.grid, rng, speed * duration + 150, 0.5, start, rng.UniformInt(0, 3));
      const LanePath path = PathAlongRoute(L_.grid, route, lane_);
      const double s0 = rng.Uniform(0, 80);
      VehicleTrack v = NewTrack("cross");
      for (int f = 0; f < frames_; ++f) {
        bool active;
        v.world_from_object[f] = VehiclePose(path, s0 + speed * f / rate_, &active);
        v.active[f] = active;
      }
      TryAccept(std::move(v));
    }
  }

  std::vector<VehicleTrack> TakeAccepted() { return std::move(accepted_); }

 private:
  static Footprint FootprintAt(const VehicleTrack& v, int f) {
    const Rigid3& p = v.world_from_object[f];
    const Eigen::Vector3d x = p.rotation * Eigen::Vector3d::UnitX();
    return Footprint{p.translation.head<2>(), std::atan2(x.y(), x.x()), 0.5 * kCarShapes[v.shape].length + 0.4,
                     0.5 * kCarShapes[v.shape].width + 0.2};
  }

  void TryAccept(VehicleTrack v) {
    for (int f = 0; f < frames_; ++f) {
      if (!v.active[f]) continue;
      const Footprint a = FootprintAt(v, f);
      if (Overlap(a, rig_[f])) return;
      for (const VehicleTrack& o : accepted_)
        if (o.active[f] && Overlap(a, FootprintAt(o, f))) return;
    }
    accepted_.push_back(std::move(v));
  }

  VehicleTrack NewTrack(const char* kind) {
    VehicleTrack v;
    v.kind = kind;
    v.shape = rng_.UniformInt(0, kNumCarShapes - 1);
    v.color = rng_.UniformInt(0, kNumCarColors - 1);
    v.world_from_object.resize(frames_);
    v.active.resize(frames_);
    return v;
  }

  const CityLayout& L_;
  SceneRng rng_;
  int frames_;
  double rate_;
  std::vector<Footprint> rig_;  // the rig's car per frame
  double duration_ = 0.0, lane_ = 0.0;
  std::vector<VehicleTrack> accepted_;
};

std::vector<VehicleTrack> PlanTraffic(const CityLayout& L, uint64_t seed, int frames, double rate) {
  TrafficPlanner planner(L, seed, frames, rate);
  planner.AddLeadVehicle();
  planner.AddOncomingTraffic();
  planner.AddCrossTraffic();
  return planner.TakeAccepted();
}

}  // namespace

void AddTraffic(Scene& scene, const CityLayout& L, uint64_t traffic_seed, double frame_rate, CarFactory& cars,
                bool lights_on) {
  const int frames = static_cast<int>(L.trajectory.size());
  const std::vector<VehicleTrack> tracks = PlanTraffic(L, traffic_seed, frames, frame_rate);
  uint16_t id = 1;
  for (const VehicleTrack& v : tracks) {
    Object o;
    o.name = "vehicle_" + std::to_string(id) + "_" + v.kind;
    o.mesh = cars.Get(v.shape, v.color, lights_on);
    o.id = id++;
    o.world_from_object_per_frame = v.world_from_object;
    scene.objects.push_back(std::move(o));
    if (!lights_on) continue;
    const int object = static_cast<int>(scene.objects.size()) - 1;
    for (const Light& l : CarFactory::Headlights(v.shape, object, scene.objects.back().name)) scene.lights.push_back(l);
  }
}

}  // namespace rovo::city_internal
