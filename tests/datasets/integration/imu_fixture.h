#pragma once
// Gives a rendered dataset an IMU (SimulateImu on its continuous-time ground truth, the preset
// mount, the ADIS16448 noise profile) for the export tests, with a camera-to-IMU time offset so
// that the files that carry it are checked too.
#include "datasets/continuous_trajectory.h"
#include "datasets/dataset.h"
#include "datasets/imu.h"
#include "datasets/imu_model.h"

namespace rovo::test {

inline void AddImu(const std::string& dataset, double time_offset_s = 0.0015) {
  DatasetInfo info = ReadDatasetInfo(dataset);
  const ContinuousTrajectory trajectory(ReadTum(GroundTruthPath(dataset)));
  ImuSettings settings;
  settings.time_offset_s = time_offset_s;
  ImuRecord record;
  const ImuStreams streams = SimulateImu(trajectory, PresetImuFromRig(), settings, 11, &record);
  WriteImuStreams(dataset, streams);
  info.imu = record;
  info.rig.imu_from_rig = PresetImuFromRig();
  WriteDatasetInfo(dataset, info);
}

}  // namespace rovo::test
