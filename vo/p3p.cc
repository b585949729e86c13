#include "vo/p3p.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

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

}  // namespace

std::vector<Rigid3> SolveP3P(const std::array<Eigen::Vector3d, 3>& bearings_in_cam,
                             const std::array<Eigen::Vector3d, 3>& points_in_world) {
  std::vector<Rigid3> solutions;
  const auto& y = bearings_in_cam;
  const auto& x = points_in_world;
  const double b12 = -2.0 * y[0].dot(y[1]);
  const double b13 = -2.0 * y[0].dot(y[2]);
  const double b23 = -2.0 * y[1].dot(y[2]);
  const double a12 = (x[0] - x[1]).squaredNorm();
  const double a13 = (x[0] - x[2]).squaredNorm();
  const double a23 = (x[1] - x[2]).squaredNorm();
  // Collinear or coincident world points have no unique solution.
  if ((x[1] - x[0]).cross(x[2] - x[0]).squaredNorm() < 1e-20 * std::max(a12, a13) * std::max(a12, a13)) {
    return solutions;
  }
  const Eigen::Matrix3d m12 = PairForm(0, 1, b12);
  const Eigen::Matrix3d m13 = PairForm(0, 2, b13);
  const Eigen::Matrix3d m23 = PairForm(1, 2, b23);
  const Eigen::Matrix3d d1 = a23 * m12 - a12 * m23;
  const Eigen::Matrix3d d2 = a23 * m13 - a13 * m23;

  // det(D1 + g D2) = c3 g^3 + c2 g^2 + c1 g + c0.
  const double c3 = d2.determinant();
  const double c2 = (d1 * Adjugate(d2)).trace();
  const double c1 = (Adjugate(d1) * d2).trace();
  const double c0 = d1.determinant();
  const double cmax = std::max({std::abs(c0), std::abs(c1), std::abs(c2), std::abs(c3)});
  if (!(cmax > 0.0)) return solutions;
  Eigen::Matrix3d d0, other;
  if (std::abs(c3) < 1e-12 * cmax) {  // D2 itself is degenerate (g -> infinity)
    d0 = d2;
    other = d1;
  } else {
    const double g = RealCubicRoot(c2 / c3, c1 / c3, c0 / c3);
    d0 = d1 + g * d2;
    other = d2;
  }

  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(d0);
  const Eigen::Vector3d sig = eig.eigenvalues();
  int k0 = 0;  // the (numerically) zero eigenvalue
  for (int k = 1; k < 3; ++k) {
    if (std::abs(sig(k)) < std::abs(sig(k0))) k0 = k;
  }
  const int ka = (k0 + 1) % 3, kb = (k0 + 2) % 3;
  const double sa = sig(ka), sb = sig(kb);
  if (sa * sb > 0.0 || sa == 0.0) return solutions;  // definite conic: no real solutions
  const double s = std::sqrt(-sb / sa);
  const Eigen::Vector3d ea = eig.eigenvectors().col(ka), eb = eig.eigenvectors().col(kb);

  std::vector<Eigen::Vector3d> lambdas;
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
      // Scale from the equation with the best-conditioned quadratic form.
      const double q23 = v.dot(m23 * v), q12 = v.dot(m12 * v), q13 = v.dot(m13 * v);
      double k2;
      if (q23 >= q12 && q23 >= q13) {
        k2 = a23 / q23;
      } else if (q12 >= q13) {
        k2 = a12 / q12;
      } else {
        k2 = a13 / q13;
      }
      if (!(k2 > 0.0)) continue;
      Eigen::Vector3d lambda = std::sqrt(k2) * v;
      if (lambda.sum() < 0.0) lambda = -lambda;
      if (lambda.minCoeff() <= 0.0) continue;
      // Gauss-Newton on the three distance equations.
      auto residual = [&](const Eigen::Vector3d& l) {
        return Eigen::Vector3d(l(0) * l(0) + l(1) * l(1) + b12 * l(0) * l(1) - a12,
                               l(0) * l(0) + l(2) * l(2) + b13 * l(0) * l(2) - a13,
                               l(1) * l(1) + l(2) * l(2) + b23 * l(1) * l(2) - a23);
      };
      Eigen::Vector3d res = residual(lambda);
      for (int it = 0; it < 5 && res.squaredNorm() > 0.0; ++it) {
        const Eigen::Vector3d& l = lambda;
        Eigen::Matrix3d jac;
        jac << 2 * l(0) + b12 * l(1), 2 * l(1) + b12 * l(0), 0.0,  //
            2 * l(0) + b13 * l(2), 0.0, 2 * l(2) + b13 * l(0),     //
            0.0, 2 * l(1) + b23 * l(2), 2 * l(2) + b23 * l(1);
        if (std::abs(jac.determinant()) < 1e-300) break;
        const Eigen::Vector3d next = lambda - jac.partialPivLu().solve(res);
        const Eigen::Vector3d next_res = residual(next);
        if (!(next_res.squaredNorm() < res.squaredNorm())) break;
        lambda = next;
        res = next_res;
      }
      const double scale = std::max({a12, a13, a23});
      if (lambda.minCoeff() <= 0.0 || res.lpNorm<Eigen::Infinity>() > 1e-6 * scale) continue;
      bool duplicate = false;
      for (const auto& other_lambda : lambdas) {
        if ((other_lambda - lambda).norm() < 1e-9 * lambda.norm()) duplicate = true;
      }
      if (!duplicate) lambdas.push_back(lambda);
    }
  }

  for (const Eigen::Vector3d& lambda : lambdas) {
    // Kabsch: R, t minimising sum |lambda_i y_i - (R X_i + t)|^2.
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
    solutions.emplace_back(rot, cp - rot * cx);
  }
  return solutions;
}

}  // namespace rovo
