// The lens model of image quality (render/optics.h; rules in datasets/FORMAT.md, section "Optics").
#include "render/optics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "render/sensor.h"

namespace rovo {

namespace {

constexpr int kSigmaSteps = 32;        // sigma quantization: 1/32 pixel
constexpr double kKernelRadius = 3.0;  // kernel half-width in sigmas

// Angle of a bearing from the optical axis (+z).
double BearingAngle(const Eigen::Vector3f& b) { return std::atan2(std::hypot(b.x(), b.y()), b.z()); }

// Half kernel w[0..R] of a sampled Gaussian (unnormalized; the passes normalize over valid taps).
std::vector<float> HalfKernel(double sigma) {
  const int radius = std::max(1, static_cast<int>(std::ceil(kKernelRadius * sigma)));
  std::vector<float> w(radius + 1);
  for (int d = 0; d <= radius; ++d) w[d] = static_cast<float>(std::exp(-0.5 * d * d / (sigma * sigma)));
  return w;
}

// One 1-D pass over `in` into `out` along (dx, dy) = (1, 0) or (0, 1) with the kernel of each output pixel.
void BlurPass(const std::vector<float>& in, const std::vector<uint8_t>& valid, const std::vector<uint16_t>& index,
              const std::vector<std::vector<float>>& kernels, int width, int height, bool vertical,
              std::vector<float>* out_image) {
  std::vector<float>& out = *out_image;
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t i = static_cast<size_t>(y) * width + x;
        if (!valid[i]) continue;
        const std::vector<float>& w = kernels[index[i]];
        const int radius = static_cast<int>(w.size()) - 1;
        const int pos = vertical ? y : x, extent = vertical ? height : width;
        const ptrdiff_t step = vertical ? width : 1;
        float sum[3] = {0.0f, 0.0f, 0.0f}, weight = 0.0f;
        for (int d = -radius; d <= radius; ++d) {
          if (pos + d < 0 || pos + d >= extent) continue;
          const size_t j = static_cast<size_t>(static_cast<ptrdiff_t>(i) + d * step);
          if (!valid[j]) continue;
          const float wd = w[std::abs(d)];
          for (int k = 0; k < 3; ++k) sum[k] += wd * in[j * 3 + k];
          weight += wd;
        }
        for (int k = 0; k < 3; ++k) out[i * 3 + k] = sum[k] / weight;
      }
    }
  });
}

}  // namespace

void OpticsSettings::Check() const {
  if (!enabled) return;
  if (!(mtf50_centre >= 0.0 && mtf50_centre <= 0.5)) throw std::invalid_argument("--mtf50-centre must be in [0, 0.5]");
  if (!(mtf50_rim >= 0.0 && mtf50_rim <= 0.5)) throw std::invalid_argument("--mtf50-rim must be in [0, 0.5]");
  if ((mtf50_centre > 0.0) != (mtf50_rim > 0.0))
    throw std::invalid_argument("--mtf50-centre and --mtf50-rim: both 0 (no blur) or both > 0");
  if (Blur() && std::min(mtf50_centre, mtf50_rim) < 0.02)
    throw std::invalid_argument("--mtf50-centre/--mtf50-rim: at least 0.02 cycles per pixel (a PSF of < 10 px sigma)");
  if (!(mtf50_spread >= 0.0 && mtf50_spread <= 1.0)) throw std::invalid_argument("--mtf50-spread must be in [0, 1]");
  if (!(falloff_angle_scale >= 0.0 && falloff_angle_scale < 1.0))
    throw std::invalid_argument("--falloff-angle-scale must be in [0, 1)");
  if (!(rim_illumination > 0.0 && rim_illumination <= 1.0))
    throw std::invalid_argument("--rim-illumination must be in (0, 1]");
  if (!(std::abs(lateral_ca_red) <= 0.05)) throw std::invalid_argument("--lateral-ca (red) must be in [-0.05, 0.05]");
  if (!(std::abs(lateral_ca_blue) <= 0.05)) throw std::invalid_argument("--lateral-ca (blue) must be in [-0.05, 0.05]");
  if (!(veiling_glare >= 0.0 && veiling_glare <= 1.0)) throw std::invalid_argument("--veiling-glare must be in [0, 1]");
}

