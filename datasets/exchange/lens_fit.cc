#include "datasets/exchange/lens_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <map>
#include <stdexcept>
#include <unsupported/Eigen/AutoDiff>

#include "datasets/camera_models.h"

namespace rovo {
namespace {

constexpr int kMaxParams = 9;
constexpr double kAngleStepDeg = 0.5;
constexpr double kAzimuthStepDeg = 5.0;
// Residual of a grid bearing the model cannot project (pushes the solver back into the valid set).
constexpr double kInvalidResidualPx = 1000.0;

using Ad = Eigen::AutoDiffScalar<Eigen::Matrix<double, kMaxParams, 1>>;

template <typename T>
bool ProjectT(ExchangeLensModel model, const T* params, const T* point, T* uv) {
  switch (model) {
#define ROVO_EXCHANGE_LENS_PROJECT(id, name, model_struct, camera_model) \
  case ExchangeLensModel::id:                                            \
    return model_struct::ImgFromCam(params, model_struct::kNumParams, point, uv);
    ROVO_EXCHANGE_LENS_MODELS(ROVO_EXCHANGE_LENS_PROJECT)
#undef ROVO_EXCHANGE_LENS_PROJECT
  }
  return false;
}

struct Sample {
  Eigen::Vector3d bearing;
  Eigen::Vector2d uv;  // the source camera's pixel
  double angle_deg = 0.0;
};

// Turn of the image axes by an ocam affine A = [c d; e 1]: the angle of the rotation closest to A,
// atan2(A21 - A12, A11 + A22). Zero for other models.
double AffineRollDeg(const Camera& camera) {
  if (camera.model != CameraModelId::kOcam || camera.params.size() < 5) return 0.0;
  const double c = camera.params[2], d = camera.params[3], e = camera.params[4];
  return std::atan2(e - d, c + 1.0) / kDegToRad;
}

// Grid bearings (angle from the axis, azimuth) that the source camera projects into its image,
// expressed in the exported frame (turned by roll_deg about the optical axis).
std::vector<Sample> SampleLens(const Camera& camera, double roll_deg) {
  const Eigen::Matrix3d exported_from_cam = Eigen::AngleAxisd(roll_deg * kDegToRad, Eigen::Vector3d::UnitZ()).matrix();
  std::vector<Sample> samples;
  const double half_fov_deg = 0.5 * camera.max_fov_deg;
  for (double angle = 0.0; angle <= half_fov_deg + 1e-9; angle += kAngleStepDeg) {
    for (double azimuth = 0.0; azimuth < 360.0; azimuth += kAzimuthStepDeg) {
      const double a = std::min(angle, half_fov_deg) * kDegToRad, b = azimuth * kDegToRad;
      const Eigen::Vector3d bearing(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a));
      const std::optional<Eigen::Vector2d> uv = camera.Project(bearing);
      if (uv && camera.InImage(*uv)) {
        samples.push_back({exported_from_cam * bearing, *uv, std::min(angle, half_fov_deg)});
      }
      if (angle == 0.0) break;
    }
  }
  return samples;
}

// Source pixel of a bearing at `angle_deg` from the axis along azimuth 0 (x) or 90 (y).
Eigen::Vector2d SourcePixel(const Camera& camera, double angle_deg, bool along_y) {
  const double a = angle_deg * kDegToRad;
  const Eigen::Vector3d bearing = along_y ? Eigen::Vector3d(0, std::sin(a), std::cos(a))
                                          : Eigen::Vector3d(std::sin(a), 0, std::cos(a));  // roll is small
  const std::optional<Eigen::Vector2d> uv = camera.Project(bearing);
  if (!uv) throw std::invalid_argument("lens fit: the camera cannot project a bearing near its axis");
  return *uv;
}

// Starting points: principal point and focal length from the source lens near its axis.
std::vector<std::vector<double>> InitialGuesses(const Camera& camera, ExchangeLensModel model) {
  const Eigen::Vector2d centre = SourcePixel(camera, 0.0, false);
  const double small = 0.5;
  const double fx = (SourcePixel(camera, small, false) - centre).norm() / std::tan(small * kDegToRad);
  const double fy = (SourcePixel(camera, small, true) - centre).norm() / std::tan(small * kDegToRad);
  const double cx = centre.x(), cy = centre.y();
  switch (model) {
    case ExchangeLensModel::kDoubleSphere: {  // on the axis u = fx x / ((1 + xi) z)
      std::vector<std::vector<double>> out;
      for (double xi : {-0.1, -0.25}) out.push_back({fx * (1 + xi), fy * (1 + xi), cx, cy, xi, 0.6});
      return out;
    }
    case ExchangeLensModel::kExtendedUnified:
      return {{fx, fy, cx, cy, 0.6, 1.0}, {fx, fy, cx, cy, 0.65, 0.9}};
    case ExchangeLensModel::kKannalaBrandt4:
      return {{fx, fy, cx, cy, 0, 0, 0, 0}};
    case ExchangeLensModel::kOmniRadtan: {  // on the axis u = fx x / ((1 + xi) z)
      std::vector<std::vector<double>> out;
      for (double xi : {1.2, 2.0}) out.push_back({fx * (1 + xi), fy * (1 + xi), cx, cy, xi, 0, 0, 0, 0});
      return out;
    }
  }
  return {};
}

// Residuals (2 per sample) and, when `jacobian` is given, their derivatives by the parameters.
double Evaluate(ExchangeLensModel model, const std::vector<double>& params, const std::vector<Sample>& samples,
                Eigen::VectorXd* residuals, Eigen::MatrixXd* jacobian) {
  const int n = static_cast<int>(params.size());
  const int m = static_cast<int>(samples.size());
  residuals->resize(2 * m);
  if (jacobian) jacobian->setZero(2 * m, n);
  Ad ad_params[kMaxParams];
  for (int i = 0; i < n; ++i) ad_params[i] = Ad(params[i], kMaxParams, i);
  for (int k = 0; k < m; ++k) {
    const Ad point[3] = {Ad(samples[k].bearing.x()), Ad(samples[k].bearing.y()), Ad(samples[k].bearing.z())};
    Ad uv[2];
    if (!ProjectT(model, ad_params, point, uv) || !std::isfinite(uv[0].value()) || !std::isfinite(uv[1].value())) {
      residuals->segment<2>(2 * k).setConstant(kInvalidResidualPx);
      continue;
    }
    for (int r = 0; r < 2; ++r) {
      (*residuals)(2 * k + r) = uv[r].value() - samples[k].uv(r);
      if (jacobian && uv[r].derivatives().size() == kMaxParams) {
        jacobian->row(2 * k + r) = uv[r].derivatives().head(n).transpose();
      }
    }
  }
  return residuals->squaredNorm();
}

// Levenberg-Marquardt with Marquardt's diagonal scaling.
std::vector<double> Minimise(ExchangeLensModel model, std::vector<double> params, const std::vector<Sample>& samples,
                             double* final_cost) {
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;
  double cost = Evaluate(model, params, samples, &residuals, &jacobian);
  double lambda = 1e-3;
  const int n = static_cast<int>(params.size());
  for (int iteration = 0; iteration < 500 && lambda < 1e16; ++iteration) {
    const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
    const Eigen::VectorXd jtr = jacobian.transpose() * residuals;
    Eigen::MatrixXd damped = jtj;
    damped.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-12);
    const Eigen::VectorXd step = damped.colPivHouseholderQr().solve(-jtr);
    std::vector<double> candidate = params;
    for (int i = 0; i < n; ++i) candidate[i] += step(i);
    Eigen::VectorXd candidate_residuals;
    const double candidate_cost = Evaluate(model, candidate, samples, &candidate_residuals, nullptr);
    if (candidate_cost < cost) {
      const double gain = cost - candidate_cost;
      params = candidate;
      cost = Evaluate(model, params, samples, &residuals, &jacobian);
      lambda = std::max(lambda * 0.2, 1e-12);
      if (gain < 1e-14 * cost) break;
    } else {
      lambda *= 10.0;
    }
  }
  *final_cost = cost;
  return params;
}

