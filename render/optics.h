#pragma once
// The lens model of image quality of `rovo render --optics` (datasets/FORMAT.md, section "Optics",
// states every rule exactly). It works on the scene-referred linear image of one camera (3 floats per
// pixel, ShadeSettings::linear_output) before the sensor model (render/sensor.h), so that exposure and
// noise see its effects. With theta the angle of a pixel's bearing from the optical axis, theta_max half
// the camera's field of view and u = theta / theta_max, in this order:
//
//   blur       a Gaussian point-spread function of standard deviation (pixels)
//                sigma(theta) = sqrt(ln 2 / 2) / (pi * m_c * f50(theta)),
//                f50(theta)   = f50_centre + (f50_rim - f50_centre) * u^2,
//              the Gaussian whose MTF exp(-2 pi^2 sigma^2 f^2) is 1/2 at f50 (cycles per pixel, the MTF50
//              of lens datasheets); m_c the camera's seeded MTF50 factor (lens-to-lens spread). Applied as
//              two 1-D passes (rows, then columns), each with the sigma of the output pixel (quantized to
//              1/32 pixel), normalized over the valid pixels of the kernel.
//   lateral    the red and blue planes magnified about the principal point p0 (the projection of the
//   colour     optical axis) by 1 + a_red and 1 + a_blue relative to green:
//                R'(p) = R(p0 + (p - p0) / (1 + a_red)), bilinear, where all four neighbours are valid
//   vignetting the relative illumination
//                E(theta) = cos^4(k * theta) * (1 - (1 - rim_illumination) * u^2),
//              the natural cos^4 fall-off in the lens's mapped angle k * theta (a fisheye's pupil grows
//              towards the rim, so k < 1) times the lens's further fall-off to rim_illumination at u = 1
//   glare      veiling glare: every valid pixel gains veiling_glare times the mean of its channel over
//              the valid pixels (after vignetting)
//
// The auto-exposure meter (render/render.cc) applies E(theta) to its own render, so the controller
// exposes the darkened image. Every draw is a function of (seed, camera).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "datasets/camera.h"
#include "datasets/optics_record.h"

namespace rovo {

struct OpticsSettings {
  bool enabled = false;              // false: an ideal lens (the default)
  std::string profile = "off";       // the profile the settings started from (OpticsProfile)
  double mtf50_centre = 0.0;         // MTF50 on the axis, cycles per pixel, in (0, 0.5]; 0 = no blur
  double mtf50_rim = 0.0;            // MTF50 at theta_max, cycles per pixel; 0 exactly when mtf50_centre is 0
  double mtf50_spread = 0.0;         // std. dev. of ln(per-camera MTF50 factor m_c)
  double falloff_angle_scale = 0.0;  // k of cos^4(k theta), [0, 1); k * theta_max < 90 degrees
  double rim_illumination = 1.0;     // relative illumination at theta_max besides cos^4, (0, 1]
  double lateral_ca_red = 0.0;       // red magnification - 1 relative to green, [-0.05, 0.05]
  double lateral_ca_blue = 0.0;      // blue magnification - 1, [-0.05, 0.05]
  double veiling_glare = 0.0;        // fraction of the mean image irradiance added to every pixel, [0, 1]

  bool Blur() const { return mtf50_centre > 0.0; }
  // Throws std::invalid_argument naming the command-line option of the first bad value.
  void Check() const;
};

// "off" (an ideal lens) or "realistic" (a 220-degree automotive/robotics fisheye, calibrated against
// the real frames of ../shared/data/itbt_real; render/README.md gives the sources); throws
// std::invalid_argument listing the names.
OpticsSettings OpticsProfile(const std::string& name);

// Command-line overrides on top of a profile (unset = the profile's value).
struct OpticsOverrides {
  std::optional<double> mtf50_centre, mtf50_rim, mtf50_spread, falloff_angle_scale, rim_illumination, lateral_ca_red,
      lateral_ca_blue, veiling_glare;
  bool Any() const;
};
// The profile with the overrides applied and checked; any override with profile "off" is an error.
// The result's profile is "custom" when an override changed it. Throws std::invalid_argument.
OpticsSettings MakeOpticsSettings(const std::string& profile, const OpticsOverrides& overrides);

// sqrt(ln 2 / 2) / (pi * mtf50): the Gaussian sigma (pixels) whose MTF is 1/2 at mtf50 (cycles/pixel).
double GaussianSigmaFromMtf50(double mtf50);
// E(theta) of the header comment.
double LensRelativeIllumination(const OpticsSettings& settings, double theta, double theta_max);
// The PSF sigma (pixels) at theta of a camera with MTF50 factor m_c; 0 without blur.
double PsfSigma(const OpticsSettings& settings, double mtf50_factor, double theta, double theta_max);
// m_c = exp(mtf50_spread * z_c), z_c = NormalQuantile of the low 16 bits of
// splitmix64(seed ^ splitmix64(0x0971c5 ^ c)).
std::vector<double> CameraMtf50Factors(const OpticsSettings& settings, int num_cameras, uint64_t seed);

// The lens of one camera: the per-pixel PSF sigma and relative illumination, precomputed.
class LensOptics {
 public:
  // `bearing` and `valid` per pixel of the camera's image (CameraRays).
  LensOptics(const OpticsSettings& settings, const Camera& camera, const std::vector<Eigen::Vector3f>& bearing,
             const std::vector<uint8_t>& valid, double mtf50_factor);
  // Applies blur, lateral colour, vignetting and glare to `linear` (3 floats per pixel), in place,
  // parallel over rows in the calling task arena. Invalid pixels stay as they are.
  void Apply(std::vector<float>* linear) const;
  // E(theta) per pixel (0 for invalid pixels) and the PSF sigma per pixel.
  const std::vector<float>& illumination() const { return illumination_; }
  const Eigen::Vector2d& principal_point() const { return principal_point_; }

 private:
  void Blur(std::vector<float>* linear) const;
  void LateralColour(std::vector<float>* linear) const;
  void VignettingAndGlare(std::vector<float>* linear) const;

  OpticsSettings settings_;
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> valid_;
  std::vector<float> illumination_;
  std::vector<uint16_t> sigma_index_;        // sigma quantized to 1/kSigmaSteps pixel
  std::vector<std::vector<float>> kernels_;  // half kernels w[0..R] by sigma index (built for the used ones)
  Eigen::Vector2d principal_point_ = Eigen::Vector2d::Zero();
};

// The dataset.json record of a render with these settings (datasets/FORMAT.md).
OpticsRecord MakeOpticsRecord(const OpticsSettings& settings, const std::vector<double>& camera_mtf50_factor);

}  // namespace rovo
