#pragma once
// The physical sensor model of `rovo render --sensor` (datasets/FORMAT.md, section "Sensor", states
// every rule exactly). Per pixel and channel, following the linear camera model of EMVA 1288:
//
//   mu    = K * q_c * t * L + D * t / 1000         mean electrons (signal + dark signal)
//   e     = Poisson(mu), clipped to [0, FWC]       photon shot noise (and dark-current shot noise)
//   DN    = clamp(round(G * (e + sigma_r * z) * (2^b - 1) / FWC), 0, 2^b - 1)
//   out   = round(255 * CRF(DN / (2^b - 1)))       8-bit output
//
// with L the scene-referred linear radiance the tracer hands over (ShadeSettings::linear_output),
// K the sensitivity (electrons per ms per unit radiance), q_c the camera's sensitivity factor
// (seeded spread), t the exposure time in ms, D the dark current (electrons/s), sigma_r the read
// noise (electrons), z a standard normal deviate, G the analogue gain, b the ADC bits and CRF the
// camera response curve. Exposure time and gain are fixed or set by the auto-exposure controller
// (ExposureSchedule), which meters a small linear render of every frame before any image is made,
// so that every shard of a render knows every frame's exposure. Every random draw is a function of
// (seed, frame, camera, pixel, channel): images do not depend on the thread count.
//
// Pure functions and plain structs; RenderDataset (render/render.cc) drives them.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/response_curve.h"

namespace rovo {

// The camera response curves (ResponseCurve, ApplyResponseCurve) are datasets/response_curve.h's.

// Luminance of linear RGB with Rec. 709 / sRGB primaries: the grayscale sensor's signal and the
// auto-exposure meter's quantity.
inline double Luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

struct SensorSettings {
  bool enabled = false;         // false: the default path (the tracer applies the scene's exposure and sRGB)
  std::string profile = "off";  // the profile the settings started from (SensorProfile)
  // Exposure. With auto_exposure the controller sets time and gain per camera and frame; without,
  // every frame uses exposure_ms and gain.
  bool auto_exposure = true;
  double exposure_ms = 0.1;        // fixed exposure time, ms (auto_exposure false)
  double gain = 1.0;               // fixed analogue gain (auto_exposure false), >= 1
  double min_exposure_ms = 0.01;   // the controller's range of exposure time
  double max_exposure_ms = 20.0;   //   (also at most the frame period)
  double max_gain = 16.0;          //   and of gain, [1, max_gain]
  double ae_target = 0.18;         // target of the centre-weighted mean signal, fraction of full scale
  double ae_rate = 0.25;           // fraction of the log2 exposure error corrected per frame, (0, 1]
  double ae_max_step_stops = 0.5;  // largest exposure change per frame, stops (factors of 2)
  int meter_width = 200;           // width of the meter render, pixels (at most the image width)
  // Sensitivity: electrons per ms per unit of scene radiance at gain 1, and the standard deviation
  // of ln(q_c), the per-camera sensitivity factor.
  double sensitivity_e_per_ms = 100000.0;
  double sensitivity_spread = 0.0;
  // Pixel and readout.
  double full_well_e = 10000.0;  // full-well capacity, electrons (= ADC full scale at gain 1)
  bool shot_noise = true;        // Poisson photon (and dark-current) shot noise
  double read_noise_e = 0.0;     // Gaussian read noise, electrons rms
  double dark_current_e_per_s = 0.0;
  int adc_bits = 12;  // in [8, 16]
  ResponseCurve response = ResponseCurve::kSrgb;
  bool grayscale = false;  // one channel: the luminance of the linear radiance