// Max, RMS and the 0.5-px angle of `params` over the samples.
void MeasureFit(const std::vector<Sample>& samples, LensFit* fit) {
  std::map<double, double> ring_max;  // angle -> largest error on that ring
  double sum2 = 0.0;
  fit->max_error_px = 0.0;
  for (const Sample& s : samples) {
    Eigen::Vector2d uv;
    double error = std::numeric_limits<double>::infinity();
    if (ProjectExchangeLens(fit->model, fit->params, s.bearing, &uv)) error = (uv - s.uv).norm();
    fit->max_error_px = std::max(fit->max_error_px, error);
    sum2 += error * error;
    double& ring = ring_max[s.angle_deg];
    ring = std::max(ring, error);
    fit->max_angle_deg = std::max(fit->max_angle_deg, s.angle_deg);
  }
  fit->rms_error_px = std::sqrt(sum2 / static_cast<double>(samples.size()));
  fit->half_px_angle_deg = 0.0;
  for (const auto& [angle, error] : ring_max) {
    if (!(error < 0.5)) break;
    fit->half_px_angle_deg = angle;
  }
  fit->num_samples = static_cast<int>(samples.size());
}

bool SameKind(CameraModelId source, ExchangeLensModel model) { return ExchangeLensCameraModel(model) == source; }

