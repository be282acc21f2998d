// The silhouette taper (frontend/silhouette_taper.h): the visible width of a cone's side grows
// along its axis by tan(half angle) per metre, a cylinder's does not, with depth noise as far
// surfaces have it; too short a support, or a line of sight along the axis, gives no taper.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "quadric_slam/frontend/silhouette_taper.h"

using quadric_slam::measureSilhouetteTaper;
using quadric_slam::predictedTaper;
using quadric_slam::PrimitiveShape;
using quadric_slam::SilhouetteTaper;

namespace {

// Points on the side of a surface of revolution facing a camera at the origin: axis along the
// image's y, through `base` (2-3 m ahead), radius(t) at axial position t in [t0, t1]; the arc
// within 75 degrees of the line of sight (the sensor returns nothing at more grazing incidence),
// with Gaussian noise of sigma_depth along each point's ray.
std::vector<Eigen::Vector3d> visibleSide(const Eigen::Vector3d& base, double t0, double t1,
                                         double (*radius)(double), double sigma_depth,
                                         unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_depth);
  std::vector<Eigen::Vector3d> points;
  const double max_angle = 75.0 * M_PI / 180.0;
  for (double t = t0; t <= t1; t += 0.005) {
    for (double a = -max_angle; a <= max_angle; a += 0.04) {
      const Eigen::Vector3d p =
          base + Eigen::Vector3d(radius(t) * std::sin(a), t, -radius(t) * std::cos(a));
      points.push_back(p * (1.0 + noise(rng) / p.norm()));
    }
  }
  return points;
}

double coneRadius(double t) {
  return t * std::tan(0.32);
}
double cylinderRadius(double) {
  return 0.15;
}

}  // namespace

TEST(SilhouetteTaper, AConesSideWidensByItsHalfAngleACylindersDoesNot) {
  // A cone opening downwards (image y) from an apex 0.4 m above the optical axis, 2.6 m away,
  // from 0.1 m below the apex to 0.75 m; 1.5 cm depth noise (the Kinect's at 2.6 m).
  const Eigen::Vector3d apex(0.1, -0.4, 2.6);
  const std::vector<Eigen::Vector3d> cone = visibleSide(apex, 0.1, 0.75, coneRadius, 0.015, 1);
  const SilhouetteTaper along_axis = measureSilhouetteTaper(apex, Eigen::Vector3d::UnitY(), cone);
  EXPECT_NEAR(along_axis.slope, std::tan(0.32), 0.15 * std::tan(0.32));
  EXPECT_TRUE(along_axis.significant(0.09));
  // Along the near generator (the axis a cylinder fitted to the visible side takes): the same.
  const Eigen::Vector3d generator =
      Eigen::Vector3d(0, std::cos(0.32), -std::sin(0.32)).normalized();
  const SilhouetteTaper along_generator = measureSilhouetteTaper(apex, generator, cone);
  EXPECT_NEAR(along_generator.slope, std::tan(0.32), 0.15 * std::tan(0.32));
  // The cone predicts it; a cylinder predicts none.
  const PrimitiveShape cone_shape = PrimitiveShape::cone(apex, Eigen::Vector3d::UnitY(), 0.32);
  EXPECT_NEAR(predictedTaper(cone_shape, Eigen::Vector3d::UnitY()), std::tan(0.32), 1e-12);
  EXPECT_NEAR(predictedTaper(cone_shape, -Eigen::Vector3d::UnitY()), -std::tan(0.32), 1e-12);
  EXPECT_EQ(predictedTaper(PrimitiveShape::cylinder(apex, Eigen::Vector3d::UnitY(), 0.15),
                           Eigen::Vector3d::UnitY()),
            0.0);

  const Eigen::Vector3d foot(-0.2, -0.3, 2.4);
  const std::vector<Eigen::Vector3d> cylinder =
      visibleSide(foot, 0.0, 0.6, cylinderRadius, 0.015, 2);
  const SilhouetteTaper straight = measureSilhouetteTaper(foot, Eigen::Vector3d::UnitY(), cylinder);
  EXPECT_NEAR(straight.slope, 0.0, 0.03);
  EXPECT_FALSE(straight.significant(0.09));
}

TEST(SilhouetteTaper, NoTaperFromAShortSupportOrAlongTheLineOfSight) {
  const Eigen::Vector3d apex(0.0, -0.1, 1.5);
  // 8 cm of a cone: too short to tell its widening from a segment's ragged ends.
  const std::vector<Eigen::Vector3d> short_band =
      visibleSide(apex, 0.3, 0.38, coneRadius, 0.003, 3);
  EXPECT_EQ(measureSilhouetteTaper(apex, Eigen::Vector3d::UnitY(), short_band).bins, 0);
  // The same cone seen along its axis: the width across the axis is not its outline.
  const std::vector<Eigen::Vector3d> cone = visibleSide(apex, 0.1, 0.75, coneRadius, 0.003, 4);
  const Eigen::Vector3d line_of_sight = cone[cone.size() / 2].normalized();
  EXPECT_EQ(measureSilhouetteTaper(apex, line_of_sight, cone).bins, 0);
  EXPECT_FALSE(SilhouetteTaper{}.significant(0.0));
  EXPECT_EQ(measureSilhouetteTaper(apex, Eigen::Vector3d::Zero(), cone).bins, 0);
}
