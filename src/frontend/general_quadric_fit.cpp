#include "quadric_slam/frontend/general_quadric_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "quadric_slam/frontend/levenberg_marquardt.h"
#include "quadric_slam/frontend/shape_refiner.h"

namespace quadric_slam {

namespace {

using Vector10d = Eigen::Matrix<double, 10, 1>;

Vector10d monomials(const Eigen::Vector3d& x) {
  Vector10d m;
  m << x.x() * x.x(), x.y() * x.y(), x.z() * x.z(), x.x() * x.y(), x.x() * x.z(), x.y() * x.z(),
      x.x(), x.y(), x.z(), 1.0;
  return m;
}

// f(x) and its gradient for coefficients c (normalised coordinates).
double value(const Vector10d& c, const Eigen::Vector3d& x, Eigen::Vector3d* gradient) {
  *gradient = Eigen::Vector3d(2 * c[0] * x.x() + c[3] * x.y() + c[4] * x.z() + c[6],
                              2 * c[1] * x.y() + c[3] * x.x() + c[5] * x.z() + c[7],
                              2 * c[2] * x.z() + c[4] * x.x() + c[5] * x.y() + c[8]);
  return c.dot(monomials(x));
}

Eigen::VectorXd residuals(const Vector10d& c, const std::vector<Eigen::Vector3d>& x) {
  Eigen::VectorXd r(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    r[i] = sampsonDistance(c, x[i]);
  return r;
}

}  // namespace

double sampsonDistance(const Vector10d& c, const Eigen::Vector3d& x, Vector10d* jacobian) {
  Eigen::Vector3d g;
  const double f = value(c, x, &g);
  const double norm = g.norm();
  if (norm < 1e-12) {  // the floor: f / 1e-12, linear in c
    if (jacobian)
      *jacobian = monomials(x) / 1e-12;
    return f / 1e-12;
  }
  if (jacobian) {
    // (grad f)^T d(grad f)/dc_j, column by column of G(x) (see value()).
    Vector10d gG;
    gG << 2 * g.x() * x.x(), 2 * g.y() * x.y(), 2 * g.z() * x.z(), g.x() * x.y() + g.y() * x.x(),
        g.x() * x.z() + g.z() * x.x(), g.y() * x.z() + g.z() * x.y(), g.x(), g.y(), g.z(), 0.0;
    *jacobian = monomials(x) / norm - f * gG / (norm * norm * norm);
  }
  return f / norm;
}

double GeneralQuadricFit::distance(const Eigen::Vector3d& p) const {
  return spread * sampsonDistance(coefficients, (p - centre) / spread);
}

Eigen::Matrix4d GeneralQuadricFit::matrix() const {
  const Vector10d& c = coefficients;
  // In normalised coordinates y = (p - centre) / spread: f = y^T A y + 2 b^T y + d.
  Eigen::Matrix4d normalised;
  normalised << c[0], c[3] / 2, c[4] / 2, c[6] / 2,  //
      c[3] / 2, c[1], c[5] / 2, c[7] / 2,            //
      c[4] / 2, c[5] / 2, c[2], c[8] / 2,            //
      c[6] / 2, c[7] / 2, c[8] / 2, c[9];
  // y = N p with N = [I / spread, -centre / spread; 0 1].
  Eigen::Matrix4d N = Eigen::Matrix4d::Identity() / spread;
  N.block<3, 1>(0, 3) = -centre / spread;
  N(3, 3) = 1.0;
  return N.transpose() * normalised * N;
}

Eigen::Vector3d GeneralQuadricFit::gradientDirection(const Eigen::Vector3d& p) const {
  Eigen::Vector3d g;
  value(coefficients, (p - centre) / spread, &g);
  const double norm = g.norm();
  return norm > 0 ? Eigen::Vector3d(g / norm) : Eigen::Vector3d::Zero();
}

GeneralQuadricFit fitGeneralQuadric(const std::vector<Eigen::Vector3d>& all_points, int max_points,
                                    int iterations) {
  GeneralQuadricFit fit;
  if (all_points.size() < 20)
    return fit;
  const std::vector<Eigen::Vector3d> points = evenSubsample(all_points, std::max(20, max_points));
  const std::size_t n = points.size();

  for (const auto& p : points)
    fit.centre += p;
  fit.centre /= static_cast<double>(n);
  double s2 = 0;
  for (const auto& p : points)
    s2 += (p - fit.centre).squaredNorm();
  fit.spread = std::max(std::sqrt(s2 / static_cast<double>(n)), 1e-9);
  std::vector<Eigen::Vector3d> x;
  x.reserve(n);
  for (const auto& p : points)
    x.push_back((p - fit.centre) / fit.spread);

  // Algebraic fit: min |D c| subject to |c| = 1.
  Eigen::Matrix<double, 10, 10> M = Eigen::Matrix<double, 10, 10>::Zero();
  for (const auto& xi : x) {
    const Vector10d m = monomials(xi);
    M += m * m.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 10, 10>> eig(M);
  Vector10d c = eig.eigenvectors().col(0);

  // Levenberg-Marquardt on the Sampson distances (scale-free in c: renormalised each step; 9
  // degrees of freedom), until a step gains less than a tenth of the residual variance
  // (convergedWithinNoise).
  LevenbergMarquardtSettings settings;
  settings.max_iterations = iterations;
  settings.relative_tolerance = 0.0;
  settings.variance_tolerance = 0.1;
  settings.initial_lambda = 1e-3;
  double cost = 0.0;
  c = minimiseSquares(
      c, 9, settings, [&](const Vector10d& coefficients) { return residuals(coefficients, x); },
      [&](const Vector10d& coefficients, const Eigen::VectorXd& rc, Eigen::MatrixXd& H,
          Eigen::VectorXd& g) {
        // J^T J and J^T r accumulated row by row in fixed-size matrices (no n x 10 Jacobian).
        Eigen::Matrix<double, 10, 10> HH = Eigen::Matrix<double, 10, 10>::Zero();
        Vector10d gg = Vector10d::Zero();
        for (std::size_t i = 0; i < x.size(); ++i) {
          Vector10d row;
          sampsonDistance(coefficients, x[i], &row);
          HH.noalias() += row * row.transpose();
          gg += row * rc[static_cast<Eigen::Index>(i)];
        }
        H = HH;
        g = gg;
      },
      [](const Vector10d& coefficients, const Eigen::VectorXd& step) -> std::optional<Vector10d> {
        return Vector10d((coefficients + step).normalized());
      },
      cost);
  fit.coefficients = c;
  fit.rms = fit.spread * std::sqrt(cost / static_cast<double>(n));
  fit.ok = true;
  return fit;
}

}  // namespace quadric_slam
