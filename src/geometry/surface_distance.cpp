#include "quadric_slam/geometry/surface_distance.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace quadric_slam {

namespace {

Eigen::Vector3d toQuadric(const QuadricModel& q, const Eigen::Vector3d& p) {
  const Eigen::Isometry3d& T = q.pose();
  return T.linear().transpose() * (p - T.translation());
}

// Closest point on a (double) cone with apex at the origin, axis z and half-angle theta, in the
// cone's frame: the closest point lies in the half-plane through the axis and p.
Eigen::Vector3d closestOnCone(const Eigen::Vector3d& p, double theta) {
  const double r = std::hypot(p.x(), p.y());
  const Eigen::Vector2d radial =
      r > 1e-15 ? Eigen::Vector2d(p.x() / r, p.y() / r) : Eigen::Vector2d(1, 0);
  const Eigen::Vector2d rh(r, p.z());
  Eigen::Vector2d best = Eigen::Vector2d::Zero();  // the apex
  double best_d = rh.norm();
  for (double sign : {1.0, -1.0}) {
    const Eigen::Vector2d u(std::sin(theta), sign * std::cos(theta));  // a generating ray
    const double t = std::max(0.0, rh.dot(u));
    const double d = (rh - t * u).norm();
    if (d < best_d) {
      best_d = d;
      best = t * u;
    }
  }
  return Eigen::Vector3d(best.x() * radial.x(), best.x() * radial.y(), best.y());
}

}  // namespace

// eqs. 2 and 4 evaluated at the homogeneous point [p; 1]
double algebraicDistance(const QuadricModel& q, const Eigen::Vector3d& p) {
  return algebraicValueAndSlope(q, p).value;
}

Eigen::Vector3d algebraicGradient(const QuadricModel& q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d s = q.scale();
  const Eigen::Vector3d local =
      2.0 * s.cwiseProduct(q.signature().head<3>().cwiseProduct(s.cwiseProduct(toQuadric(q, p))));
  return q.pose().linear() * local;
}

AlgebraicValue algebraicValueAndSlope(const QuadricModel& q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d s = q.scale();
  const Eigen::Vector3d sigma = q.signature().head<3>();
  const Eigen::Vector3d y = s.cwiseProduct(toQuadric(q, p));
  AlgebraicValue result;
  result.value = y.dot(sigma.cwiseProduct(y)) + q.signature()[3];
  result.gradient_norm = 2.0 * s.cwiseProduct(sigma.cwiseProduct(y)).norm();
  return result;
}

double firstOrderDistance(const QuadricModel& q, const Eigen::Vector3d& p) {
  const AlgebraicValue a = algebraicValueAndSlope(q, p);
  const double f = a.value, g = a.gradient_norm;
  if (f == 0)
    return 0;
  if (g == 0)
    return std::numeric_limits<double>::infinity();
  return std::abs(f) / g;
}

double exactDistance(const QuadricModel& q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d pq = toQuadric(q, p);
  switch (q.quadricClass()) {
    case QuadricClass::kPlane:
      return std::abs(pq.x());
    case QuadricClass::kSphere:
      return std::abs(pq.norm() - 1.0 / q.scale().x());
    case QuadricClass::kCylinder:
      return std::abs(std::hypot(pq.x(), pq.y()) - 1.0 / q.scale().x());
    case QuadricClass::kCone:
      return (pq - closestOnCone(pq, std::atan2(1.0, q.scale().x()))).norm();
    case QuadricClass::kGeneral:
      break;
  }
  throw std::invalid_argument("exactDistance: not available for general quadrics");
}

double surfaceDistance(const QuadricModel& q, const Eigen::Vector3d& p) {
  return q.quadricClass() == QuadricClass::kGeneral ? firstOrderDistance(q, p)
                                                    : exactDistance(q, p);
}

void SurfaceProjector::Params::validate() const {
  if (max_iterations < 1)
    throw std::invalid_argument("SurfaceProjector::Params::max_iterations must be >= 1, got " +
                                std::to_string(max_iterations));
  if (!(tolerance > 0))
    throw std::invalid_argument("SurfaceProjector::Params::tolerance must be > 0 (m), got " +
                                std::to_string(tolerance));
}

SurfaceProjector::SurfaceProjector() : SurfaceProjector(Params()) {}

SurfaceProjector::SurfaceProjector(const Params& params) : params_(params) {
  params_.validate();
}

Eigen::Vector3d SurfaceProjector::project(const QuadricModel& q, const Eigen::Vector3d& p) const {
  const Eigen::Vector3d pq = toQuadric(q, p);
  Eigen::Vector3d out;
  switch (q.quadricClass()) {
    case QuadricClass::kPlane:
      out = Eigen::Vector3d(0, pq.y(), pq.z());
      return q.pose() * out;
    case QuadricClass::kSphere: {
      const double r = 1.0 / q.scale().x();
      const double n = pq.norm();
      out = n > 1e-15 ? Eigen::Vector3d(r * pq / n) : Eigen::Vector3d(r, 0, 0);
      return q.pose() * out;
    }
    case QuadricClass::kCylinder: {
      const double r = 1.0 / q.scale().x();
      const double n = std::hypot(pq.x(), pq.y());
      out = n > 1e-15 ? Eigen::Vector3d(r * pq.x() / n, r * pq.y() / n, pq.z())
                      : Eigen::Vector3d(r, 0, pq.z());
      return q.pose() * out;
    }
    case QuadricClass::kCone:
      return q.pose() * closestOnCone(pq, std::atan2(1.0, q.scale().x()));
    case QuadricClass::kGeneral:
      break;
  }
  Eigen::Vector3d x = p;
  for (int i = 0; i < params_.max_iterations; ++i) {
    const double f = algebraicDistance(q, x);
    const Eigen::Vector3d g = algebraicGradient(q, x);
    const double g2 = g.squaredNorm();
    if (g2 == 0)
      break;
    if (std::abs(f) / std::sqrt(g2) < params_.tolerance)
      return x;
    x -= f / g2 * g;
  }
  if (firstOrderDistance(q, x) < params_.tolerance * 1e3)
    return x;
  throw std::invalid_argument("SurfaceProjector::project: no convergence for this point");
}

}  // namespace quadric_slam
