// The silhouette taper (frontend/silhouette_taper.h): the visible width of a cone's side grows
// along its axis by tan(half angle) per metre, a cylinder's does not, with depth noise as far
// surfaces have it; too short a support, or a line of sight along the axis, gives no taper.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "quadric_slam/frontend/silhouette_taper.h"

using quadric_slam::cutOutline;
using quadric_slam::measureSilhouetteTaper;
using quadric_slam::predictedTaper;
using quadric_slam::PrimitiveShape;
using quadric_slam::SegmentationFrame;
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

namespace {

// The points of `side` that a nearer surface standing in front of their lower part leaves
// visible: those with t (the axial position along the image's y from `base`) beyond t_cut and
// image x below x_cut are hidden; the visible points within 1 cm of the cut are flagged as the
// occluded outline.
void occludeLowerLeft(const std::vector<Eigen::Vector3d>& side, const Eigen::Vector3d& base,
                      double t_cut, double x_cut, std::vector<Eigen::Vector3d>* visible,
                      std::vector<std::uint8_t>* occluded) {
  for (const Eigen::Vector3d& p : side) {
    const bool below = p.y() - base.y() > t_cut;
    if (below && p.x() < x_cut)
      continue;
    visible->push_back(p);
    occluded->push_back(below && p.x() < x_cut + 0.01);
  }
}

}  // namespace

TEST(SilhouetteTaper, AnOccludedSideIsLeftOutOfTheWidth) {
  // The cone of the first test with the lower two thirds of its left side hidden behind a nearer
  // surface whose edge runs vertically in the image: the occluded side's edge is straight, and the
  // width measured across both sides would be a cylinder's. Each side's own silhouette still
  // opens by the half angle.
  const Eigen::Vector3d apex(0.1, -0.4, 2.6);
  const std::vector<Eigen::Vector3d> cone = visibleSide(apex, 0.1, 0.75, coneRadius, 0.015, 5);
  std::vector<Eigen::Vector3d> visible;
  std::vector<std::uint8_t> occluded;
  occludeLowerLeft(cone, apex, 0.3, apex.x() - 0.3 * std::tan(0.32), &visible, &occluded);
  const SilhouetteTaper unflagged = measureSilhouetteTaper(apex, Eigen::Vector3d::UnitY(), visible);
  const SilhouetteTaper flagged =
      measureSilhouetteTaper(apex, Eigen::Vector3d::UnitY(), visible, occluded);
  EXPECT_LT(unflagged.slope, 0.7 * std::tan(0.32));
  EXPECT_NEAR(flagged.slope, std::tan(0.32), 0.25 * std::tan(0.32));
  EXPECT_TRUE(flagged.significant(0.09));

  // A cylinder with one side hidden all along: no taper, whatever the other side does.
  const Eigen::Vector3d foot(-0.2, -0.3, 2.4);
  const std::vector<Eigen::Vector3d> cylinder =
      visibleSide(foot, 0.0, 0.6, cylinderRadius, 0.015, 6);
  std::vector<Eigen::Vector3d> strip;
  std::vector<std::uint8_t> strip_occluded;
  occludeLowerLeft(cylinder, foot, -1.0, foot.x() - 0.05, &strip, &strip_occluded);
  EXPECT_FALSE(measureSilhouetteTaper(foot, Eigen::Vector3d::UnitY(), strip, strip_occluded)
                   .significant(0.09));
  EXPECT_EQ(measureSilhouetteTaper(foot, Eigen::Vector3d::UnitY(), strip, strip_occluded).bins, 0);
  // Hidden on one side below its middle: the sides' own lines are parallel.
  std::vector<Eigen::Vector3d> half;
  std::vector<std::uint8_t> half_occluded;
  occludeLowerLeft(cylinder, foot, 0.3, foot.x() - 0.05, &half, &half_occluded);
  const SilhouetteTaper parallel =
      measureSilhouetteTaper(foot, Eigen::Vector3d::UnitY(), half, half_occluded);
  EXPECT_NEAR(parallel.slope, 0.0, 0.05);
  EXPECT_FALSE(parallel.significant(0.09));
}

TEST(SilhouetteTaper, AnOutlineIsCutWhereANearerSurfaceOrTheSameSurfaceLiesBeyondIt) {
  // A 40 x 30 grid: a wall 4 m away; the support, columns 15-24 of rows 5-24, 2.5 m away; left of
  // it, behind a seam without depth (columns 11-14), a nearer surface at 1.8 m over rows 15-29;
  // right of it over rows 5-9 the surface goes on at 2.52 m outside the support.
  const int width = 40, height = 30;
  pcl::PointCloud<pcl::PointNormal> cloud(width, height);
  std::vector<std::uint8_t> valid(width * height, 1);
  std::vector<int> support;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float z = 4.0f;
      if (x >= 15 && x <= 24 && y >= 5 && y <= 24) {
        z = 2.5f;
        support.push_back(y * width + x);
      } else if (x >= 25 && x <= 27 && y >= 5 && y <= 9) {
        z = 2.52f;
      } else if (x >= 11 && x <= 14) {
        valid[y * width + x] = 0;
      } else if (x >= 5 && x <= 10 && y >= 15) {
        z = 1.8f;
      }
      pcl::PointNormal& p = cloud.at(x, y);
      p.x = (x - 20) * z / 525.0f;
      p.y = (y - 15) * z / 525.0f;
      p.z = z;
    }
  }
  const SegmentationFrame frame{cloud, width, height, valid,
                                std::vector<std::uint8_t>(valid.size(), 0)};
  const std::vector<std::uint8_t> cut = cutOutline(frame, support, 0.04);
  ASSERT_EQ(cut.size(), support.size());
  const auto cutAt = [&](int x, int y) {
    const auto it = std::find(support.begin(), support.end(), y * width + x);
    return cut[static_cast<std::size_t>(it - support.begin())] != 0;
  };
  EXPECT_FALSE(cutAt(20, 15));  // inside the support
  EXPECT_TRUE(cutAt(15, 20));   // beside the nearer surface, across the seam
  EXPECT_FALSE(cutAt(15, 6));   // the nearer surface 9 rows away: the silhouette
  EXPECT_FALSE(cutAt(24, 20));  // the farther wall beyond: the silhouette
  EXPECT_TRUE(cutAt(24, 7));    // the surface going on beyond
  EXPECT_FALSE(cutAt(18, 5));   // the top edge, the farther wall above
}