OpticsSettings OpticsProfile(const std::string& name) {
  OpticsSettings s;
  s.profile = name;
  if (name == "off") return s;
  if (name != "realistic") throw std::invalid_argument("--optics: unknown profile `" + name + "` (off, realistic)");
  // A 220-degree M12 fisheye on a ~3 um-pixel sensor; render/README.md ("Optics") gives the sources and
  // which values are fitted to the real frames of ../shared/data/itbt_real.
  s.enabled = true;
  s.mtf50_centre = 0.35;
  s.mtf50_rim = 0.20;
  s.mtf50_spread = 0.05;
  s.falloff_angle_scale = 0.30;
  s.rim_illumination = 0.40;
  // Lateral colour that leaves the luminance in place (0.2126 * 0.001 - 0.0722 * 0.003 = 0): a rig calibrated
  // on its own images has the luminance's geometry, which the ground-truth camera model states.
  s.lateral_ca_red = 0.001;
  s.lateral_ca_blue = -0.003;
  s.veiling_glare = 0.02;
  return s;
}

bool OpticsOverrides::Any() const {
  return mtf50_centre || mtf50_rim || mtf50_spread || falloff_angle_scale || rim_illumination || lateral_ca_red ||
         lateral_ca_blue || veiling_glare;
}

OpticsSettings MakeOpticsSettings(const std::string& profile, const OpticsOverrides& o) {
  OpticsSettings s = OpticsProfile(profile);
  if (!o.Any()) return s;
  if (!s.enabled)
    throw std::invalid_argument("the lens options (--mtf50-centre, --rim-illumination, ...) need --optics realistic");
  const OpticsSettings before = s;
  auto set = [](const std::optional<double>& v, double* field) {
    if (v) *field = *v;
  };
  set(o.mtf50_centre, &s.mtf50_centre);
  set(o.mtf50_rim, &s.mtf50_rim);
  set(o.mtf50_spread, &s.mtf50_spread);
  set(o.falloff_angle_scale, &s.falloff_angle_scale);
  set(o.rim_illumination, &s.rim_illumination);
  set(o.lateral_ca_red, &s.lateral_ca_red);
  set(o.lateral_ca_blue, &s.lateral_ca_blue);
  set(o.veiling_glare, &s.veiling_glare);
  if (MakeOpticsRecord(s, {}) != MakeOpticsRecord(before, {})) s.profile = "custom";
  s.Check();
  return s;
}

double GaussianSigmaFromMtf50(double mtf50) { return std::sqrt(std::log(2.0) / 2.0) / (M_PI * mtf50); }

double LensRelativeIllumination(const OpticsSettings& s, double theta, double theta_max) {
  return RelativeIlluminationAt(s.falloff_angle_scale, s.rim_illumination, theta, theta_max);
}

double PsfSigma(const OpticsSettings& s, double mtf50_factor, double theta, double theta_max) {
  if (!s.Blur()) return 0.0;
  const double u = theta / theta_max;
  return GaussianSigmaFromMtf50(mtf50_factor * (s.mtf50_centre + (s.mtf50_rim - s.mtf50_centre) * u * u));
}

std::vector<double> CameraMtf50Factors(const OpticsSettings& s, int num_cameras, uint64_t seed) {
  std::vector<double> m(num_cameras, 1.0);
  for (int c = 0; c < num_cameras; ++c) {
    const uint64_t h = SplitMix64(seed ^ SplitMix64(0x0971c5ull ^ static_cast<uint64_t>(c)));
    m[c] = std::exp(s.mtf50_spread * NormalQuantile(static_cast<uint16_t>(h & 0xffffu)));
  }
  return m;
}

LensOptics::LensOptics(const OpticsSettings& settings, const Camera& camera,
                       const std::vector<Eigen::Vector3f>& bearing, const std::vector<uint8_t>& valid,
                       double mtf50_factor)
    : settings_(settings), width_(camera.width), height_(camera.height), valid_(valid) {
  settings_.Check();
  const double theta_max = camera.max_fov_deg * M_PI / 360.0;
  if (settings_.falloff_angle_scale * theta_max >= 0.5 * M_PI)
    throw std::invalid_argument("--falloff-angle-scale: k * theta_max must stay below 90 degrees (field of view " +
                                std::to_string(camera.max_fov_deg) + " degrees)");
  const size_t n = static_cast<size_t>(width_) * height_;
  illumination_.assign(n, 0.0f);
  sigma_index_.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!valid_[i]) continue;
    const double theta = BearingAngle(bearing[i]);
    illumination_[i] = static_cast<float>(LensRelativeIllumination(settings_, theta, theta_max));
    const double sigma = PsfSigma(settings_, mtf50_factor, theta, theta_max);
    sigma_index_[i] = static_cast<uint16_t>(std::clamp(std::lround(sigma * kSigmaSteps), 1L, 65535L));
  }
  if (settings_.Blur()) {
    const uint16_t top = *std::max_element(sigma_index_.begin(), sigma_index_.end());
    kernels_.resize(top + 1);
    for (int k = 1; k <= top; ++k) kernels_[k] = HalfKernel(static_cast<double>(k) / kSigmaSteps);
  }
  const std::optional<Eigen::Vector2d> p0 = camera.Project(Eigen::Vector3d::UnitZ());
  principal_point_ = p0 ? *p0 : Eigen::Vector2d(0.5 * (width_ - 1), 0.5 * (height_ - 1));
}