  // Throws std::invalid_argument naming the command-line option of the first bad value.
  void Check() const;
};

// "off" (the default path), "ideal" (HDR sun, auto-exposure, sRGB response, no noise, no spread,
// 16-bit ADC) or "realistic" (automotive fisheye camera values, render/README.md gives the
// sources); throws std::invalid_argument listing the names.
SensorSettings SensorProfile(const std::string& name);

// Command-line overrides on top of a profile (unset = the profile's value).
struct SensorOverrides {
  std::optional<double> exposure_ms, gain, ae_target, sensitivity, sensitivity_spread, full_well, read_noise,
      dark_current;
  std::optional<bool> auto_exposure, shot_noise, grayscale;
  std::optional<int> adc_bits;
  std::optional<std::string> response;
  bool Any() const;
};
// The profile with the overrides applied and checked. --exposure-ms or --gain fix the exposure
// (auto-exposure off); with --auto-exposure on they are an error, as is any override with profile
// "off". Throws std::invalid_argument naming the option.
SensorSettings MakeSensorSettings(const std::string& profile, const SensorOverrides& overrides);

// q_c = exp(sensitivity_spread * z_c), z_c the standard normal deviate NormalQuantile(word) of the
// low 16 bits of splitmix64(seed ^ splitmix64(0x5e115e ^ c)).
std::vector<double> CameraSensitivities(const SensorSettings& settings, int num_cameras, uint64_t seed);

// Standard normal quantile of the midpoint of 16-bit cell `word`: Phi^-1((word + 1/2) / 65536).
double NormalQuantile(uint16_t word);
// splitmix64, the hash behind every draw of the sensor model.
uint64_t SplitMix64(uint64_t x);
// Seed of the noise of camera index `camera` at dataset frame `frame`:
// splitmix64(seed ^ splitmix64(frame * 16 + camera)).
uint64_t SensorNoiseSeed(uint64_t seed, int frame, int camera);

struct CameraExposure {
  double exposure_ms = 1.0;
  double gain = 1.0;
};

// The meter, output-referred: the luminance M whose exposure x = log2(ae_target / M) (in units of
// full scale per unit radiance) puts the centre-weighted mean of the clipped signal,
// sum_i w_i min(2^x Y_i, 1) / sum_i w_i, at ae_target; w_i = (1 + b_z) / 2 for the unit bearing b of
// every valid pixel of `linear` (3 floats per pixel). Without clipping M is the centre-weighted mean
// luminance; saturated highlights (lamps, the sun disc) count as full scale, not by their radiance.
// 0 when no pixel is valid or the target cannot be reached (too few lit pixels).
double MeterLuminance(const std::vector<float>& linear, const std::vector<Eigen::Vector3f>& bearing,
                      const std::vector<uint8_t>& valid, double ae_target);

// log2 of the exposure (ms x gain) that puts a meter value at the target:
// log2(ae_target * full_well / (sensitivity * meter)); for meter <= 0 the largest exposure.
double TargetLog2Exposure(const SensorSettings& settings, double meter_luminance, double frame_rate);
// Time first, then gain: t = clamp(2^x, t_min, t_max), G = clamp(2^x / t, 1, max_gain).
CameraExposure SplitExposure(const SensorSettings& settings, double log2_exposure, double frame_rate);
// Exposures of every frame and camera from the meter values meter[frame][camera] (the controller
// rule is in datasets/FORMAT.md): frame 0 starts at its target, frame f moves from frame f-1's
// exposure towards frame f-1's target by ae_rate of the log2 error, at most ae_max_step_stops.
// Without auto_exposure every entry is (exposure_ms, gain).
std::vector<std::vector<CameraExposure>> ExposureSchedule(const SensorSettings& settings,
                                                          const std::vector<std::vector<double>>& meter,
                                                          double frame_rate);

// The pixel pipeline of one camera image (formulas at the top of this file).
class SensorPipeline {
 public:
  explicit SensorPipeline(const SensorSettings& settings);

  int full_scale() const { return full_scale_; }  // 2^b - 1
  // The ADC code of one pixel channel with `mean_e` mean electrons (signal + dark) at `gain`;
  // `shot_word` and `read_word` are the 16-bit words of its draws (datasets/FORMAT.md).
  int Digitize(double mean_e, double gain, uint16_t shot_word, uint16_t read_word) const;
  // round(255 * CRF(dn / full_scale)).
  uint8_t Encode(int dn) const { return lut_[dn]; }

  // `linear` (3 floats per pixel, scene radiance) -> `out` (3 bytes per pixel, or 1 when
  // grayscale), parallel over rows in the calling task arena; pixels with valid[i] == 0 are 0.
  void Apply(const std::vector<float>& linear, const std::vector<uint8_t>& valid, const CameraExposure& exposure,
             double camera_sensitivity, uint64_t noise_seed, std::vector<uint8_t>* out) const;

 private:
  SensorSettings settings_;
  int full_scale_ = 4095;
  std::vector<uint8_t> lut_;
};

// The dataset.json record of a render with these settings (datasets/FORMAT.md).
SensorRecord MakeSensorRecord(const SensorSettings& settings, const std::vector<double>& camera_sensitivity);
// exposure.csv rows of dataset frames [0, frames) for the rig's camera names.
std::vector<ExposureRow> MakeExposureRows(const SensorSettings& settings,
                                          const std::vector<std::vector<CameraExposure>>& exposures,
                                          const std::vector<std::vector<double>>& meter,
                                          const std::vector<double>& camera_sensitivity,
                                          const std::vector<std::string>& camera_names);

}  // namespace rovo
