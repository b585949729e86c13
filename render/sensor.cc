#include "render/sensor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace rovo {
namespace {

// Below this mean (electrons) shot noise is drawn exactly from the Poisson distribution by
// inversion; from it on by the normal approximation N(mu, mu).
constexpr double kPoissonExactBelow = 16.0;

// Phi^-1(p) for p in (0, 1): the Abramowitz-Stegun 26.2.23 start refined by three Newton steps on
// Phi(x) = erfc(-x / sqrt(2)) / 2 (double precision).
double InverseNormalCdf(double p) {
  const double q = std::min(p, 1.0 - p);
  const double t = std::sqrt(-2.0 * std::log(q));
  double x =
      t - (2.515517 + 0.802853 * t + 0.010328 * t * t) / (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
  if (p < 0.5) x = -x;
  for (int i = 0; i < 3; ++i) {
    const double cdf = 0.5 * std::erfc(-x / std::sqrt(2.0));
    const double pdf = std::exp(-0.5 * x * x) / std::sqrt(2.0 * M_PI);
    x -= (cdf - p) / pdf;
  }
  return x;
}

const std::array<float, 65536>& NormalTable() {
  static const std::array<float, 65536> table = [] {
    std::array<float, 65536> t{};
    // The lower half, mirrored: the table is exactly antisymmetric (zero mean).
    for (int i = 0; i < 32768; ++i) {
      const float x = static_cast<float>(InverseNormalCdf((i + 0.5) / 65536.0));
      t[i] = x;
      t[65535 - i] = -x;
    }
    return t;
  }();
  return table;
}

// Poisson(mu) by inversion of the CDF at u in (0, 1).
int PoissonInverse(double mu, double u) {
  double p = std::exp(-mu);
  double cdf = p;
  int k = 0;
  while (u > cdf && k < 200) {
    ++k;
    p *= mu / k;
    cdf += p;
  }
  return k;
}

bool Finite(double x) { return std::isfinite(x); }

}  // namespace

// ---- hashing ------------------------------------------------------------------

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

uint64_t SensorNoiseSeed(uint64_t seed, int frame, int camera) {
  return SplitMix64(seed ^ SplitMix64(static_cast<uint64_t>(frame) * 16 + static_cast<uint64_t>(camera)));
}

double NormalQuantile(uint16_t word) { return NormalTable()[word]; }

// ---- settings --------------------------------------------------------------------------------------

void SensorSettings::Check() const {
  if (!enabled) return;
  auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  if (!(exposure_ms > 0.0) || !Finite(exposure_ms)) fail("--exposure-ms must be a positive number of milliseconds");
  if (!(gain >= 1.0) || !Finite(gain)) fail("--gain must be >= 1 (analogue gain)");
  if (!(min_exposure_ms > 0.0) || !(max_exposure_ms >= min_exposure_ms) || !Finite(max_exposure_ms))
    fail("sensor exposure range: need 0 < min_exposure_ms <= max_exposure_ms");
  if (!(max_gain >= 1.0) || !Finite(max_gain)) fail("sensor max_gain must be >= 1");
  if (!(ae_target > 0.0 && ae_target <= 1.0)) fail("--ae-target must be in (0, 1] (fraction of the ADC full scale)");
  if (!(ae_rate > 0.0 && ae_rate <= 1.0)) fail("sensor ae_rate must be in (0, 1]");
  if (!(ae_max_step_stops > 0.0) || !Finite(ae_max_step_stops)) fail("sensor ae_max_step_stops must be > 0");
  if (meter_width < 8) fail("sensor meter_width must be >= 8 pixels");
  if (!(sensitivity_e_per_ms > 0.0) || !Finite(sensitivity_e_per_ms))
    fail("--sensitivity must be > 0 (electrons per ms per unit radiance)");
  if (!(sensitivity_spread >= 0.0 && sensitivity_spread <= 1.0)) fail("--sensitivity-spread must be in [0, 1]");
  if (!(full_well_e >= 1.0) || !Finite(full_well_e)) fail("--full-well must be >= 1 electron");
  if (!(read_noise_e >= 0.0) || !Finite(read_noise_e)) fail("--read-noise must be >= 0 electrons");
  if (!(dark_current_e_per_s >= 0.0) || !Finite(dark_current_e_per_s))
    fail("--dark-current must be >= 0 electrons per second");
  if (adc_bits < 8 || adc_bits > 16) fail("--adc-bits must be in [8, 16]");
}

SensorSettings SensorProfile(const std::string& name) {
  SensorSettings s;
  s.profile = name;
  if (name == "off") return s;
  s.enabled = true;
  if (name == "ideal") {
    s.sensitivity_spread = 0.0;
    s.shot_noise = false;
    s.read_noise_e = 0.0;
    s.dark_current_e_per_s = 0.0;
    s.adc_bits = 16;
    s.response = ResponseCurve::kSrgb;
    return s;
  }
  if (name == "realistic") {
    // Values and their sources: render/README.md, "Sensor model".
    s.sensitivity_spread = 0.05;
    s.full_well_e = 10000.0;
    s.shot_noise = true;
    s.read_noise_e = 3.0;
    s.dark_current_e_per_s = 50.0;
    s.adc_bits = 12;
    s.response = ResponseCurve::kBt709;
    return s;
  }
  throw std::invalid_argument("--sensor '" + name + "': unknown profile (known: off, ideal, realistic)");
}

bool SensorOverrides::Any() const {
  return exposure_ms || gain || ae_target || sensitivity || sensitivity_spread || full_well || read_noise ||
         dark_current || auto_exposure || shot_noise || grayscale || adc_bits || response;
}

SensorSettings MakeSensorSettings(const std::string& profile, const SensorOverrides& o) {
  SensorSettings s = SensorProfile(profile);
  if (!s.enabled) {
    if (o.Any())
      throw std::invalid_argument(
          "the sensor options (--exposure-ms, --gain, --auto-exposure, --full-well, --read-noise, ...) need "
          "--sensor ideal or --sensor realistic");
    return s;
  }
  const bool fixed = o.exposure_ms.has_value() || o.gain.has_value();
  if (fixed && o.auto_exposure.value_or(false))
    throw std::invalid_argument(
        "--auto-exposure on cannot be combined with --exposure-ms or --gain (a fixed exposure)");
  if (fixed) s.auto_exposure = false;
  if (o.auto_exposure) s.auto_exposure = *o.auto_exposure;
  if (o.exposure_ms) s.exposure_ms = *o.exposure_ms;
  if (o.gain) s.gain = *o.gain;
  if (o.ae_target) s.ae_target = *o.ae_target;
  if (o.sensitivity) s.sensitivity_e_per_ms = *o.sensitivity;
  if (o.sensitivity_spread) s.sensitivity_spread = *o.sensitivity_spread;
  if (o.full_well) s.full_well_e = *o.full_well;
  if (o.read_noise) s.read_noise_e = *o.read_noise;
  if (o.dark_current) s.dark_current_e_per_s = *o.dark_current;
  if (o.shot_noise) s.shot_noise = *o.shot_noise;
  if (o.grayscale) s.grayscale = *o.grayscale;
  if (o.adc_bits) s.adc_bits = *o.adc_bits;
  if (o.response) s.response = ResponseCurveFromName(*o.response);
  s.Check();
  return s;
}

std::vector<double> CameraSensitivities(const SensorSettings& settings, int num_cameras, uint64_t seed) {
  std::vector<double> q(num_cameras, 1.0);
  for (int c = 0; c < num_cameras; ++c) {
    const uint64_t h = SplitMix64(seed ^ SplitMix64(0x5e115eull ^ static_cast<uint64_t>(c)));
    q[c] = std::exp(settings.sensitivity_spread * NormalQuantile(static_cast<uint16_t>(h & 0xffffu)));
  }
  return q;
}

// ---- auto-exposure ---------------------------------------------------------------------------------

double MeterLuminance(const std::vector<float>& linear, const std::vector<Eigen::Vector3f>& bearing,
                      const std::vector<uint8_t>& valid, double ae_target) {
  // (luminance, weight) of the valid pixels, brightest first.
  std::vector<std::pair<double, double>> pixels;
  double weight = 0.0, sum = 0.0;
  for (size_t i = 0; i < valid.size(); ++i) {
    if (!valid[i]) continue;
    const double w = 0.5 * (1.0 + bearing[i].z());
    const double y = Luminance(linear[3 * i], linear[3 * i + 1], linear[3 * i + 2]);
    pixels.emplace_back(y, w);
    weight += w;
    sum += w * y;
  }
  if (!(weight > 0.0)) return 0.0;
  std::sort(pixels.begin(), pixels.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  // With the k brightest pixels clipped, sum_w min(s Y, 1) / W = target is linear in s:
  // s = (target W - W_k) / S_k (W_k their weight, S_k the weighted luminance of the rest); the
  // first k whose next pixel stays below full scale is the solution.
  double clipped_weight = 0.0;
  for (size_t k = 0; k <= pixels.size(); ++k) {
    if (!(sum > 0.0) || ae_target * weight <= clipped_weight) return 0.0;  // unreachable: the longest exposure
    const double s = (ae_target * weight - clipped_weight) / sum;
    if (k == pixels.size() || s * pixels[k].first < 1.0) return ae_target / s;
    clipped_weight += pixels[k].second;
    sum -= pixels[k].second * pixels[k].first;
  }
  return 0.0;
}

namespace {

// The exposure time range [t_min, t_max] in ms, t_max at most the frame period.
std::pair<double, double> ExposureTimeRange(const SensorSettings& s, double frame_rate) {
  const double period_ms = frame_rate > 0.0 ? 1000.0 / frame_rate : s.max_exposure_ms;
  const double t_max = std::max(s.min_exposure_ms, std::min(s.max_exposure_ms, period_ms));
  return {s.min_exposure_ms, t_max};
}

}  // namespace

double TargetLog2Exposure(const SensorSettings& s, double meter_luminance, double frame_rate) {
  const auto [t_min, t_max] = ExposureTimeRange(s, frame_rate);
  const double lo = std::log2(t_min), hi = std::log2(t_max * s.max_gain);
  if (!(meter_luminance > 0.0) || !Finite(meter_luminance)) return hi;
  const double x = std::log2(s.ae_target * s.full_well_e / (s.sensitivity_e_per_ms * meter_luminance));
  return std::clamp(x, lo, hi);
}

CameraExposure SplitExposure(const SensorSettings& s, double log2_exposure, double frame_rate) {
  const auto [t_min, t_max] = ExposureTimeRange(s, frame_rate);
  const double total = std::exp2(log2_exposure);
  CameraExposure e;
  e.exposure_ms = std::clamp(total, t_min, t_max);
  e.gain = std::clamp(total / e.exposure_ms, 1.0, s.max_gain);
  return e;
}

std::vector<std::vector<CameraExposure>> ExposureSchedule(const SensorSettings& s,
                                                          const std::vector<std::vector<double>>& meter,
                                                          double frame_rate) {
  std::vector<std::vector<CameraExposure>> out(meter.size());
  std::vector<double> state, target;
  for (size_t f = 0; f < meter.size(); ++f) {
    const size_t num_cameras = meter[f].size();
    out[f].resize(num_cameras);
    for (size_t c = 0; c < num_cameras; ++c) {
      if (!s.auto_exposure) {
        out[f][c] = CameraExposure{s.exposure_ms, s.gain};
        continue;
      }
      if (f == 0) {
        state.push_back(TargetLog2Exposure(s, meter[0][c], frame_rate));
      } else {
        // One frame of latency: the move towards frame f-1's target.
        const double step = s.ae_rate * (target[c] - state[c]);
        state[c] += std::clamp(step, -s.ae_max_step_stops, s.ae_max_step_stops);
      }
      out[f][c] = SplitExposure(s, state[c], frame_rate);
    }
    if (s.auto_exposure) {
      target.resize(num_cameras);
      for (size_t c = 0; c < num_cameras; ++c) target[c] = TargetLog2Exposure(s, meter[f][c], frame_rate);
    }
  }
  return out;
}

// ---- the pixel pipeline --------------------------------------------------------------------------

SensorPipeline::SensorPipeline(const SensorSettings& settings) : settings_(settings) {
  full_scale_ = (1 << settings.adc_bits) - 1;
  lut_.resize(full_scale_ + 1);
  for (int dn = 0; dn <= full_scale_; ++dn) {
    const double y = ApplyResponseCurve(settings.response, static_cast<double>(dn) / full_scale_);
    lut_[dn] = static_cast<uint8_t>(std::clamp(std::floor(255.0 * y + 0.5), 0.0, 255.0));
  }
  NormalTable();  // built before the parallel loops
}

int SensorPipeline::Digitize(double mean_e, double gain, uint16_t shot_word, uint16_t read_word) const {
  double e = 0.0;
  if (mean_e > 0.0) {
    if (!settings_.shot_noise) {
      e = mean_e;
    } else if (mean_e < kPoissonExactBelow) {
      e = PoissonInverse(mean_e, (shot_word + 0.5) / 65536.0);
    } else {
      e = mean_e + std::sqrt(mean_e) * NormalTable()[shot_word];
    }
  }
  e = std::min(std::max(e, 0.0), settings_.full_well_e);  // NaN -> 0
  if (settings_.read_noise_e > 0.0) e += settings_.read_noise_e * NormalTable()[read_word];
  const double dn = gain * e * full_scale_ / settings_.full_well_e;
  if (!(dn > 0.0)) return 0;
  if (dn >= full_scale_) return full_scale_;
  return static_cast<int>(dn + 0.5);  // NOLINT(bugprone-incorrect-roundings): dn > 0, so this rounds half up
}

void SensorPipeline::Apply(const std::vector<float>& linear, const std::vector<uint8_t>& valid,
                           const CameraExposure& exposure, double camera_sensitivity, uint64_t noise_seed,
                           std::vector<uint8_t>* out) const {
  const size_t n = valid.size();
  const int channels = settings_.grayscale ? 1 : 3;
  if (linear.size() != 3 * n) throw std::invalid_argument("SensorPipeline::Apply: linear image of the wrong size");
  out->resize(n * channels);
  const double electrons_per_radiance = settings_.sensitivity_e_per_ms * camera_sensitivity * exposure.exposure_ms;
  const double dark_e = settings_.dark_current_e_per_s * exposure.exposure_ms / 1000.0;
  const double gain = exposure.gain;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) {
      uint8_t* o = out->data() + i * channels;
      if (!valid[i]) {
        for (int k = 0; k < channels; ++k) o[k] = 0;
        continue;
      }
      const float* l = linear.data() + 3 * i;
      const uint64_t h0 = SplitMix64(noise_seed ^ SplitMix64(2 * static_cast<uint64_t>(i)));
      auto word = [](uint64_t h, int k) { return static_cast<uint16_t>((h >> (16 * k)) & 0xffffu); };
      if (channels == 1) {
        const double mean = electrons_per_radiance * Luminance(l[0], l[1], l[2]) + dark_e;
        o[0] = lut_[Digitize(mean, gain, word(h0, 0), word(h0, 1))];
        continue;
      }
      const uint64_t h1 = SplitMix64(noise_seed ^ SplitMix64(2 * static_cast<uint64_t>(i) + 1));
      // Channel k: words 2k (shot) and 2k + 1 (read) of h0 then h1.
      o[0] = lut_[Digitize(electrons_per_radiance * l[0] + dark_e, gain, word(h0, 0), word(h0, 1))];
      o[1] = lut_[Digitize(electrons_per_radiance * l[1] + dark_e, gain, word(h0, 2), word(h0, 3))];
      o[2] = lut_[Digitize(electrons_per_radiance * l[2] + dark_e, gain, word(h1, 0), word(h1, 1))];
    }
  });
}