void LensOptics::Apply(std::vector<float>* linear) const {
  if (linear->size() != valid_.size() * 3)
    throw std::invalid_argument("LensOptics::Apply: the image does not match the camera's size");
  if (settings_.Blur()) Blur(linear);
  if (settings_.lateral_ca_red != 0.0 || settings_.lateral_ca_blue != 0.0) LateralColour(linear);
  VignettingAndGlare(linear);
}

void LensOptics::Blur(std::vector<float>* linear) const {
  // A copy of the image kept per thread: a fresh 30 MB buffer per image costs more in page faults
  // than the pass itself (about 5x on this machine's VM).
  thread_local std::vector<float> rows;
  rows.assign(linear->begin(), linear->end());
  BlurPass(*linear, valid_, sigma_index_, kernels_, width_, height_, false, &rows);
  BlurPass(rows, valid_, sigma_index_, kernels_, width_, height_, true, linear);
}

void LensOptics::LateralColour(std::vector<float>* linear) const {
  thread_local std::vector<float> copy;  // kept per thread, as in Blur
  copy.assign(linear->begin(), linear->end());
  const std::vector<float>& in = copy;
  const double scale[2] = {1.0 / (1.0 + settings_.lateral_ca_red), 1.0 / (1.0 + settings_.lateral_ca_blue)};
  const int channel[2] = {0, 2};
  tbb::parallel_for(tbb::blocked_range<int>(0, height_), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < width_; ++x) {
        const size_t i = static_cast<size_t>(y) * width_ + x;
        if (!valid_[i]) continue;
        for (int c = 0; c < 2; ++c) {
          if (scale[c] == 1.0) continue;
          const double u = principal_point_.x() + (x - principal_point_.x()) * scale[c];
          const double v = principal_point_.y() + (y - principal_point_.y()) * scale[c];
          const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
          if (x0 < 0 || y0 < 0 || x0 + 1 >= width_ || y0 + 1 >= height_) continue;
          const size_t j = static_cast<size_t>(y0) * width_ + x0;
          if (!(valid_[j] & valid_[j + 1] & valid_[j + width_] & valid_[j + width_ + 1])) continue;
          const float ax = static_cast<float>(u - x0), ay = static_cast<float>(v - y0);
          const int k = channel[c];
          const float top = in[j * 3 + k] + ax * (in[(j + 1) * 3 + k] - in[j * 3 + k]);
          const float bottom =
              in[(j + width_) * 3 + k] + ax * (in[(j + width_ + 1) * 3 + k] - in[(j + width_) * 3 + k]);
          (*linear)[i * 3 + k] = top + ay * (bottom - top);
        }
      }
    }
  });
}

void LensOptics::VignettingAndGlare(std::vector<float>* linear) const {
  std::vector<float>& image = *linear;
  double mean[3] = {0.0, 0.0, 0.0};
  size_t count = 0;
  for (size_t i = 0; i < valid_.size(); ++i) {
    if (!valid_[i]) continue;
    for (int k = 0; k < 3; ++k) {
      image[i * 3 + k] *= illumination_[i];
      mean[k] += image[i * 3 + k];
    }
    ++count;
  }
  if (settings_.veiling_glare <= 0.0 || count == 0) return;
  float add[3];
  for (int k = 0; k < 3; ++k) add[k] = static_cast<float>(settings_.veiling_glare * mean[k] / count);
  for (size_t i = 0; i < valid_.size(); ++i) {
    if (!valid_[i]) continue;
    for (int k = 0; k < 3; ++k) image[i * 3 + k] += add[k];
  }
}

OpticsRecord MakeOpticsRecord(const OpticsSettings& s, const std::vector<double>& camera_mtf50_factor) {
  OpticsRecord r;
  r.profile = s.profile;
  r.mtf50_centre = s.mtf50_centre;
  r.mtf50_rim = s.mtf50_rim;
  r.mtf50_spread = s.mtf50_spread;
  r.camera_mtf50_factor = camera_mtf50_factor;
  r.falloff_angle_scale = s.falloff_angle_scale;
  r.rim_illumination = s.rim_illumination;
  r.lateral_ca_red = s.lateral_ca_red;
  r.lateral_ca_blue = s.lateral_ca_blue;
  r.veiling_glare = s.veiling_glare;
  return r;
}

}  // namespace rovo
