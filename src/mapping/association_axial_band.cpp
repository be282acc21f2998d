#include "quadric_slam/mapping/association_axial_band.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "quadric_slam/geometry/quadric_class.h"

namespace quadric_slam {

namespace {

bool isAxial(QuadricClass c) { return c == QuadricClass::kCylinder || c == QuadricClass::kCone; }

// Radius of the observed surface at height z of its own frame: a cylinder's 1/alpha, a cone's
// |z| tan(half-angle) = |z| / alpha (either nappe: a symmetry of the quadric may flip the frame).
double radiusAt(const QuadricModel& axial, double z) {
  const double alpha = axial.scale().x();
  return axial.quadricClass() == QuadricClass::kCylinder ? 1.0 / alpha : std::abs(z) / alpha;
}

}  // namespace

bool axialClassPair(const QuadricModel& a, const QuadricModel& b) {
  return isAxial(a.quadricClass()) && isAxial(b.quadricClass()) &&
         a.quadricClass() != b.quadricClass();
}

double axialSurfaceDistance(const QuadricModel& axial, const Eigen::Vector3d& p) {
  const double rho = p.head<2>().norm();
  if (axial.quadricClass() == QuadricClass::kCylinder)
    return std::abs(rho - 1.0 / axial.scale().x());
  if (axial.quadricClass() != QuadricClass::kCone)
    throw std::invalid_argument("axialSurfaceDistance: needs a cylinder or a cone, got " +
                                toString(axial.quadricClass()));
  // In the plane through the axis and p, the nearer nappe is the ray at the half-angle beta from
  // +-z towards p (the quadric is the double cone; a symmetry of it may flip the frame's z).
  const double beta = std::atan(1.0 / axial.scale().x());
  return std::abs(rho * std::cos(beta) - std::abs(p.z()) * std::sin(beta));
}

double axialBandDistance(const QuadricModel& observed, const ExtentBox& box,
                         const QuadricModel& target) {
  const double inf = std::numeric_limits<double>::infinity();
  if (!axialClassPair(observed, target) || !box.known())
    return inf;
  // A grid over the band: 8 heights x 72 angles, kept where the surface point lies inside the
  // box (its x-y extent says which side of the surface the sensor saw).
  constexpr int kHeights = 8, kAngles = 72;
  const double slack = 1e-3;  // m: points on the box's faces count
  const Eigen::Isometry3d T_target_observed = target.pose().inverse() * observed.pose();
  double sum = 0.0;
  int n = 0;
  for (int i = 0; i < kHeights; ++i) {
    const double z = box.min.z() + (box.max.z() - box.min.z()) * (i + 0.5) / kHeights;
    const double r = radiusAt(observed, z);
    for (int j = 0; j < kAngles; ++j) {
      const double theta = 2.0 * M_PI * j / kAngles;
      const Eigen::Vector3d p(r * std::cos(theta), r * std::sin(theta), z);
      if ((p.array() < box.min.array() - slack).any() ||
          (p.array() > box.max.array() + slack).any())
        continue;
      const double d = axialSurfaceDistance(target, T_target_observed * p);
      sum += d * d;
      ++n;
    }
  }
  return n == 0 ? inf : std::sqrt(sum / n);
}

}  // namespace quadric_slam
