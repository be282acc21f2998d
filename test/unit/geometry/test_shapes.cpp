#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "../test_support.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {
namespace {

TEST(PlaneShape, FollowsMessageConventions) {
  // n = quadric x axis, n.p = offset for every point of the plane.
  const QuadricModel q = quadricFromShape(PlaneShape{Eigen::Vector3d(0, 0, 2), 1.5});
  EXPECT_LT((q.pose().linear().col(0) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(algebraicDistance(q, Eigen::Vector3d(3, -2, 1.5)), 0, 1e-12);
  EXPECT_NEAR(exactDistance(q, Eigen::Vector3d(3, -2, 2.5)), 1.0, 1e-12);
  const PlaneShape s = planeShape(q);
  EXPECT_LT((s.normal - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(s.offset, 1.5, 1e-12);
  EXPECT_EQ(q.scale(), Eigen::Vector3d::Ones());
  EXPECT_NEAR(q.pose().linear().determinant(), 1.0, 1e-12);
}

TEST(SphereShape, FollowsMessageConventions) {
  const QuadricModel q = quadricFromShape(SphereShape{Eigen::Vector3d(1, 2, 3), 0.5});
  EXPECT_LT((q.scale() - Eigen::Vector3d::Constant(2.0)).norm(), 1e-12);  // S = 1/r
  EXPECT_NEAR(algebraicDistance(q, Eigen::Vector3d(1, 2.5, 3)), 0, 1e-12);
  EXPECT_NEAR(sphereShape(q).radius, 0.5, 1e-12);
}

TEST(CylinderShape, FollowsMessageConventions) {
  const QuadricModel q =
      quadricFromShape(CylinderShape{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 3, 0), 0.25});
  EXPECT_LT((q.pose().linear().col(2) - Eigen::Vector3d::UnitY()).norm(), 1e-12);  // axis = z
  EXPECT_LT((q.scale() - Eigen::Vector3d(4, 4, 1)).norm(), 1e-12);
  EXPECT_NEAR(algebraicDistance(q, Eigen::Vector3d(1.25, 7, 0)), 0, 1e-12);
  EXPECT_NEAR(exactDistance(q, Eigen::Vector3d(1, -3, 1)), 0.75, 1e-12);
  EXPECT_NEAR(q.pose().linear().determinant(), 1.0, 1e-12);
}

TEST(ConeShape, FollowsMessageConventions) {
  const double half = 0.3;
  const QuadricModel q =
      quadricFromShape(ConeShape{Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1), half});
  EXPECT_LT((q.pose().linear().col(2) + Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(q.scale().x(), 1 / std::tan(half), 1e-12);  // S = 1/tan(half_angle)
  EXPECT_NEAR(q.scale().z(), 1.0, 1e-15);
  // A point 2 m down the axis, on the opening's rim.
  EXPECT_NEAR(algebraicDistance(q, Eigen::Vector3d(2 * std::tan(half), 0, -1)), 0, 1e-12);
  const ConeShape s = coneShape(q);
  EXPECT_NEAR(s.half_angle, half, 1e-12);
  EXPECT_LT((s.apex - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
}

void expectShapeRoundTrips(QuadricClass c, int seed) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 20; ++trial) {
    const QuadricModel q = test::randomQuadric(c, rng);
    const std::vector<double> v = shapeVector(q);
    EXPECT_EQ(v.size(), c == QuadricClass::kPlane || c == QuadricClass::kSphere ? 4u : 7u);
    const QuadricModel from_vector = quadricFromShapeVector(c, v);
    const QuadricModel from_map = quadricFromShapeMap(c, shapeMap(q));
    // Same surface (frames may differ by the class's symmetry).
    EXPECT_LT(surfaceMinus(from_vector, q).norm(), 1e-9);
    EXPECT_LT(surfaceMinus(from_map, q).norm(), 1e-9);
    EXPECT_LT((test::normalizedMatrix(from_vector.matrix()) - test::normalizedMatrix(q.matrix()))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9);
    // Idempotent on the human-readable side.
    const std::vector<double> again = shapeVector(from_vector);
    for (size_t i = 0; i < v.size(); ++i)
      EXPECT_NEAR(again[i], v[i], 1e-9);
  }
}

TEST(PlaneShape, VectorAndMapRoundTrip) {
  expectShapeRoundTrips(QuadricClass::kPlane, 71);
}
TEST(SphereShape, VectorAndMapRoundTrip) {
  expectShapeRoundTrips(QuadricClass::kSphere, 72);
}
TEST(CylinderShape, VectorAndMapRoundTrip) {
  expectShapeRoundTrips(QuadricClass::kCylinder, 73);
}
TEST(ConeShape, VectorAndMapRoundTrip) {
  expectShapeRoundTrips(QuadricClass::kCone, 74);
}

TEST(Shapes, MapKeysFollowTheSchema) {
  const auto plane = shapeMap(quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 1}));
  EXPECT_EQ(plane.size(), 2u);
  EXPECT_EQ(plane.at("normal").size(), 3u);
  EXPECT_EQ(plane.at("offset").size(), 1u);
  const auto sphere = shapeMap(quadricFromShape(SphereShape{}));
  EXPECT_EQ(sphere.at("center").size(), 3u);
  EXPECT_EQ(sphere.at("radius").size(), 1u);
  const auto cylinder = shapeMap(quadricFromShape(CylinderShape{}));
  EXPECT_EQ(cylinder.at("point").size(), 3u);
  EXPECT_EQ(cylinder.at("axis").size(), 3u);
  EXPECT_EQ(cylinder.at("radius").size(), 1u);
  const auto cone = shapeMap(quadricFromShape(ConeShape{}));
  EXPECT_EQ(cone.at("apex").size(), 3u);
  EXPECT_EQ(cone.at("axis").size(), 3u);
  EXPECT_EQ(cone.at("half_angle").size(), 1u);
  EXPECT_TRUE(shapeMap(QuadricModel(QuadricClass::kGeneral, Eigen::Isometry3d::Identity(),
                               Eigen::Vector3d(1, 2, 3), Eigen::Vector4d(1, 1, 1, -1)))
                  .empty());
}

TEST(Shapes, RejectInvalidInput) {
  EXPECT_THROW(quadricFromShape(SphereShape{Eigen::Vector3d::Zero(), -1}), std::invalid_argument);
  EXPECT_THROW(quadricFromShape(PlaneShape{Eigen::Vector3d::Zero(), 1}), std::invalid_argument);
  EXPECT_THROW(quadricFromShape(ConeShape{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 1.6}),
               std::invalid_argument);
  EXPECT_THROW(quadricFromShapeVector(QuadricClass::kCylinder, {1, 2, 3}), std::invalid_argument);
  EXPECT_THROW(quadricFromShapeVector(QuadricClass::kGeneral, {}), std::invalid_argument);
  EXPECT_THROW(quadricFromShapeMap(QuadricClass::kSphere, {{"center", {0, 0, 0}}}),
               std::invalid_argument);
  EXPECT_THROW(sphereShape(quadricFromShape(PlaneShape{})), std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam
