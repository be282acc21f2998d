// Model selection among the curved classes (curved_model_selection.h) on noisy samples of the
// visible side of a surface, started from the wrong class: a cone fitted as a cylinder becomes a
// cone, a cylinder fitted as a cone becomes a cylinder, a sphere cap fitted as a cylinder becomes a
// sphere, a cylinder fitted as a wide cone (axis far from its own) becomes the cylinder, and a
// cylinder fitted as a cylinder stays one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "axial_surface_samples.h"
#include "quadric_slam/frontend/curved_model_selection.h"
#include "quadric_slam/frontend/curved_shape_starts.h"

namespace qs = quadric_slam;
using qs::PrimitiveShape;
using qs::QuadricClass;

namespace {

using Samples = qs::test::SurfaceSamples;
using qs::test::kAxisPoint;

// 1500 points of the camera-facing part (azimuth within +-70 degrees) of a cone or cylinder.
Samples axialSurface(bool cone, double radius_or_angle, double y_min, double y_max, double noise,
                     unsigned seed) {
  return qs::test::axialSurface(cone, radius_or_angle, y_min, y_max, noise, seed, 1500, 70.0);
}

// A cap of a sphere facing the camera (polar angle from -z within 60 degrees).
Samples sphereCap(double radius, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, noise);
  Samples s;
  for (int i = 0; i < 1500; ++i) {
    const double polar = std::acos(1 - uni(rng) * (1 - std::cos(60 * M_PI / 180)));
    const double azimuth = 2 * M_PI * uni(rng);
    const Eigen::Vector3d n(std::sin(polar) * std::cos(azimuth),
                            std::sin(polar) * std::sin(azimuth), -std::cos(polar));
    s.points.push_back(kAxisPoint + (radius + gauss(rng)) * n);
    s.normals.push_back(n);
  }
  return s;
}

qs::QuadricSegmenter::Params params() {
  qs::QuadricSegmenter::Params p;
  p.detect_cones = true;
  p.detect_spheres = true;
  return p;
}

// The refined fit of start's class on the samples, then model selection.
qs::ShapeRefiner::Result selected(const PrimitiveShape& start, const Samples& s) {
  const qs::ShapeRefiner refiner;
  const qs::ShapeRefiner::Result fit = refiner.refine(start, s.points);
  return qs::selectCurvedModel(fit, s.points, s.normals, {}, params(), refiner);
}

}  // namespace

TEST(CurvedModelSelection, ConeFittedAsCylinderBecomesCone) {
  const double half_angle = 0.3;
  const Samples s = axialSurface(true, half_angle, 0.2, 0.5, 0.001, 1);
  const PrimitiveShape start = qs::cylinderFromCone(
      PrimitiveShape::cone(kAxisPoint, Eigen::Vector3d::UnitY(), half_angle), s.points);
  const qs::ShapeRefiner::Result result = selected(start, s);
  ASSERT_EQ(result.shape.quadric_class, QuadricClass::kCone);
  EXPECT_NEAR(result.shape.size, half_angle, 0.01);
  EXPECT_LT(result.rms, 0.0012);
}

TEST(CurvedModelSelection, CylinderFittedAsConeBecomesCylinder) {
  const double radius = 0.06;
  const Samples s = axialSurface(false, radius, -0.15, 0.15, 0.001, 2);
  // A thin cone around the cylinder: apex far down the axis.
  const double height = 3.0;
  const PrimitiveShape start =
      PrimitiveShape::cone(kAxisPoint - height * Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitY(),
                           std::atan(radius / height));
  const qs::ShapeRefiner::Result result = selected(start, s);
  ASSERT_EQ(result.shape.quadric_class, QuadricClass::kCylinder);
  EXPECT_NEAR(result.shape.size, radius, 0.002);
}

TEST(CurvedModelSelection, SphereCapFittedAsCylinderBecomesSphere) {
  const double radius = 0.1;
  const Samples s = sphereCap(radius, 0.001, 3);
  const PrimitiveShape start =
      PrimitiveShape::cylinder(kAxisPoint, Eigen::Vector3d::UnitY(), radius);
  const qs::ShapeRefiner::Result result = selected(start, s);
  ASSERT_EQ(result.shape.quadric_class, QuadricClass::kSphere);
  EXPECT_NEAR(result.shape.size, radius, 0.002);
  EXPECT_LT((result.shape.point - kAxisPoint).norm(), 0.003);
}

TEST(CurvedModelSelection, CylinderStaysCylinder) {
  const double radius = 0.05;
  const Samples s = axialSurface(false, radius, -0.2, 0.2, 0.001, 4);
  const PrimitiveShape start =
      PrimitiveShape::cylinder(kAxisPoint, Eigen::Vector3d::UnitY(), radius * 1.1);
  const qs::ShapeRefiner::Result result = selected(start, s);
  ASSERT_EQ(result.shape.quadric_class, QuadricClass::kCylinder);
  EXPECT_NEAR(result.shape.size, radius, 0.001);
  EXPECT_LT(result.rms, 0.0012);
}

// A wide cone fitted to a narrow cylinder's strip (CGAL proposes one on a tube lying on a desk):
// its axis lies far from the cylinder's, the cylinder around it does not fit, and the cylinder the
// normals describe is the start that finds the tube.
TEST(CurvedModelSelection, CylinderFittedAsAWideConeBecomesCylinder) {
  const double radius = 0.04;
  const Samples s = axialSurface(false, radius, -0.15, 0.15, 0.001, 5);
  // A cone whose axis crosses the tube's, apex to one side: it refines to a wide cone (about 1 rad)
  // through the strip.
  const PrimitiveShape start = PrimitiveShape::cone(kAxisPoint + Eigen::Vector3d(0.3, 0.0, 0.0),
                                                    Eigen::Vector3d(-1, 0, 0), 0.3);
  const qs::ShapeRefiner refiner;
  const qs::ShapeRefiner::Result cone = refiner.refine(start, s.points);
  ASSERT_EQ(cone.shape.quadric_class, QuadricClass::kCone);
  ASSERT_LT(cone.shape.size, params().max_cone_half_angle) << "a plausible cone";
  std::printf("the wide cone: half angle %.3f, RMS %.4f m\n", cone.shape.size, cone.rms);
  const qs::ShapeRefiner::Result result =
      qs::selectCurvedModel(cone, s.points, s.normals, {}, params(), refiner);
  ASSERT_EQ(result.shape.quadric_class, QuadricClass::kCylinder);
  EXPECT_NEAR(result.shape.size, radius, 0.002);
}
