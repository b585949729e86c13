// The OmniMVS file conventions as rig cameras, and the `rovo4_real` preset (omnimvs_rig.h).
#include "datasets/omnimvs_rig.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "datasets/ocam.h"

namespace rovo {
namespace {

// The ITBT rig's OmniMVS config.yaml, cameras 1..4 (rovo4_real).
const OmniMvsCamera kItbtCameras[4] = {
    {{-392.21983020642324, 0.0, 0.0012707685299884767, -1.7456026867522776E-6, 2.257655719602505E-9},
     {611.433, 386.965, -15.0504, -65.1466, -119.568, 27.7131, 355.781, 206.82, -667.654, -1290.67, -985.814, -361.63,
      -52.6566},
     756.215,
     811.661,
     {0.999876, -2.91382E-4, -1.66556E-4},
     1532,
     1600,
     {0.05287133304667693, 0.7411561834637101, 0.02981358273057615, 0.1485451015397448, -6.40692965168468E-5,
      0.14722476953097846},
     220.0},
    {{-393.2636335626606, 0.0, 0.0013030161088532755, -1.8689651365463267E-6, 2.3792432009042225E-9},
     {611.562, 383.54, -22.3448, -47.6112, -41.6246, 10.0601, -37.4865, -278.722, -487.074, -433.682, -222.271,
      -63.4335, -7.90549},
     793.1,
     817.845,
     {1.00028, -0.032979, 0.0327437},
     1532,
     1600,
     {-0.01748403647284513, 2.3597683150646245, -0.051198752155718716, 0.14783151534302344, 6.437518511735495E-5,
      -0.14432158757883862},
     220.0},
    {{-397.8543380457763, 0.0, 0.0014956852335708303, -2.272212930459553E-6, 2.6072875869332744E-9},
     {607.095, 381.297, -21.3511, -43.0875, -56.1323, -71.1995, -22.3406, 318.49, 865.72, 1041.49, 665.323, 220.271,
      29.8479},
     769.23,
     809.789,
     {1.00032, -0.00668755, 0.00648385},
     1532,
     1600,
     {0.006337812304309649, -2.4506787246407957, -0.02780629345273642, -0.14783151534302352, -6.297664270220886E-5,
      -0.15046281430153374},
     220.0},
    {{-392.9083750477403, 0.0, 0.0013458091464087045, -1.9466309855382977E-6, 2.4144190106312376E-9},
     {609.338, 384.453, -20.1199, -45.4585, -36.506, -26.2937, -130.633, -175.538, 77.9449, 334.117, 279.3, 99.8473,
      13.3981},
     797.373,
     819.266,
     {1.00004, -0.0140823, 0.0149072},
     1532,
     1600,
     {0.04659071698722346, -0.8132957468650718, 0.022361144111398168, -0.14854510153974484, 6.267075410156638E-5,
      0.1475596323493941},
     220.0},
};

// Forward ocam parameters [cx, cy, c, d, e, a0..a4] of a file entry; `where` names it in errors.
std::vector<double> ForwardParams(const OmniMvsCamera& cam, const std::string& where) {
  if (cam.poly.empty()) throw std::runtime_error(where + ".poly: no coefficients");
  for (size_t i = 5; i < cam.poly.size(); ++i) {
    if (cam.poly[i] != 0.0) {
      throw std::runtime_error(where + ".poly: degree above 4 is not supported (a" + std::to_string(i) + " != 0)");
    }
  }
  // OCamCalib's convention, as OmniMVS reads it: (row, col) = [c d; e 1] (x_o, y_o) + (center_row,
  // center_col), x_o along rows, and the OpenCV ray is (y_o, x_o, -poly(rho)). Our layout has x
  // along columns and v's y-coefficient 1; scaling the sensor plane by c (X = c y_o, Y = c x_o)
  // gives u = X / c + (e / c) Y + cx, v = (d / c) X + Y + cy, and the same rays with
  // a'_i = a_i c^(1 - i) (see ReadOcamCalibTxt in ocam.h for the same mapping).
  const double c = cam.affine[0], d = cam.affine[1], e = cam.affine[2];
  if (!(std::abs(c) > 1e-6) || !(std::abs(c - d * e) > 1e-9)) {
    throw std::runtime_error(where + ".affine: singular stretch matrix");
  }
  std::vector<double> params = {cam.center_col, cam.center_row, 1.0 / c, e / c, d / c};
  for (size_t i = 0; i < 5; ++i) params.push_back((i < cam.poly.size() ? cam.poly[i] : 0.0) * std::pow(c, 1.0 - i));
  return params;
}

}  // namespace

Eigen::Matrix3d RigFromOmniMvsRigRotation() {
  Eigen::Matrix3d m;
  m << 1, 0, 0,  //  x_ours = x_file (forward)
      0, 0, 1,   //  y_ours = z_file (left)
      0, -1, 0;  //  z_ours = -y_file (up; the file's y points down)
  return m;
}

std::vector<double> OcamParamsWithFittedInverse(const std::vector<double>& forward_params, double max_fov_deg,
                                                double* max_error_px) {
  const OcamInverseFit fit = FitOcamInversePolynomial(forward_params, max_fov_deg, 0.01);
  if (!(fit.max_error_px < 0.01)) {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "inverse polynomial fit reaches only %.4f px (need < 0.01 px)", fit.max_error_px);
    throw std::runtime_error(buf);
  }
  std::vector<double> params(forward_params.begin(), forward_params.begin() + 10);
  params.insert(params.end(), fit.inverse_poly.begin(), fit.inverse_poly.end());
  if (max_error_px) *max_error_px = fit.max_error_px;
  return params;
}

