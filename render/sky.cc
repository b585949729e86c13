// Sun, sky and ambient light: the sun frame and disc samples, the sky a miss sees (with the sun
// disc and the aureole), and the ambient hemisphere term (formulas: render/tracer.h).
#include <algorithm>

#include "render/tracer_internal.h"

namespace rovo {
namespace tracer_internal {

void SetSkyTerms(const Tracer::Impl& d, const ShadeSettings& settings, RenderJob* job_out) {
  RenderJob& job = *job_out;
  const Lighting& light = d.scene.lighting;
  job.sky_horizon = Load3(light.sky_horizon);
  job.sky_delta = Load3(light.sky_zenith - light.sky_horizon);
  job.sky_ground = Load3(light.ground_albedo.cwiseProduct(light.sky_horizon));
  job.ambient_ground = Load3(light.ambient * d.ground_irradiance);
  job.ambient_delta = Load3(light.ambient * (d.sky_mean - d.ground_irradiance));
  job.sun_radiance = Load3(light.sun_radiance);
  job.sun_disc = settings.sun_disc && light.sun_radiance.maxCoeff() > 0.0f;
  const float sun_radius = static_cast<float>(0.5 * light.sun_angular_diameter_deg * M_PI / 180.0);
  job.sun_var = 0.25f * sun_radius * sun_radius;
  if (settings.sun_aureole && light.sun_radiance.maxCoeff() > 0.0f) {
    auto luminance = [](const Eigen::Vector3f& c) { return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z(); };
    const float sky = static_cast<float>(M_PI) * luminance(light.sky_horizon);
    job.aureole_k = 10.0f * (sky > 0.0f ? std::min(1.0f, luminance(light.sun_radiance) / sky) : 1.0f);
  }
}

__m128 MissRadiance(const RenderJob& job, const Eigen::Vector3f& dir, size_t pi) {
  const Tracer::Impl& d = job.d;
  // Sky: mix(horizon, zenith, sqrt(d.z)) above the horizon, ground_albedo * horizon below.
  __m128 sky = dir.z() >= 0.0f ? _mm_add_ps(job.sky_horizon, _mm_mul_ps(_mm_set1_ps(std::sqrt(dir.z())), job.sky_delta))
                               : job.sky_ground;
  if (job.aureole_k > 0.0f && dir.z() >= 0.0f) {
    // The circumsolar aureole: gamma = 2 asin(|d - s_dir| / 2).
    const float gamma = 2.0f * std::asin(std::min(1.0f, 0.5f * (dir - d.sun_dir).norm()));
    sky = _mm_mul_ps(sky, _mm_set1_ps(1.0f + job.aureole_k * std::exp(-3.0f * gamma)));
  }
  if (job.sun_disc) {
    // The HDR sun through the pixel footprint (render/tracer.h): E_sun exp(-c2 / 2s2) / (2 pi s2).
    const float c2 = (dir - d.sun_dir).squaredNorm();
    const float f = 0.5f * job.rays.pixel_angle[pi];
    const float s2 = job.sun_var + f * f;
    if (c2 < 50.0f * s2)
      sky = _mm_add_ps(sky,
                       _mm_mul_ps(job.sun_radiance, _mm_set1_ps(std::exp(-c2 / (2.0f * s2)) * (0.5f * kInvPi) / s2)));
  }
  return sky;
}

}  // namespace tracer_internal

using tracer_internal::kInvPi;
using tracer_internal::kSunSamples;
using tracer_internal::RadicalInverse2;
using tracer_internal::Sobol2;

// Lighting constants: sun frame and disc samples, sky mean, ground irradiance.
void Tracer::Impl::SetUpLighting() {
  const Lighting& light = scene.lighting;
  const Eigen::Vector3d s =
      light.direction_to_sun.norm() > 0 ? light.direction_to_sun.normalized() : Eigen::Vector3d::UnitZ();
  sun_dir = s.cast<float>();
  const Eigen::Vector3f helper = std::abs(sun_dir.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  sun_e1 = sun_dir.cross(helper).normalized();
  sun_e2 = sun_dir.cross(sun_e1);
  sun_disc_radius = static_cast<float>(std::tan(0.5 * light.sun_angular_diameter_deg * M_PI / 180.0));
  sky_mean = 0.5f * (light.sky_zenith + light.sky_horizon);
  ground_irradiance =
      light.ground_albedo.cwiseProduct(light.sun_radiance * std::max(0.0f, sun_dir.z()) * kInvPi + sky_mean);
  // Sun-disc directions: point i of the (0,2)-sequence (radinv2(i), sobol2(i)) mapped to the disc
  // of radius tan(diameter / 2) around sun_dir (uniform in area).
  for (int i = 0; i < kSunSamples; ++i) {
    const float radius = sun_disc_radius * std::sqrt(RadicalInverse2(static_cast<uint32_t>(i)));
    const float phi = 6.2831853f * Sobol2(static_cast<uint32_t>(i));
    sun_samples[i] = (sun_dir + radius * (std::cos(phi) * sun_e1 + std::sin(phi) * sun_e2)).normalized();
  }
  sun_on = light.sun_radiance.maxCoeff() > 0.0f;
  SetUpLights();
}

}  // namespace rovo