constexpr ExchangeLensModel kExchangeLensModels[] = {
#define ROVO_EXCHANGE_LENS_ID(id, name, model_struct, camera_model) ExchangeLensModel::id,
    ROVO_EXCHANGE_LENS_MODELS(ROVO_EXCHANGE_LENS_ID)
#undef ROVO_EXCHANGE_LENS_ID
};

}  // namespace

std::string ExchangeLensModelName(ExchangeLensModel model) {
  switch (model) {
#define ROVO_EXCHANGE_LENS_NAME(id, name, model_struct, camera_model) \
  case ExchangeLensModel::id:                                         \
    return name;
    ROVO_EXCHANGE_LENS_MODELS(ROVO_EXCHANGE_LENS_NAME)
#undef ROVO_EXCHANGE_LENS_NAME
  }
  return "?";
}

ExchangeLensModel ExchangeLensModelFromName(const std::string& name) {
  std::string known;
  for (ExchangeLensModel m : kExchangeLensModels) {
    if (ExchangeLensModelName(m) == name) return m;
    known += (known.empty() ? "" : ", ") + ExchangeLensModelName(m);
  }
  throw std::invalid_argument("unknown lens model '" + name + "' (known: " + known + ")");
}

int ExchangeLensNumParams(ExchangeLensModel model) {
  switch (model) {
#define ROVO_EXCHANGE_LENS_NUM_PARAMS(id, name, model_struct, camera_model) \
  case ExchangeLensModel::id:                                               \
    return model_struct::kNumParams;
    ROVO_EXCHANGE_LENS_MODELS(ROVO_EXCHANGE_LENS_NUM_PARAMS)
#undef ROVO_EXCHANGE_LENS_NUM_PARAMS
  }
  return 0;
}

std::optional<CameraModelId> ExchangeLensCameraModel(ExchangeLensModel model) {
  switch (model) {
#define ROVO_EXCHANGE_LENS_CAMERA_MODEL(id, name, model_struct, camera_model) \
  case ExchangeLensModel::id:                                                 \
    return camera_model;
    ROVO_EXCHANGE_LENS_MODELS(ROVO_EXCHANGE_LENS_CAMERA_MODEL)
#undef ROVO_EXCHANGE_LENS_CAMERA_MODEL
  }
  return std::nullopt;
}

bool ProjectExchangeLens(ExchangeLensModel model, const std::vector<double>& params,
                         const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* uv) {
  if (static_cast<int>(params.size()) != ExchangeLensNumParams(model)) return false;
  return ProjectT(model, params.data(), point_in_cam.data(), uv->data()) && uv->allFinite();
}

LensFit FitExchangeLens(const Camera& camera, ExchangeLensModel model) {
  LensFit fit;
  fit.model = model;
  fit.roll_deg = AffineRollDeg(camera);
  const std::vector<Sample> samples = SampleLens(camera, fit.roll_deg);
  if (samples.size() < 20) throw std::invalid_argument("lens fit: the camera projects too few bearings into its image");
  if (SameKind(camera.model, model)) {
    fit.params = camera.params;
    fit.exact = true;
  } else {
    double best_cost = std::numeric_limits<double>::infinity();
    for (const std::vector<double>& start : InitialGuesses(camera, model)) {
      double cost = 0.0;
      std::vector<double> params = Minimise(model, start, samples, &cost);
      if (cost < best_cost) {
        best_cost = cost;
        fit.params = params;
      }
    }
  }
  MeasureFit(samples, &fit);
  if (model != ExchangeLensModel::kOmniRadtan) {
    CameraFromExchangeLens(model, fit.params, camera.width, camera.height, camera.max_fov_deg,
                           "fitted " + ExchangeLensModelName(model) + " lens")
        .Check("fitted " + ExchangeLensModelName(model) + " lens");
  }
  return fit;
}

Camera CameraFromExchangeLens(ExchangeLensModel model, const std::vector<double>& params, int width, int height,
                              double max_fov_deg, const std::string& what) {
  Camera camera;
  camera.width = width;
  camera.height = height;
  camera.params = params;
  camera.max_fov_deg = max_fov_deg;
  const std::optional<CameraModelId> camera_model = ExchangeLensCameraModel(model);
  if (!camera_model)
    throw std::invalid_argument(what +
                                ": the omni (unified + radtan) lens has no rovo camera model; export "
                                "with ds or eucm to exchange it both ways");
  camera.model = *camera_model;
  return camera;
}

}  // namespace rovo
