#include "vo/p3p.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <optional>

namespace rovo {
namespace {

// Adjugate of a 3x3 matrix: rows are the cross products of the columns, adj(A) * A = det(A) I.
Eigen::Matrix3d Adjugate(const Eigen::Matrix3d& a) {
  Eigen::Matrix3d adj;
  adj.row(0) = a.col(1).cross(a.col(2)).transpose();
  adj.row(1) = a.col(2).cross(a.col(0)).transpose();
  adj.row(2) = a.col(0).cross(a.col(1)).transpose();
  return adj;
}

// One real root of x^3 + a x^2 + b x + c (Cardano / trigonometric form), polished by Newton.
double RealCubicRoot(double a, double b, double c) {
  const double p = b - a * a / 3.0;
  const double q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
  const double disc = q * q / 4.0 + p * p * p / 27.0;
  double t;
  if (disc >= 0.0) {
    const double sq = std::sqrt(disc);
    t = std::cbrt(-q / 2.0 + sq) + std::cbrt(-q / 2.0 - sq);
  } else {  // three real roots, p < 0: take the largest
    const double m = 2.0 * std::sqrt(-p / 3.0);
    const double arg = std::clamp(3.0 * q / (p * m), -1.0, 1.0);
    t = m * std::cos(std::acos(arg) / 3.0);
  }
  double x = t - a / 3.0;
  for (int it = 0; it < 4; ++it) {
    const double f = ((x + a) * x + b) * x + c;
    const double df = (3.0 * x + 2.0 * a) * x + b;
    if (df == 0.0) break;
    x -= f / df;
  }
  return x;
}

// Symmetric matrix of the form lambda_i^2 + lambda_j^2 + b lambda_i lambda_j.
Eigen::Matrix3d PairForm(int i, int j, double b) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(i, i) = 1.0;
  m(j, j) = 1.0;
  m(i, j) = m(j, i) = 0.5 * b;
  return m;
}

// The three distance equations |lambda_i y_i - lambda_j y_j|^2 = a_ij as quadratic forms in lambda:
// lambda^T m_ij lambda = a_ij with b_ij = -2 y_i . y_j.
struct P3PEquations {
  double b12, b13, b23, a12, a13, a23;
  Eigen::Matrix3d m12, m13, m23;

