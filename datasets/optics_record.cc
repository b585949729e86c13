#include "datasets/optics_record.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "datasets/json_check.h"

namespace rovo {

double RelativeIlluminationAt(double falloff_angle_scale, double rim_illumination, double theta, double theta_max) {
  const double u = theta / theta_max;
  const double c = std::cos(falloff_angle_scale * theta);
  return c * c * c * c * (1.0 - (1.0 - rim_illumination) * u * u);
}
using nlohmann::json;

OpticsRecord ParseOpticsRecord(JsonChecker& check, const json& oj, const std::string& p, int num_cameras) {
  OpticsRecord o;
  if (!check.Object(oj, p)) return o;
  o.profile = check.String(oj, p, "profile", true);
  o.mtf50_centre = check.Number(oj, p, "mtf50_centre", 0.0, 0.0, 1.0);
  o.mtf50_rim = check.Number(oj, p, "mtf50_rim", 0.0, 0.0, 1.0);
  if ((o.mtf50_centre > 0.0) != (o.mtf50_rim > 0.0))
    check.Issue(p + "/mtf50_rim", "must be 0 exactly when mtf50_centre is 0 (no blur)");
  o.mtf50_spread = check.Number(oj, p, "mtf50_spread", 0.0, 0.0, 1.0);
  o.camera_mtf50_factor = check.Numbers(oj, p, "camera_mtf50_factor", num_cameras);
  for (size_t c = 0; c < o.camera_mtf50_factor.size(); ++c) {
    if (!(o.camera_mtf50_factor[c] > 0.0)) check.Issue(p + "/camera_mtf50_factor/" + std::to_string(c), "must be > 0");
  }
  o.falloff_angle_scale = check.Number(oj, p, "falloff_angle_scale", 0.0, 0.0, 1.0);
  o.rim_illumination = check.Number(oj, p, "rim_illumination", 1.0, 0.0, 1.0, /*lo_open=*/true);
  o.lateral_ca_red = check.Number(oj, p, "lateral_ca_red", 0.0, -0.05, 0.05);
  o.lateral_ca_blue = check.Number(oj, p, "lateral_ca_blue", 0.0, -0.05, 0.05);
  o.veiling_glare = check.Number(oj, p, "veiling_glare", 0.0, 0.0, 1.0);
  return o;
}

json OpticsRecordJson(const OpticsRecord& o) {
  return json{{"profile", o.profile},
              {"mtf50_centre", o.mtf50_centre},
              {"mtf50_rim", o.mtf50_rim},
              {"mtf50_spread", o.mtf50_spread},
              {"camera_mtf50_factor", o.camera_mtf50_factor},
              {"falloff_angle_scale", o.falloff_angle_scale},
              {"rim_illumination", o.rim_illumination},
              {"lateral_ca_red", o.lateral_ca_red},
              {"lateral_ca_blue", o.lateral_ca_blue},
              {"veiling_glare", o.veiling_glare}};
}

bool OpticsRecord::operator==(const OpticsRecord& o) const { return OpticsRecordJson(*this) == OpticsRecordJson(o); }

}  // namespace rovo
