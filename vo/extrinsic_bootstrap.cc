#include "vo/extrinsic_bootstrap.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "vo/local_ba.h"
#include "vo/triangulation.h"

namespace rovo {
namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

ExtrinsicBootstrapReport CalibrateExtrinsicsFromFrame(const FrontendFrame& frame,
                                                      const std::vector<Rigid3>& cam_from_rig,
                                                      const std::vector<double>& baseline_lengths,
                                                      const ExtrinsicBootstrapOptions& options) {
  ExtrinsicBootstrapReport report;
  report.cam_from_rig = cam_from_rig;
  const int num_cams = static_cast<int>(cam_from_rig.size());
  if (num_cams < 2 || static_cast<int>(frame.features_per_camera.size()) != num_cams) return report;

  // Tracks seen by >= 2 cameras at this frame (ordered by id: deterministic).
  std::map<uint64_t, std::vector<const Feature*>> shared;
  for (const auto& features : frame.features_per_camera) {
    for (const Feature& f : features) shared[f.track_id].push_back(&f);
  }
  std::vector<Rigid3> rig_from_cam;
  for (const Rigid3& c : cam_from_rig) rig_from_cam.push_back(c.Inverse());

  LocalBaProblem problem;
  problem.rig_from_world = {Rigid3::Identity()};  // world = rig at this frame
  problem.cam_from_rig = cam_from_rig;
  problem.baseline_lengths = baseline_lengths;
  std::vector<std::vector<int>> cameras_of_point;
  TriangulationOptions topt;
  topt.min_parallax_deg = options.min_parallax_deg;
  topt.max_error_deg = options.max_error_deg;
  topt.max_distance = 5.0 * options.far_distance_m;
  std::vector<double> errors_before;
  for (const auto& [id, features] : shared) {
    if (features.size() < 2) continue;
    std::vector<Ray> rays;
    std::vector<int> cams;
    std::vector<const Feature*> used;  // one feature per camera
    for (const Feature* f : features) {
      if (std::find(cams.begin(), cams.end(), f->camera) != cams.end()) continue;
      cams.push_back(f->camera);
      used.push_back(f);
      rays.push_back({rig_from_cam[f->camera].translation, rig_from_cam[f->camera].rotation * f->bearing_in_cam});
    }
    if (rays.size() < 2) continue;
    Eigen::Vector3d point;
    if (const auto tri = TriangulateRays(rays, topt)) {
      point = tri->point_in_world;
    } else {
      // Near-parallel rays that agree within the uncertainty: a far point.
      Eigen::Vector3d mean_dir = Eigen::Vector3d::Zero(), mean_origin = Eigen::Vector3d::Zero();
      for (const Ray& r : rays) {
        mean_dir += r.direction_in_world;
        mean_origin += r.origin_in_world;
      }
      mean_dir.normalize();
      mean_origin /= static_cast<double>(rays.size());
      bool agree = true;
      for (const Ray& r : rays)
        agree &= AngleBetween(r.direction_in_world, mean_dir) * 180.0 / M_PI <= 0.5 * options.max_error_deg;
      if (!agree) continue;
      double parallax = 0.0;
      for (size_t a = 0; a < rays.size(); ++a) {
        for (size_t b = a + 1; b < rays.size(); ++b) {
          parallax = std::max(parallax, AngleBetween(rays[a].direction_in_world, rays[b].direction_in_world));
        }
      }
      if (parallax * 180.0 / M_PI > options.min_parallax_deg) continue;  // converging but inconsistent: an outlier
      point = mean_origin + options.far_distance_m * mean_dir;
    }
    const int point_index = static_cast<int>(problem.points_in_world.size());
    problem.points_in_world.push_back(point);
    problem.point_num_cameras.push_back(static_cast<int>(cams.size()));
    cameras_of_point.push_back(cams);
    for (const Feature* f : used) {
      problem.observations.push_back({0, f->camera, point_index, f->bearing_in_cam});
      errors_before.push_back(AngleBetween(f->bearing_in_cam, cam_from_rig[f->camera] * point) * 180.0 / M_PI);
    }
  }
  report.num_points = static_cast<int>(problem.points_in_world.size());
  report.num_observations = static_cast<int>(problem.observations.size());
  report.median_error_deg_before = Median(errors_before);
  int fewest = report.num_points;
  for (int j = 0; j < num_cams && num_cams > 2; ++j) {
    const int k = (j + 1) % num_cams;
    int n = 0;
    for (const auto& cams : cameras_of_point) {
      n += std::count(cams.begin(), cams.end(), j) && std::count(cams.begin(), cams.end(), k);
    }
    fewest = std::min(fewest, n);
  }
  report.points_per_pair_min = fewest;
  if (report.num_points < 10) return report;

  LocalBaOptions ba;
  ba.optimize_extrinsics = true;
  ba.max_iterations = options.max_iterations;
  ba.baseline_weight = options.baseline_weight;
  ba.multi_camera_weight = options.multi_camera_weight;
  // Cauchy scale on the chord: a third of the current uncertainty, at least the nominal 0.3 deg.
  ba.cauchy_scale_rad = std::max(0.005, options.max_error_deg * M_PI / 180.0 / 3.0);
  const LocalBaReport ba_report = SolveLocalBa(problem, ba);
  if (!ba_report.usable) return report;
  std::vector<double> errors_after;
  for (const LocalBaObservation& o : problem.observations) {
    errors_after.push_back(
        AngleBetween(o.bearing_in_cam, problem.cam_from_rig[o.camera] * problem.points_in_world[o.point_index]) *
        180.0 / M_PI);
  }
  report.median_error_deg_after = Median(errors_after);
  for (int j = 0; j < num_cams; ++j) {
    report.max_change_deg = std::max(report.max_change_deg,
                                     RotationDistanceDeg(problem.cam_from_rig[j].rotation, cam_from_rig[j].rotation));
  }
  report.cam_from_rig = problem.cam_from_rig;
  report.usable = true;
  return report;
}

}  // namespace rovo