  Eigen::Vector3d Residual(const Eigen::Vector3d& l) const {
    return Eigen::Vector3d(l(0) * l(0) + l(1) * l(1) + b12 * l(0) * l(1) - a12,
                           l(0) * l(0) + l(2) * l(2) + b13 * l(0) * l(2) - a13,
                           l(1) * l(1) + l(2) * l(2) + b23 * l(1) * l(2) - a23);
  }
};

// A degenerate member d0 of the pencil D1 + g D2 (D_k = a23 m_1k - a1k m23) and the other form;
// false when the pencil vanishes.
bool DegeneratePencilMember(const P3PEquations& e, Eigen::Matrix3d* d0, Eigen::Matrix3d* other) {
  const Eigen::Matrix3d d1 = e.a23 * e.m12 - e.a12 * e.m23;
  const Eigen::Matrix3d d2 = e.a23 * e.m13 - e.a13 * e.m23;
  // det(D1 + g D2) = c3 g^3 + c2 g^2 + c1 g + c0.
  const double c3 = d2.determinant();
  const double c2 = (d1 * Adjugate(d2)).trace();
  const double c1 = (Adjugate(d1) * d2).trace();
  const double c0 = d1.determinant();
  const double cmax = std::max({std::abs(c0), std::abs(c1), std::abs(c2), std::abs(c3)});
  if (!(cmax > 0.0)) return false;
  if (std::abs(c3) < 1e-12 * cmax) {  // D2 itself is degenerate (g -> infinity)
    *d0 = d2;
    *other = d1;
  } else {
    const double g = RealCubicRoot(c2 / c3, c1 / c3, c0 / c3);
    *d0 = d1 + g * d2;
    *other = d2;
  }
  return true;
}

// Scales direction v onto the equations (from the best-conditioned quadratic form), orients it
// positive and polishes it with Gauss-Newton; nullopt when it is not a valid positive solution.
std::optional<Eigen::Vector3d> DepthsAlong(const P3PEquations& e, const Eigen::Vector3d& v) {
  const double q23 = v.dot(e.m23 * v), q12 = v.dot(e.m12 * v), q13 = v.dot(e.m13 * v);
  double k2;
  if (q23 >= q12 && q23 >= q13) {
    k2 = e.a23 / q23;
  } else if (q12 >= q13) {
    k2 = e.a12 / q12;
  } else {
    k2 = e.a13 / q13;
  }
  if (!(k2 > 0.0)) return std::nullopt;
  Eigen::Vector3d lambda = std::sqrt(k2) * v;
  if (lambda.sum() < 0.0) lambda = -lambda;
  if (lambda.minCoeff() <= 0.0) return std::nullopt;
  // Gauss-Newton on the three distance equations.
  Eigen::Vector3d res = e.Residual(lambda);
  for (int it = 0; it < 5 && res.squaredNorm() > 0.0; ++it) {
    const Eigen::Vector3d& l = lambda;
    Eigen::Matrix3d jac;
    jac << 2 * l(0) + e.b12 * l(1), 2 * l(1) + e.b12 * l(0), 0.0,  //
        2 * l(0) + e.b13 * l(2), 0.0, 2 * l(2) + e.b13 * l(0),     //
        0.0, 2 * l(1) + e.b23 * l(2), 2 * l(2) + e.b23 * l(1);
    if (std::abs(jac.determinant()) < 1e-300) break;
    const Eigen::Vector3d next = lambda - jac.partialPivLu().solve(res);
    const Eigen::Vector3d next_res = e.Residual(next);
    if (!(next_res.squaredNorm() < res.squaredNorm())) break;
    lambda = next;
    res = next_res;
  }
  const double scale = std::max({e.a12, e.a13, e.a23});
  if (lambda.minCoeff() <= 0.0 || res.lpNorm<Eigen::Infinity>() > 1e-6 * scale) return std::nullopt;
  return lambda;
}

// The depth triples: the degenerate conic d0 splits into two planes; on each, the other form's
// conic gives up to two directions.
std::vector<Eigen::Vector3d> DepthSolutions(const P3PEquations& e, const Eigen::Matrix3d& d0,
                                            const Eigen::Matrix3d& other) {
  std::vector<Eigen::Vector3d> lambdas;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(d0);
  const Eigen::Vector3d& sig = eig.eigenvalues();
  int k0 = 0;  // the (numerically) zero eigenvalue
  for (int k = 1; k < 3; ++k) {
    if (std::abs(sig(k)) < std::abs(sig(k0))) k0 = k;
  }
  const int ka = (k0 + 1) % 3, kb = (k0 + 2) % 3;
  const double sa = sig(ka), sb = sig(kb);
  if (sa * sb > 0.0 || sa == 0.0) return lambdas;  // definite conic: no real solutions
  const double s = std::sqrt(-sb / sa);
  const Eigen::Vector3d ea = eig.eigenvectors().col(ka), eb = eig.eigenvectors().col(kb);

  for (const double sign : {1.0, -1.0}) {
    const Eigen::Vector3d w = (ea - sign * s * eb).normalized();
    // Orthonormal basis n1, n2 of the plane w . lambda = 0.
    Eigen::Vector3d n1 = w.unitOrthogonal();
    Eigen::Vector3d n2 = w.cross(n1);
    Eigen::Matrix<double, 3, 2> basis;
    basis << n1, n2;
    const Eigen::Matrix2d nq = basis.transpose() * other * basis;
    const double disc = nq(0, 1) * nq(0, 1) - nq(0, 0) * nq(1, 1);
    if (disc < 0.0) continue;
    const double sq = std::sqrt(disc);
    for (const double root_sign : {1.0, -1.0}) {
      Eigen::Vector3d v;
      if (std::abs(nq(0, 0)) >= std::abs(nq(1, 1))) {
        if (nq(0, 0) == 0.0) continue;
        const double r = (-nq(0, 1) + root_sign * sq) / nq(0, 0);
        v = r * n1 + n2;
      } else {
        const double r = (-nq(0, 1) + root_sign * sq) / nq(1, 1);
        v = n1 + r * n2;
      }
      const std::optional<Eigen::Vector3d> lambda = DepthsAlong(e, v);
      if (!lambda) continue;
      bool duplicate = false;
      for (const auto& other_lambda : lambdas) {
        if ((other_lambda - *lambda).norm() < 1e-9 * lambda->norm()) duplicate = true;
      }
      if (!duplicate) lambdas.push_back(*lambda);
    }
  }
  return lambdas;
}

// Kabsch: R, t minimising sum |lambda_i y_i - (R X_i + t)|^2.
Rigid3 PoseFromDepths(const Eigen::Vector3d& lambda, const std::array<Eigen::Vector3d, 3>& y,
                      const std::array<Eigen::Vector3d, 3>& x) {
  Eigen::Vector3d p[3];
  for (int i = 0; i < 3; ++i) p[i] = lambda(i) * y[i];
  const Eigen::Vector3d cx = (x[0] + x[1] + x[2]) / 3.0;
  const Eigen::Vector3d cp = (p[0] + p[1] + p[2]) / 3.0;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) h += (x[i] - cx) * (p[i] - cp).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d rot = svd.matrixV() * fix * svd.matrixU().transpose();
  return Rigid3(rot, cp - rot * cx);
}

}  // namespace

std::vector<Rigid3> SolveP3P(const std::array<Eigen::Vector3d, 3>& bearings_in_cam,
                             const std::array<Eigen::Vector3d, 3>& points_in_world) {
  std::vector<Rigid3> solutions;
  const auto& y = bearings_in_cam;
  const auto& x = points_in_world;
  P3PEquations e;
  e.b12 = -2.0 * y[0].dot(y[1]);
  e.b13 = -2.0 * y[0].dot(y[2]);
  e.b23 = -2.0 * y[1].dot(y[2]);
  e.a12 = (x[0] - x[1]).squaredNorm();
  e.a13 = (x[0] - x[2]).squaredNorm();
  e.a23 = (x[1] - x[2]).squaredNorm();
  // Collinear or coincident world points have no unique solution.
  if ((x[1] - x[0]).cross(x[2] - x[0]).squaredNorm() < 1e-20 * std::max(e.a12, e.a13) * std::max(e.a12, e.a13)) {
    return solutions;
  }
  e.m12 = PairForm(0, 1, e.b12);
  e.m13 = PairForm(0, 2, e.b13);
  e.m23 = PairForm(1, 2, e.b23);
  Eigen::Matrix3d d0, other;
  if (!DegeneratePencilMember(e, &d0, &other)) return solutions;
  for (const Eigen::Vector3d& lambda : DepthSolutions(e, d0, other)) solutions.push_back(PoseFromDepths(lambda, y, x));
  return solutions;
}

}  // namespace rovo
