// Shared helpers for the geometry and mapping unit tests: seeded random poses and quadrics, and
// central-difference Jacobians.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <random>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {
namespace test {

inline double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline Eigen::Vector3d randomVector(std::mt19937& rng, double scale) {
  return Eigen::Vector3d(uniform(rng, -scale, scale), uniform(rng, -scale, scale),
                         uniform(rng, -scale, scale));
}

inline Eigen::Isometry3d randomPose(std::mt19937& rng, double translation_scale = 2.0) {
  Eigen::Quaterniond q(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1),
                       uniform(rng, -1, 1));
  q.normalize();
  return makeIsometry(q.toRotationMatrix(), randomVector(rng, translation_scale));
}

// A random quadric of the class; for kGeneral the signature is given (default: ellipsoid).
inline QuadricModel randomQuadric(QuadricClass c, std::mt19937& rng,
                             const Eigen::Vector4d& general_signature = Eigen::Vector4d(1, 1, 1,
                                                                                        -1)) {
  const Eigen::Isometry3d T = randomPose(rng);
  switch (c) {
    case QuadricClass::kPlane:
      return QuadricModel(c, T, Eigen::Vector3d::Ones());
    case QuadricClass::kSphere: {
      const double a = 1.0 / uniform(rng, 0.2, 2.0);
      return QuadricModel(c, T, Eigen::Vector3d(a, a, a));
    }
    case QuadricClass::kCylinder: {
      const double a = 1.0 / uniform(rng, 0.1, 1.5);
      return QuadricModel(c, T, Eigen::Vector3d(a, a, 1));
    }
    case QuadricClass::kCone: {
      const double a = 1.0 / std::tan(uniform(rng, 0.2, 1.2));
      return QuadricModel(c, T, Eigen::Vector3d(a, a, 1));
    }
    case QuadricClass::kGeneral:
      break;
  }
  Eigen::Vector3d s(uniform(rng, 0.3, 3.0), uniform(rng, 0.3, 3.0), uniform(rng, 0.3, 3.0));
  for (int i = 0; i < 3; ++i) {
    if (general_signature[i] == 0)
      s[i] = 1.0;
  }
  return QuadricModel(c, T, s, general_signature);
}

// A random element of the class's symmetry group, including discrete flips (quadric frame).
inline Eigen::Isometry3d randomSymmetry(QuadricClass c, std::mt19937& rng) {
  const double angle = uniform(rng, -M_PI, M_PI);
  const double slide = uniform(rng, -2, 2), slide2 = uniform(rng, -2, 2);
  const bool flip = uniform(rng, 0, 1) < 0.5;
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  switch (c) {
    case QuadricClass::kSphere:
      return makeIsometry(randomPose(rng).linear(), Eigen::Vector3d::Zero());
    case QuadricClass::kCylinder:
    case QuadricClass::kCone:
      G.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      if (c == QuadricClass::kCylinder)
        G.translation() = Eigen::Vector3d(0, 0, slide);
      if (flip)
        G.linear() =
            G.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
      return G;
    case QuadricClass::kPlane:
      G.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
      G.translation() = Eigen::Vector3d(0, slide, slide2);
      if (flip)
        G.linear() =
            G.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
      return G;
    case QuadricClass::kGeneral:
      break;
  }
  if (flip)
    G.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return G;
}

// Central differences of f: R^n -> R^m at x = 0 (the tangent origin), step h.
inline Eigen::MatrixXd numericJacobian(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, int n, double h = 1e-6) {
  const Eigen::VectorXd f0 = f(Eigen::VectorXd::Zero(n));
  Eigen::MatrixXd J(f0.size(), n);
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
    d[i] = h;
    J.col(i) = (f(d) - f(-d)) / (2 * h);
  }
  return J;
}

// Largest entry-wise difference relative to max(1, largest entry).
inline double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const double scale = std::max(1.0, std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()));
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

// Q normalised for comparison: unit max-abs entry, sign chosen so the largest entry is positive.
inline Eigen::Matrix4d normalizedMatrix(const Eigen::Matrix4d& Q) {
  Eigen::Index r, c;
  Q.cwiseAbs().maxCoeff(&r, &c);
  return Q / Q(r, c);
}

}  // namespace test
}  // namespace quadric_slam
