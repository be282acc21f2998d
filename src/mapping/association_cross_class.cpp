#include "quadric_slam/mapping/association_cross_class.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/geometry/surface_distance.h"

namespace quadric_slam {

namespace {

bool isAxial(QuadricClass c) { return c == QuadricClass::kCylinder || c == QuadricClass::kCone; }

// A general quadric of the ellipsoid's signature (the only general surface sampled here).
bool isEllipsoid(const QuadricModel& q) {
  return q.quadricClass() == QuadricClass::kGeneral && q.signature() == Eigen::Vector4d(1, 1, 1, -1);
}

// Points of the observed surface (its own frame) on a grid over the box, kept where they lie inside
// it (the box says which side of the surface the sensor saw): cylinders and cones 8 heights x 72
// angles, spheres and ellipsoids 36 polar x 72 azimuth angles.
std::vector<Eigen::Vector3d> surfacePointsInBox(const QuadricModel& observed,
                                                const ExtentBox& box) {
  std::vector<Eigen::Vector3d> points;
  const double slack = 1e-3;  // m: points on the box's faces count
  auto keep = [&](const Eigen::Vector3d& p) {
    if ((p.array() >= box.min.array() - slack).all() && (p.array() <= box.max.array() + slack).all())
      points.push_back(p);
  };
  const double alpha = observed.scale().x();
  if (observed.quadricClass() == QuadricClass::kSphere || isEllipsoid(observed)) {
    const Eigen::Vector3d semi_axes = observed.scale().cwiseInverse();
    constexpr int kPolar = 36, kAzimuth = 72;
    for (int i = 0; i < kPolar; ++i) {
      const double theta = M_PI * (i + 0.5) / kPolar;
      for (int j = 0; j < kAzimuth; ++j) {
        const double phi = 2.0 * M_PI * j / kAzimuth;
        keep(semi_axes.cwiseProduct(Eigen::Vector3d(std::sin(theta) * std::cos(phi),
                                                     std::sin(theta) * std::sin(phi),
                                                     std::cos(theta))));
      }
    }
    return points;
  }
  constexpr int kHeights = 8, kAngles = 72;
  for (int i = 0; i < kHeights; ++i) {
    const double z = box.min.z() + (box.max.z() - box.min.z()) * (i + 0.5) / kHeights;
    // A cylinder's radius 1/alpha; a cone's |z| tan(half-angle) = |z| / alpha (either nappe: a
    // symmetry of the quadric may flip the frame).
    const double r = observed.quadricClass() == QuadricClass::kCylinder ? 1.0 / alpha
                                                                         : std::abs(z) / alpha;
    for (int j = 0; j < kAngles; ++j) {
      const double phi = 2.0 * M_PI * j / kAngles;
      keep(Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z));
    }
  }
  return points;
}

}  // namespace

bool surfaceTestApplies(const QuadricModel& observed, const QuadricModel& target) {
  const QuadricClass o = observed.quadricClass(), t = target.quadricClass();
  // Axial classes and spheres against their own class too: a partial view (a cone's upper band, a
  // cylinder's narrow strip) fits a shape whose parameters fail the gate of a landmark it lies on.
  if (isAxial(o) && isAxial(t))
    return true;
  if (o == QuadricClass::kSphere)
    return isAxial(t) || t == QuadricClass::kGeneral || t == QuadricClass::kSphere;
  // An ellipsoid against any curved landmark, general ones included: a general fit of part of a
  // surface is poorly determined (its minimal-space covariance misses the shape's model error),
  // so two fits of one patch can fail the association gate yet lie on each other.
  return isEllipsoid(observed) && t != QuadricClass::kPlane;
}

double crossClassDistance(const QuadricModel& observed, const ExtentBox& box,
                          const QuadricModel& target) {
  const double inf = std::numeric_limits<double>::infinity();
  if (!surfaceTestApplies(observed, target) || !box.known())
    return inf;
  double sum = 0.0;
  int n = 0;
  for (const Eigen::Vector3d& p : surfacePointsInBox(observed, box)) {
    // Exact for the four classes (for a cone, the nearer nappe of the double cone: a symmetry of
    // the quadric may flip the frame's z); first-order (Sampson) for general quadrics.
    const double d = surfaceDistance(target, observed.pose() * p);
    sum += d * d;
    ++n;
  }
  return n == 0 ? inf : std::sqrt(sum / n);
}

}  // namespace quadric_slam