RigCamera OmniMvsRigCamera(const OmniMvsCamera& cam, int index, const std::string& where, std::string* report) {
  RigCamera rc;
  rc.name = "cam" + std::to_string(index);
  rc.camera.model = CameraModelId::kOcam;
  rc.camera.width = cam.width;
  rc.camera.height = cam.height;
  rc.camera.max_fov_deg = cam.max_fov_deg;
  const std::vector<double> forward = ForwardParams(cam, where);
  double fit_error_px = 0.0;
  try {
    rc.camera.params = OcamParamsWithFittedInverse(forward, cam.max_fov_deg, &fit_error_px);
  } catch (const std::exception& e) {
    throw std::runtime_error(where + ".poly: " + e.what());
  }
  if (report) {
    char line[256];
    if (cam.inv_poly.empty()) {
      std::snprintf(line, sizeof(line), "%s: refitted inverse polynomial (%zu coefficients) max error %.5f px\n",
                    rc.name.c_str(), rc.camera.params.size() - 10, fit_error_px);
    } else {
      // The file's inverse gives rho in the unscaled sensor plane: b'_i = c b_i.
      std::vector<double> with_file_inverse = forward;
      for (double b : cam.inv_poly) with_file_inverse.push_back(b * cam.affine[0]);
      const double file_error_px = OcamInverseMaxErrorPx(with_file_inverse, cam.max_fov_deg);
      std::snprintf(line, sizeof(line),
                    "%s: file inv_poly (%zu coefficients) off by up to %.3f px; refitted (%zu coefficients) max "
                    "error %.5f px\n",
                    rc.name.c_str(), cam.inv_poly.size(), file_error_px, rc.camera.params.size() - 10, fit_error_px);
    }
    *report += line;
  }
  // cam2rig in the file's frame, then the frame change to ours.
  const Eigen::Vector3d rotation_vector(cam.pose[0], cam.pose[1], cam.pose[2]);
  const Rigid3 file_rig_from_cam =
      Rigid3::FromAxisAngle(rotation_vector, Eigen::Vector3d(cam.pose[3], cam.pose[4], cam.pose[5]));
  const Rigid3 rig_from_file_rig(RigFromOmniMvsRigRotation(), Eigen::Vector3d::Zero());
  rc.cam_from_rig = (rig_from_file_rig * file_rig_from_cam).Inverse();
  return rc;
}

Rig MakeRovo4RealRig() {
  Rig rig;
  for (int i = 0; i < 4; ++i) {
    rig.cameras.push_back(
        OmniMvsRigCamera(kItbtCameras[i], i, "rovo4_real cameras[" + std::to_string(i) + "]", nullptr));
  }
  return rig;
}

}  // namespace rovo
