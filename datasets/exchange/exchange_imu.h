#pragma once
// The IMU in the EuRoC, Kalibr and Basalt exports and in their import (docs/exchange.md, "The IMU").
// With an IMU in the dataset the body frame B of every file is the IMU (frame S of EuRoC, `imu` of
// Kalibr and Basalt), without one it stays the rig.
//
//   mav0/imu0/data.csv         #timestamp [ns],w_RS_S_x [rad s^-1],...,a_RS_S_z [m s^-2]: the measurements
//   mav0/imu0/sensor.yaml      sensor_type imu, T_BS identity, rate_hz, the four noise figures (EuRoC's
//                              keys and units), and rovo_* keys (the rest of the IMU record and
//                              rovo_imu_from_rig, row-major 4x4) that other readers ignore
//   mav0/imu0/rovo_exact.csv   the noise-free samples, same columns (rovo extension)
//   mav0/state_groundtruth_estimate0/data.csv   at every IMU sample: p_RS_R, q_RS (w first), v_RS_R of
//                              the IMU, the true biases b_w_RS_S, b_a_RS_S; stamped at the dataset
//                              (camera-clock) time of the sample, its IMU stamp minus time_offset_s
//   imu.yaml                   (kalibr) Kalibr's IMU keys: noise densities, random walks, rostopic, update_rate
// Camera extrinsics: EuRoC T_BS = imu_from_cam, Kalibr T_cam_imu = cam_from_imu and
// timeshift_cam_imu = time_offset_s (t_imu = t_cam + shift), Basalt T_imu_cam = imu_from_cam,
// cam_time_offset_ns = round(time_offset_s x 1e9), imu_update_rate and the noise densities and random
// walks as *_noise_std / *_bias_std (Basalt's continuous-time figures).

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/imu.h"

namespace rovo {

// cam_from_body of each camera: cam_from_rig * rig_from_imu when the dataset has an IMU (the body is
// the IMU), else cam_from_rig unchanged.
std::vector<Rigid3> ExchangeCamFromBody(const DatasetInfo& info, const std::vector<Rigid3>& cam_from_rig);

// mav0/imu0/*, the IMU-rate ground truth (replacing the frame-rate one) and, for Kalibr, imu.yaml.
// Nothing without an IMU. Throws naming the dataset's files when they cannot be read.
void WriteExchangeImu(const std::string& dataset_dir, const DatasetInfo& info, bool kalibr, const std::string& out_dir);

// A Kalibr camchain with `timeshift_cam_imu` (the IMU's time offset) added to every camera when the
// dataset has an IMU; unchanged without one.
std::string WithKalibrTimeshift(const std::string& camchain, const DatasetInfo& info);

// Basalt's IMU fields of calibration.json's value0 (noise, rate, time offset).
void SetBasaltImu(const ImuRecord& imu, nlohmann::json* calibration);

// Kalibr's imu.yaml text and EuRoC's imu0/sensor.yaml text.
std::string KalibrImuYaml(const ImuRecord& imu);
std::string EurocImuSensorYaml(const ImuRecord& imu, const Rigid3& imu_from_rig);

// An IMU read back from an exported folder.
struct ExchangeImu {
  ImuRecord record;
  ImuStreams streams;
  Rigid3 imu_from_rig;  // rovo_imu_from_rig of imu0/sensor.yaml; identity (the IMU is the rig) without it
};
// Reads mav0/imu0 (data.csv, sensor.yaml, rovo_exact.csv) and the biases of the ground-truth csv;
// nullopt when mav0/imu0/data.csv is absent, or when the noise-free samples or the biases are (a
// rovo dataset holds them too). Throws naming the file, line and field.
std::optional<ExchangeImu> ReadExchangeImu(const std::string& in_dir);

// For an import: when `in_dir` has an IMU (ReadExchangeImu), moves the rig's cameras, perturbed sets
// and the ground truth from the IMU body back to the rovo rig frame (cam_from_rig = cam_from_imu *
// imu_from_rig, world_from_rig = world_from_imu * imu_from_rig), gives `info` the IMU record and
// mount, and writes the three streams into `out_dir`. Returns whether it did.
bool ApplyExchangeImu(const std::string& in_dir, const std::string& out_dir, DatasetInfo* info, Trajectory* gt);

}  // namespace rovo
