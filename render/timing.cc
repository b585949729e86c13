#include "render/timing.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "render/sensor.h"

namespace rovo {

bool TimingSettings::Enabled() const {
  return shutter_ms > 0.0 || shutter_from_sensor || rolling_shutter_ms > 0.0 || trigger_offset_std_ms > 0.0 ||
         !trigger_offset_ms.empty();
}

TimingSettings RealisticTiming() {
  TimingSettings t;
  t.shutter_from_sensor = true;
  t.rolling_shutter_ms = 20.0;
  t.trigger_offset_std_ms = 0.5;
  return t;
}

void TimingSettings::Check(int num_cameras, bool sensor_on) const {
  auto range = [](double v, double hi, const std::string& option) {
    if (!(v >= 0.0 && v <= hi))
      throw std::invalid_argument(option + " " + std::to_string(v) + ": must be in [0, " + std::to_string(hi) + "]");
  };
  range(shutter_ms, 1000.0, "--shutter-ms");
  range(rolling_shutter_ms, 1000.0, "--rolling-shutter-ms");
  range(trigger_offset_std_ms, 1000.0, "--trigger-offset-ms");
  if (shutter_from_sensor && shutter_ms > 0.0)
    throw std::invalid_argument("--motion-blur and --shutter-ms: give one (--motion-blur uses the sensor's exposure)");
  if (shutter_from_sensor && !sensor_on)
    throw std::invalid_argument(
        "--motion-blur: needs the sensor model (--sensor ideal|realistic) for the exposure "
        "time; without it give --shutter-ms");
  if (!trigger_offset_ms.empty()) {
    if (trigger_offset_std_ms > 0.0)
      throw std::invalid_argument("--trigger-offset-ms and --trigger-offsets-ms: give one");
    if (static_cast<int>(trigger_offset_ms.size()) != num_cameras)
      throw std::invalid_argument("--trigger-offsets-ms: " + std::to_string(trigger_offset_ms.size()) +
                                  " values for a rig of " + std::to_string(num_cameras) + " cameras");
    for (double o : trigger_offset_ms)
      if (!(std::abs(o) <= 1000.0))
        throw std::invalid_argument("--trigger-offsets-ms: " + std::to_string(o) + " outside [-1000, 1000]");
  }
}

Rigid3 PoseAtTime(const Trajectory& trajectory, const std::vector<Rigid3>* poses, double t) {
  if (trajectory.empty()) throw std::invalid_argument("PoseAtTime: empty trajectory");
  auto pose = [&](size_t k) -> const Rigid3& { return poses ? (*poses)[k] : trajectory[k].world_from_rig; };
  if (trajectory.size() == 1) return pose(0);
  // The segment [k, k + 1] holding t, or the first / last one outside the samples.
  const auto after = std::upper_bound(trajectory.begin(), trajectory.end(), t,
                                      [](double time, const StampedPose& p) { return time < p.timestamp; });
  size_t k = static_cast<size_t>(after - trajectory.begin());
  k = std::clamp<size_t>(k, 1, trajectory.size() - 1) - 1;
  const double t0 = trajectory[k].timestamp, t1 = trajectory[k + 1].timestamp;
  const double alpha = (t - t0) / (t1 - t0);
  if (alpha == 0.0) return pose(k);
  if (alpha == 1.0) return pose(k + 1);
  return Interpolate(pose(k), pose(k + 1), alpha);
}

std::vector<double> TriggerOffsetsMs(const TimingSettings& settings, int num_cameras, uint64_t seed) {
  if (!settings.trigger_offset_ms.empty()) return settings.trigger_offset_ms;
  std::vector<double> offsets(num_cameras, 0.0);
  if (settings.trigger_offset_std_ms <= 0.0) return offsets;
  for (int c = 0; c < num_cameras; ++c) {
    const uint64_t h = SplitMix64(seed ^ SplitMix64(0x7419ull ^ static_cast<uint64_t>(c)));
    offsets[c] = settings.trigger_offset_std_ms * NormalQuantile(static_cast<uint16_t>(h & 0xffffu));
  }
  return offsets;
}

double HalfWindowSeconds(const std::vector<double>& offsets_ms, double readout_ms,
                         const std::vector<double>& shutter_ms) {
  double offset = 0.0, shutter = 0.0;
  for (double o : offsets_ms) offset = std::max(offset, std::abs(o));
  for (double s : shutter_ms) shutter = std::max(shutter, s);
  return (offset + 0.5 * readout_ms + 0.5 * shutter) / 1000.0;
}

CameraMotion MakeCameraMotion(const ContinuousTrajectory& rig_motion, int frame, const Rigid3& cam_from_rig,
                              double half_window_s, double offset_ms, double shutter_ms, double readout_ms, int height,
                              Rigid3* world_from_cam_at_trigger) {
  const double t = rig_motion.frames().at(frame).timestamp;
  const double window = 2.0 * half_window_s;
  const Rigid3 rig_from_cam = cam_from_rig.Inverse();
  CameraMotion m;
  m.time_mid = static_cast<float>((offset_ms / 1000.0 + half_window_s) / window);
  m.readout = static_cast<float>(readout_ms / 1000.0 / window);
  m.shutter = static_cast<float>(shutter_ms / 1000.0 / window);
  if (height <= 1) m.readout = 0.0f;
  *world_from_cam_at_trigger = rig_motion.Pose(t + offset_ms / 1000.0) * rig_from_cam;
  if (m.readout == 0.0f && m.shutter == 0.0f) return m;
  m.rotation.resize(kMotionPoses);
  m.origin.resize(kMotionPoses);
  for (int k = 0; k < kMotionPoses; ++k) {
    const double time = t - half_window_s + window * k / (kMotionPoses - 1);
    const Rigid3 world_from_cam = rig_motion.Pose(time) * rig_from_cam;
    m.rotation[k] = world_from_cam.RotationMatrix().cast<float>();
    m.origin[k] = world_from_cam.translation.cast<float>();
  }
  return m;
}

TimingRecord MakeTimingRecord(const TimingSettings& settings, const std::vector<double>& offsets_ms) {
  TimingRecord r;
  r.exposure = settings.shutter_from_sensor ? "sensor" : settings.shutter_ms > 0.0 ? "fixed" : "none";
  r.shutter_ms = settings.shutter_ms;
  r.rolling_shutter_ms = settings.rolling_shutter_ms;
  r.trigger_offset_std_ms = settings.trigger_offset_ms.empty() ? settings.trigger_offset_std_ms : 0.0;
  r.trigger_offset_ms = offsets_ms;
  return r;
}

}  // namespace rovo
