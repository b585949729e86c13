#pragma once
// The IMU simulation: exact measurements from the continuous-time ground truth
// (datasets/continuous_trajectory.h) and the Kalibr/EuRoC noise model on top (datasets/imu.h states
// frames, units and the clock). Callable without rendering: `rovo render --imu` writes its output,
// tests and exports call it directly.
//
// Exact values at dataset time tau, for the rig state (R, p, omega, alpha, v, a) and the mount
// imu_from_rig = (R_ir, t_ir) with the IMU origin r = -R_ir^T t_ir in the rig frame:
//   angular_velocity    = R_ir omega
//   linear_acceleration = R_ir (R^T (a + g e_z) + alpha x r + omega x (omega x r))
// (g e_z: minus gravity, gravity pointing along -z of the world).
// Noise (discrete time, dt = 1 / rate): measured_k = exact_k + b_k + sigma_d n_k with
// sigma_d = noise_density / sqrt(dt); b_0 the initial bias, b_k+1 = b_k + random_walk sqrt(dt) m_k;
// n_k, m_k independent standard normal 3-vectors (per sensor) from the seed.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "datasets/continuous_trajectory.h"
#include "datasets/imu.h"
#include "datasets/rigid3.h"

namespace rovo {

// The noise profiles: "none" (exact) and "adis16448" (the Analog Devices ADIS16448 of the EuRoC
// MAV datasets, at the values of EuRoC's imu0/sensor.yaml).
std::vector<std::string> ImuNoiseProfileNames();
// The four densities of a profile (initial biases zero); throws std::invalid_argument for an unknown name.
ImuNoise ImuNoiseProfile(const std::string& name);
// Standard deviations of the seeded draw of the initial biases of a profile (rad/s, m/s^2).
void ImuInitialBiasSigmas(const std::string& name, double* gyroscope_sigma, double* accelerometer_sigma);

struct ImuSettings {
  double rate_hz = 200.0;
  std::string noise_profile = "adis16448";
  // Each overrides the profile's value (and makes the record's profile "custom").
  std::optional<double> gyroscope_noise_density, gyroscope_random_walk;
  std::optional<double> accelerometer_noise_density, accelerometer_random_walk;
  std::optional<Eigen::Vector3d> gyroscope_initial_bias, accelerometer_initial_bias;
  double time_offset_s = 0.0;  // t_imu = t_cam + time_offset_s
  double gravity_m_s2 = 9.81;
  // Throws std::invalid_argument naming the command-line option of the first bad value.
  void Check() const;
};

// The exact IMU sample of a rig state (timestamp left 0).
ImuSample ExactImuSample(const RigMotionState& state, const Rigid3& imu_from_rig, double gravity_m_s2);

// The IMU over the trajectory: stamps first + k / rate on the IMU clock from first = start_time +
// time_offset_s while the dataset time stays within [start_time, end_time] (1e-9 s slack); the
// record gets the noise used (profile, overrides, initial biases as drawn), the seed and the counts.
ImuStreams SimulateImu(const ContinuousTrajectory& trajectory, const Rigid3& imu_from_rig, const ImuSettings& settings,
                       uint64_t seed, ImuRecord* record);

// The IMU's true state (EuRoC's state_groundtruth_estimate0 with the body frame at the IMU): the
// pose world_from_imu = world_from_rig * imu_from_rig^-1 and the velocity of the IMU origin in the
// world frame, v_rig + R (omega x r).
struct ImuGroundTruthState {
  double timestamp = 0.0;  // seconds; ImuGroundTruthStream: IMU clock
  Rigid3 world_from_imu;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s, world frame
};
// At dataset time t (timestamp t).
ImuGroundTruthState ImuStateAt(const ContinuousTrajectory& trajectory, const Rigid3& imu_from_rig, double t);
// At every sample of a record: stamp s on the IMU clock, the state at dataset time s - time_offset_s.
std::vector<ImuGroundTruthState> ImuGroundTruthStream(const ContinuousTrajectory& trajectory,
                                                      const Rigid3& imu_from_rig, const ImuRecord& record);

// The exact stream of a record (the stamps and values SimulateImu gives imu/exact.csv).
std::vector<ImuSample> ExactImuStream(const ContinuousTrajectory& trajectory, const Rigid3& imu_from_rig,
                                      const ImuRecord& record);

}  // namespace rovo
