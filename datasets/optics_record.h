#pragma once
// dataset.json "optics": the lens model of image quality a render used (render/optics.h; the rules
// are in datasets/FORMAT.md, section "Optics"). Absent when the lens is ideal (the default rendering).

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace rovo {

class JsonChecker;

struct OpticsRecord {
  std::string profile;                      // "realistic", or "custom" when options changed the profile
  double mtf50_centre = 0.0;                // MTF50 on the optical axis, cycles per pixel (0: no blur)
  double mtf50_rim = 0.0;                   // MTF50 at the edge of the field of view, cycles per pixel
  double mtf50_spread = 0.0;                // std. dev. of ln(per-camera MTF50 factor), seeded
  std::vector<double> camera_mtf50_factor;  // m_c, one per rig camera
  double falloff_angle_scale = 0.0;         // k of the natural fall-off cos^4(k theta) (0: none)
  double rim_illumination = 1.0;            // relative illumination at the edge of the field of view, (0, 1]
  double lateral_ca_red = 0.0;              // magnification of the red plane relative to green, minus 1
  double lateral_ca_blue = 0.0;             // of the blue plane
  double veiling_glare = 0.0;               // fraction of the mean image irradiance added to every pixel
  bool operator==(const OpticsRecord& other) const;
  bool operator!=(const OpticsRecord& other) const { return !(*this == other); }
};

// The relative illumination E at `theta` radians off the axis of a lens whose field reaches
// theta_max: cos^4(k theta) (1 - (1 - rim_illumination) u^2), u = theta / theta_max (FORMAT.md,
// section Optics, step 3). The renderer darkens by it (render/optics.h), the VO divides by it (vo/flat_field.h).
double RelativeIlluminationAt(double falloff_angle_scale, double rim_illumination, double theta, double theta_max);

// /optics: every field present, typed and in range; problems recorded in `check`.
OpticsRecord ParseOpticsRecord(JsonChecker& check, const nlohmann::json& oj, const std::string& pointer,
                               int num_cameras);
nlohmann::json OpticsRecordJson(const OpticsRecord& record);

}  // namespace rovo
