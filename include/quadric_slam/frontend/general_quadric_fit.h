// A general quadric (10 coefficients, any class: ellipsoids included) fitted to points, used to
// tell whether a primitive's residuals are noise or shape: a sphere fitted to an ellipsoid has an
// RMS well above that of the general quadric, a true sphere does not.
// Fit: algebraic least squares (smallest right singular vector of the monomial matrix, in
// coordinates centred and scaled on the points), then Levenberg-Marquardt on the Sampson distance
// f(p) / |grad f(p)| (the first-order geometric distance).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace quadric_slam {

struct GeneralQuadricFit {
  // f(p) = c0 x^2 + c1 y^2 + c2 z^2 + c3 xy + c4 xz + c5 yz + c6 x + c7 y + c8 z + c9 in the
  // normalised coordinates x = (p - centre) / spread.
  Eigen::Matrix<double, 10, 1> coefficients = Eigen::Matrix<double, 10, 1>::Zero();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double spread = 1.0;
  double rms = 0.0;  // RMS Sampson distance of the points (m)
  bool ok = false;   // false for fewer than 20 points
  // Sampson distance (m) of a point.
  double distance(const Eigen::Vector3d& p) const;
  // The quadric as x^T Q x = 0 in the points' coordinates (x homogeneous).
  Eigen::Matrix4d matrix() const;
  // Unit gradient of f at a point (the quadric's normal direction there; zero where f is flat).
  Eigen::Vector3d gradientDirection(const Eigen::Vector3d& p) const;
};

// The Sampson distance f(x) / |grad f(x)| of a normalised point x for coefficients c, and (when
// jacobian is given) its derivative in c: f = c.m(x) and grad f = G(x) c are linear in c, so
// d/dc = m / |grad f| - f (grad f)^T G / |grad f|^3 (the fit's analytic Jacobian row).
double sampsonDistance(const Eigen::Matrix<double, 10, 1>& c, const Eigen::Vector3d& x,
                       Eigen::Matrix<double, 10, 1>* jacobian = nullptr);

// Uses at most max_points points (an even sub-sample). Iterations of the Sampson refinement >= 0.
GeneralQuadricFit fitGeneralQuadric(const std::vector<Eigen::Vector3d>& points,
                                    int max_points = 600, int iterations = 8);

}  // namespace quadric_slam
