#pragma once
// Exposure timing of `rovo render` (datasets/FORMAT.md, section "Timing", states every rule
// exactly): per-camera trigger offsets, motion blur over the exposure interval and a rolling
// shutter. Camera c of dataset frame f (trajectory time t_f) is triggered at t_f + o_c; row v
// (0 = top) of its H rows is exposed over [t_v - T/2, t_v + T/2] with
//   t_v = t_f + o_c + (v / (H - 1) - 1/2) * R,
// T the exposure (shutter) time and R the rolling-shutter readout time of the whole image. The rig
// at any time comes from the dataset's continuous-time ground truth (ContinuousTrajectory,
// datasets/continuous_trajectory.h: a C2 spline through the poses of groundtruth.tum, the same
// curve the IMU samples); the dynamic objects keep their own motion, from the scene's per-frame
// samples by PoseAtTime.
//
// Pure functions and plain structs; RenderDataset (render/render.cc) drives them, the tracer
// (render/tracer.h, CameraMotion and Tracer::SetFrameWindow) samples the times.

#include <cstdint>
#include <vector>

#include "datasets/continuous_trajectory.h"
#include "datasets/dataset.h"
#include "datasets/rigid3.h"
#include "datasets/trajectory.h"
#include "render/tracer.h"

namespace rovo {

struct TimingSettings {
  double shutter_ms = 0.0;                // fixed exposure interval of the motion blur, ms (0: none)
  bool shutter_from_sensor = false;       // blur over the sensor model's exposure time (exposure.csv)
  double rolling_shutter_ms = 0.0;        // readout of the whole image, top row first (0: global shutter)
  double trigger_offset_std_ms = 0.0;     // standard deviation of the seeded per-camera offset draw
  std::vector<double> trigger_offset_ms;  // explicit per-camera offsets (instead of the draw)

  bool Enabled() const;
  // Throws std::invalid_argument naming the command-line option of the first bad value;
  // `num_cameras` checks the count of explicit offsets, `sensor_on` --motion-blur.
  void Check(int num_cameras, bool sensor_on) const;
};

// The timing of the realistic profile (`rovo render --realistic`, render/README.md gives the sources):
// motion blur over the sensor's exposure, a 20 ms rolling-shutter readout, per-camera trigger offsets
// drawn with a standard deviation of 0.5 ms.
TimingSettings RealisticTiming();

// Pose at time t (seconds) of a sampled motion: the samples' times are the trajectory's
// timestamps, the poses `poses` (one per trajectory frame; nullptr: the trajectory's
// world_from_rig). Between samples k and k + 1 (t_k <= t <= t_k+1): rotation slerp and linear
// translation with alpha = (t - t_k) / (t_k+1 - t_k) (Interpolate, datasets/rigid3.h); before the
// first or after the last sample the first or last segment is extrapolated (alpha < 0 or > 1); a
// one-sample trajectory is constant.
Rigid3 PoseAtTime(const Trajectory& trajectory, const std::vector<Rigid3>* poses, double t);

// o_c in ms: the explicit offsets, else trigger_offset_std_ms * Phi^-1((w + 1/2) / 65536) with w
// the low 16 bits of splitmix64(seed ^ splitmix64(0x7419 ^ c)) (NormalQuantile, render/sensor.h).
std::vector<double> TriggerOffsetsMs(const TimingSettings& settings, int num_cameras, uint64_t seed);

// Half-width (s) of the time window of a frame around its time: max_c |o_c| + R / 2 + max_c T_c / 2.
double HalfWindowSeconds(const std::vector<double>& offsets_ms, double readout_ms,
                         const std::vector<double>& shutter_ms);

// Poses in a CameraMotion table (ray times k / (kMotionPoses - 1)).
inline constexpr int kMotionPoses = 129;

// The CameraMotion of a camera of trajectory frame `frame` (of rig_motion.frames()) over the window
// [t_f - h, t_f + h] (h = half_window_s > 0), and world_from_cam at its trigger time t_f + o_c (the
// pose Render takes), the rig from the continuous-time ground truth. `height` is the image height in rows.
CameraMotion MakeCameraMotion(const ContinuousTrajectory& rig_motion, int frame, const Rigid3& cam_from_rig,
                              double half_window_s, double offset_ms, double shutter_ms, double readout_ms, int height,
                              Rigid3* world_from_cam_at_trigger);

// The dataset.json record of a render with these settings and offsets.
TimingRecord MakeTimingRecord(const TimingSettings& settings, const std::vector<double>& offsets_ms);

}  // namespace rovo