// ---- records ---------------------------------------------------------------------------------------

SensorRecord MakeSensorRecord(const SensorSettings& s, const std::vector<double>& camera_sensitivity) {
  SensorRecord r;
  r.profile = s.profile;
  r.auto_exposure = s.auto_exposure;
  r.exposure_ms = s.exposure_ms;
  r.gain = s.gain;
  r.min_exposure_ms = s.min_exposure_ms;
  r.max_exposure_ms = s.max_exposure_ms;
  r.max_gain = s.max_gain;
  r.ae_target = s.ae_target;
  r.ae_rate = s.ae_rate;
  r.ae_max_step_stops = s.ae_max_step_stops;
  r.meter_width = s.meter_width;
  r.sensitivity_e_per_ms = s.sensitivity_e_per_ms;
  r.sensitivity_spread = s.sensitivity_spread;
  r.camera_sensitivity = camera_sensitivity;
  r.full_well_e = s.full_well_e;
  r.shot_noise = s.shot_noise;
  r.read_noise_e = s.read_noise_e;
  r.dark_current_e_per_s = s.dark_current_e_per_s;
  r.adc_bits = s.adc_bits;
  r.response = ResponseCurveName(s.response);
  r.grayscale = s.grayscale;
  return r;
}

std::vector<ExposureRow> MakeExposureRows(const SensorSettings& s,
                                          const std::vector<std::vector<CameraExposure>>& exposures,
                                          const std::vector<std::vector<double>>& meter,
                                          const std::vector<double>& camera_sensitivity,
                                          const std::vector<std::string>& camera_names) {
  const double full_scale = (1 << s.adc_bits) - 1;
  std::vector<ExposureRow> rows;
  for (size_t f = 0; f < exposures.size(); ++f) {
    for (size_t c = 0; c < exposures[f].size(); ++c) {
      const CameraExposure& e = exposures[f][c];
      ExposureRow row;
      row.frame = static_cast<int>(f);
      row.camera = camera_names[c];
      row.exposure_ms = e.exposure_ms;
      row.gain = e.gain;
      row.meter_luminance = meter[f][c];
      const double dn_per_electron = e.gain * full_scale / s.full_well_e;
      row.dn_per_radiance = dn_per_electron * s.sensitivity_e_per_ms * camera_sensitivity[c] * e.exposure_ms;
      row.dark_dn = dn_per_electron * s.dark_current_e_per_s * e.exposure_ms / 1000.0;
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace rovo
