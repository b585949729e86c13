// Street scenes' lighting: the sun and sky of each lighting preset, and the street lamps at night.

#include <cmath>
#include <stdexcept>
#include <string>

#include "scenes/city_internal.h"

namespace rovo::city_internal {

Lighting MakeLighting(const std::string& preset, uint64_t seed, bool high_sun_along_streets) {
  SceneRng rng(SubSeed(seed, "lighting"));
  Lighting l;
  l.preset = preset;
  double elevation_deg = 60, azimuth_deg = rng.Uniform(0, 360);
  if (preset == "sunny") {
    elevation_deg = rng.Uniform(50, 65);
    if (high_sun_along_streets) {
      elevation_deg = rng.Uniform(68, 76);
      azimuth_deg = rng.UniformInt(0, 3) * 90.0 + rng.Uniform(15, 25);
    }
    l.sun_radiance = {3.0f, 2.9f, 2.7f};
    l.sun_angular_diameter_deg = 0.53;
    l.sky_zenith = {0.25f, 0.45f, 0.9f};
    l.sky_horizon = {0.7f, 0.8f, 0.95f};
    l.ambient = 0.35f;
    l.exposure = 1.0f;
  } else if (preset == "cloudy") {
    elevation_deg = rng.Uniform(35, 55);
    l.sun_radiance = {0.3f, 0.3f, 0.32f};
    l.sun_angular_diameter_deg = 30.0;  // a bright patch in the overcast, no crisp shadows
    l.sky_zenith = {0.78f, 0.8f, 0.84f};
    l.sky_horizon = {0.86f, 0.87f, 0.9f};
    l.ambient = 0.95f;
    l.exposure = 1.25f;
  } else if (preset == "sunset") {
    elevation_deg = rng.Uniform(6, 10);
    // 25-35 degrees off the street axes: long shadows across the streets, sun not straight down them.
    azimuth_deg = rng.UniformInt(0, 3) * 90.0 + rng.Uniform(25, 35);
    l.sun_radiance = {2.6f, 1.45f, 0.65f};
    l.sun_angular_diameter_deg = 0.53;
    l.sky_zenith = {0.28f, 0.33f, 0.6f};
    l.sky_horizon = {0.95f, 0.62f, 0.38f};
    l.ground_albedo = {0.3f, 0.25f, 0.22f};
    l.ambient = 0.3f;
    l.exposure = 1.3f;
  } else if (preset == "night") {
    // Moonless, light-polluted night: no sun, a dark blue zenith and an orange glow at the horizon;
    // the street lamps and headlights (scene lights) do the rest. Radiances are on the day presets'
    // scale (sun irradiance 3), so the exposure is 1000 times a day preset's: a real camera
    // needs a long exposure and high gain.
    elevation_deg = -20.0;
    l.sun_radiance = {0.0f, 0.0f, 0.0f};
    l.sky_zenith = {0.6e-5f, 0.8e-5f, 1.8e-5f};
    l.sky_horizon = {2.6e-5f, 2.0e-5f, 1.4e-5f};
    l.ground_albedo = {0.2f, 0.2f, 0.2f};
    l.ambient = 1.0f;
    l.exposure = 1000.0f;
  } else {
    throw std::invalid_argument("unknown lighting preset '" + preset + "' (valid: sunny, cloudy, sunset, night)");
  }
  const double el = elevation_deg * M_PI / 180, az = azimuth_deg * M_PI / 180;
  l.direction_to_sun = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  return l;
}

void LightStreetLamps(Scene& scene, int mesh_light, int m_lamp) {
  scene.materials[m_lamp].emission = {5.0f, 4.4f, 3.4f};  // warm white
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    if (scene.objects[o].mesh != mesh_light) continue;
    Light l;
    l.name = scene.objects[o].name + "_lamp";
    l.position = Eigen::Vector3d(1.6, 0.0, 6.1);           // in the street light's frame (AddStreetLightMesh)
    l.intensity = Eigen::Vector3f(0.035f, 0.03f, 0.024f);  // about 25 lux below on the day scale
    l.range = 30.0;
    l.object = static_cast<int>(o);
    // A full cut-off luminaire: light goes down (A = cos of the angle off the axis, none above
    // 75 degrees), so the road is lit in pools and the facades stay dark.
    l.spot = true;
    l.spot_direction = Eigen::Vector3d(0.0, 0.0, -1.0);
    l.spot_angle_deg = 150.0;
    l.spot_blend = 0.3;
    scene.lights.push_back(l);
  }
}

}  // namespace rovo::city_internal
