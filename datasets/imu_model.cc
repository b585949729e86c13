#include "datasets/imu_model.h"

#include <cmath>
#include <stdexcept>

namespace rovo {

namespace {

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Standard normal draws (Box-Muller on a splitmix64 stream): the same numbers on every platform.
class NormalStream {
 public:
  explicit NormalStream(uint64_t seed) : state_(SplitMix64(seed)) {}
  double Next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = Uniform(), u2 = Uniform();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * M_PI * u2);
  }
  Eigen::Vector3d Next3() {
    const double x = Next(), y = Next(), z = Next();
    return Eigen::Vector3d(x, y, z);
  }

 private:
  double Uniform() {  // in (0, 1]
    state_ = SplitMix64(state_);
    return (static_cast<double>(state_ >> 11) + 1.0) / 9007199254740992.0;
  }
  uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

// Independent streams of one seed.
enum Stream : uint64_t { kGyroNoise = 1, kAccelNoise, kGyroWalk, kAccelWalk, kInitialBias };
uint64_t StreamSeed(uint64_t seed, Stream stream) { return SplitMix64(seed ^ SplitMix64(0x1a0ull + stream)); }

// The noise of the settings: the profile, each override on top, the initial biases drawn unless given.
ImuNoise ResolveNoise(const ImuSettings& s, uint64_t seed, std::string* profile) {
  ImuNoise n = ImuNoiseProfile(s.noise_profile);
  *profile = s.noise_profile;
  auto apply = [&](const std::optional<double>& v, double* field) {
    if (!v) return;
    *field = *v;
    *profile = "custom";
  };
  apply(s.gyroscope_noise_density, &n.gyroscope_noise_density);
  apply(s.gyroscope_random_walk, &n.gyroscope_random_walk);
  apply(s.accelerometer_noise_density, &n.accelerometer_noise_density);
  apply(s.accelerometer_random_walk, &n.accelerometer_random_walk);
  double gyro_sigma = 0.0, accel_sigma = 0.0;
  ImuInitialBiasSigmas(s.noise_profile, &gyro_sigma, &accel_sigma);
  NormalStream draw(StreamSeed(seed, kInitialBias));
  const Eigen::Vector3d gyro_draw = draw.Next3(), accel_draw = draw.Next3();
  n.gyroscope_initial_bias =
      s.gyroscope_initial_bias ? *s.gyroscope_initial_bias : Eigen::Vector3d(gyro_sigma * gyro_draw);
  n.accelerometer_initial_bias =
      s.accelerometer_initial_bias ? *s.accelerometer_initial_bias : Eigen::Vector3d(accel_sigma * accel_draw);
  if (s.gyroscope_initial_bias || s.accelerometer_initial_bias) *profile = "custom";
  return n;
}

void CheckDensity(const std::optional<double>& v, const char* option) {
  if (v && !(*v >= 0.0 && *v <= 1e3))
    throw std::invalid_argument(std::string(option) + " " + std::to_string(*v) + ": must be a number in [0, 1000]");
}

void CheckBias(const std::optional<Eigen::Vector3d>& v, const char* option, double limit) {
  if (v && !(v->allFinite() && v->cwiseAbs().maxCoeff() <= limit))
    throw std::invalid_argument(std::string(option) + ": each component must be a number in [-" +
                                std::to_string(limit) + ", " + std::to_string(limit) + "]");
}

}  // namespace

std::vector<std::string> ImuNoiseProfileNames() { return {"none", "adis16448"}; }

ImuNoise ImuNoiseProfile(const std::string& name) {
  ImuNoise n;
  if (name == "none") return n;
  if (name == "adis16448") {
    // EuRoC MAV dataset, mav0/imu0/sensor.yaml (ADIS16448).
    n.gyroscope_noise_density = 1.6968e-04;
    n.gyroscope_random_walk = 1.9393e-05;
    n.accelerometer_noise_density = 2.0000e-3;
    n.accelerometer_random_walk = 3.0000e-3;
    return n;
  }
  throw std::invalid_argument("--imu-noise `" + name + "`: unknown profile (known: none, adis16448)");
}

void ImuInitialBiasSigmas(const std::string& name, double* gyroscope_sigma, double* accelerometer_sigma) {
  ImuNoiseProfile(name);  // checks the name
  const bool noisy = name != "none";
  *gyroscope_sigma = noisy ? 0.005 : 0.0;     // rad/s (0.29 deg/s)
  *accelerometer_sigma = noisy ? 0.05 : 0.0;  // m/s^2
}

void ImuSettings::Check() const {
  if (!(rate_hz > 0.0 && rate_hz <= 100000.0))
    throw std::invalid_argument("--imu-rate " + std::to_string(rate_hz) + ": must be a number in (0, 100000] Hz");
  ImuNoiseProfile(noise_profile);
  CheckDensity(gyroscope_noise_density, "--imu-gyro-noise-density");
  CheckDensity(gyroscope_random_walk, "--imu-gyro-random-walk");
  CheckDensity(accelerometer_noise_density, "--imu-accel-noise-density");
  CheckDensity(accelerometer_random_walk, "--imu-accel-random-walk");
  CheckBias(gyroscope_initial_bias, "--imu-gyro-bias", 10.0);
  CheckBias(accelerometer_initial_bias, "--imu-accel-bias", 100.0);
  if (!(std::abs(time_offset_s) <= 1.0))
    throw std::invalid_argument("--imu-time-offset-ms " + std::to_string(time_offset_s * 1000.0) +
                                ": must be a number in [-1000, 1000]");
  if (!(gravity_m_s2 >= 0.0 && gravity_m_s2 <= 100.0))
    throw std::invalid_argument("IMU gravity " + std::to_string(gravity_m_s2) + ": must be in [0, 100] m/s^2");
}

ImuSample ExactImuSample(const RigMotionState& state, const Rigid3& imu_from_rig, double gravity_m_s2) {
  const Eigen::Matrix3d imu_r_rig = imu_from_rig.RotationMatrix();
  const Eigen::Matrix3d world_r_rig = state.world_from_rig.RotationMatrix();
  const Eigen::Vector3d imu_in_rig = -(imu_r_rig.transpose() * imu_from_rig.translation);
  const Eigen::Vector3d& w = state.angular_velocity;
  const Eigen::Vector3d lever = state.angular_acceleration.cross(imu_in_rig) + w.cross(w.cross(imu_in_rig));
  const Eigen::Vector3d specific_force_rig =
      world_r_rig.transpose() * (state.linear_acceleration + Eigen::Vector3d(0.0, 0.0, gravity_m_s2)) + lever;
  ImuSample s;
  s.angular_velocity = imu_r_rig * w;
  s.linear_acceleration = imu_r_rig * specific_force_rig;
  return s;
}

ImuGroundTruthState ImuStateAt(const ContinuousTrajectory& trajectory, const Rigid3& imu_from_rig, double t) {
  const RigMotionState s = trajectory.State(t);
  const Eigen::Vector3d imu_in_rig = imu_from_rig.Inverse().translation;
  ImuGroundTruthState out;
  out.timestamp = t;
  out.world_from_imu = s.world_from_rig * imu_from_rig.Inverse();
  out.velocity = s.linear_velocity + s.world_from_rig.rotation * s.angular_velocity.cross(imu_in_rig);
  return out;
}

std::vector<ImuGroundTruthState> ImuGroundTruthStream(const ContinuousTrajectory& trajectory,
                                                      const Rigid3& imu_from_rig, const ImuRecord& record) {
  std::vector<ImuGroundTruthState> out;
  out.reserve(record.sample_count);
  for (int k = 0; k < record.sample_count; ++k) {
    const double stamp = record.first_timestamp + k / record.rate_hz;
    ImuGroundTruthState s = ImuStateAt(trajectory, imu_from_rig, stamp - record.time_offset_s);
    s.timestamp = stamp;
    out.push_back(s);
  }
  return out;
}

std::vector<ImuSample> ExactImuStream(const ContinuousTrajectory& trajectory, const Rigid3& imu_from_rig,
                                      const ImuRecord& record) {
  std::vector<ImuSample> out;
  out.reserve(record.sample_count);
  for (int k = 0; k < record.sample_count; ++k) {
    const double stamp = record.first_timestamp + k / record.rate_hz;
    ImuSample s = ExactImuSample(trajectory.State(stamp - record.time_offset_s), imu_from_rig, record.gravity_m_s2);
    s.timestamp = stamp;
    out.push_back(s);
  }
  return out;
}

ImuStreams SimulateImu(const ContinuousTrajectory& trajectory, const Rigid3& imu_from_rig, const ImuSettings& settings,
                       uint64_t seed, ImuRecord* record) {
  settings.Check();
  ImuRecord r;
  r.rate_hz = settings.rate_hz;
  r.noise = ResolveNoise(settings, seed, &r.noise_profile);
  r.seed = seed;
  r.time_offset_s = settings.time_offset_s;
  r.gravity_m_s2 = settings.gravity_m_s2;
  r.first_timestamp = trajectory.start_time() + settings.time_offset_s;
  const double span = trajectory.end_time() - trajectory.start_time();
  r.sample_count = static_cast<int>(std::floor(span * settings.rate_hz + 1e-9 * settings.rate_hz)) + 1;

  ImuStreams streams;
  streams.exact = ExactImuStream(trajectory, imu_from_rig, r);
  const double dt = 1.0 / r.rate_hz;
  const ImuNoise& n = r.noise;
  NormalStream gyro_noise(StreamSeed(seed, kGyroNoise)), accel_noise(StreamSeed(seed, kAccelNoise));
  NormalStream gyro_walk(StreamSeed(seed, kGyroWalk)), accel_walk(StreamSeed(seed, kAccelWalk));
  Eigen::Vector3d gyro_bias = n.gyroscope_initial_bias, accel_bias = n.accelerometer_initial_bias;
  for (const ImuSample& exact : streams.exact) {
    ImuBiasSample b;
    b.timestamp = exact.timestamp;
    b.gyroscope_bias = gyro_bias;
    b.accelerometer_bias = accel_bias;
    streams.bias.push_back(b);
    ImuSample m = exact;
    m.angular_velocity += gyro_bias + n.gyroscope_noise_density / std::sqrt(dt) * gyro_noise.Next3();
    m.linear_acceleration += accel_bias + n.accelerometer_noise_density / std::sqrt(dt) * accel_noise.Next3();
    streams.measured.push_back(m);
    gyro_bias += n.gyroscope_random_walk * std::sqrt(dt) * gyro_walk.Next3();
    accel_bias += n.accelerometer_random_walk * std::sqrt(dt) * accel_walk.Next3();
  }
  if (record) *record = r;
  return streams;
}

}  // namespace rovo
