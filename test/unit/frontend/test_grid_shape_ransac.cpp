// The grid RANSAC (grid_shape_ransac.h) on samples laid out on a grid of cells like a component's
// sub-sampled pixels: each surface class found as itself with its size, a plane and a cylinder in
// one component found apart, the same input giving the same shapes, and inputs of unequal length
// refused.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "quadric_slam/frontend/grid_shape_ransac.h"

namespace qs = quadric_slam;
using qs::GridShapeRansac;
using qs::PrimitiveShape;
using qs::QuadricClass;

namespace {

struct GridSamples {
  std::vector<Eigen::Vector3d> points, normals;
  std::vector<Eigen::Vector2i> cells;

  // Adds cols x rows samples at cells (u0 + i, j); at(s, t) gives the point and outward normal at
  // parameters s, t in [0, 1]; noise moves each point along its normal.
  template <typename At>
  void add(int u0, int cols, int rows, At at, double noise, std::mt19937& rng) {
    std::normal_distribution<double> gauss(0.0, noise);
    for (int j = 0; j < rows; ++j) {
      for (int i = 0; i < cols; ++i) {
        const auto [point, normal] = at(i / (cols - 1.0), j / (rows - 1.0));
        points.push_back(point + gauss(rng) * normal);
        normals.push_back(normal);
        cells.emplace_back(u0 + i, j);
      }
    }
  }
};

using PointNormal = std::pair<Eigen::Vector3d, Eigen::Vector3d>;

// The camera-facing side (azimuth within +-70 degrees of the direction towards the origin) of a
// cylinder with axis along y through (x, 0, 1.6), heights -0.2..0.2 m.
auto cylinderAt(double radius, double x = 0.0) {
  return [radius, x](double s, double t) {
    const double a = (s - 0.5) * 140.0 * M_PI / 180.0;
    const Eigen::Vector3d radial(std::sin(a), 0, -std::cos(a));
    return PointNormal{Eigen::Vector3d(x, -0.2 + 0.4 * t, 1.6) + radius * radial, radial};
  };
}

// The camera-facing cap (azimuth and elevation within +-60 degrees) of a sphere centred at
// (0, 0, 1.6).
auto sphereAt(double radius) {
  return [radius](double s, double t) {
    const double a = (s - 0.5) * 120.0 * M_PI / 180.0, e = (t - 0.5) * 120.0 * M_PI / 180.0;
    const Eigen::Vector3d radial(std::sin(a) * std::cos(e), std::sin(e),
                                 -std::cos(a) * std::cos(e));
    return PointNormal{Eigen::Vector3d(0, 0, 1.6) + radius * radial, radial};
  };
}

// The camera-facing side of a cone with apex (0, -0.3, 1.6), axis +y, heights 0.2..0.6 m above the
// apex.
auto coneAt(double half_angle) {
  return [half_angle](double s, double t) {
    const double a = (s - 0.5) * 140.0 * M_PI / 180.0, y = 0.2 + 0.4 * t;
    const Eigen::Vector3d radial(std::sin(a), 0, -std::cos(a));
    const Eigen::Vector3d normal =
        std::cos(half_angle) * radial - std::sin(half_angle) * Eigen::Vector3d::UnitY();
    return PointNormal{Eigen::Vector3d(0, -0.3 + y, 1.6) + y * std::tan(half_angle) * radial,
                       normal};
  };
}

// A 0.4 m x 0.4 m square of the plane z = 1.5 with its left edge at x.
auto planeAt(double x) {
  return [x](double s, double t) {
    return PointNormal{Eigen::Vector3d(x + 0.4 * s, -0.2 + 0.4 * t, 1.5),
                       Eigen::Vector3d(0, 0, -1)};
  };
}

GridShapeRansac::Params curvedParams() {
  GridShapeRansac::Params p;
  p.planes = true;  // as in the segmenter: planes absorb flat patches
  p.probability = 0.2;
  p.min_points = 40;
  return p;
}

const GridShapeRansac::Shape& largest(const std::vector<GridShapeRansac::Shape>& shapes) {
  return *std::max_element(shapes.begin(), shapes.end(), [](const auto& a, const auto& b) {
    return a.indices.size() < b.indices.size();
  });
}

double axisAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

// The largest shape found on a 20 x 20 grid of samples of one surface (1 mm noise); it must take
// at least 80 % of them.
template <typename At>
GridShapeRansac::Shape largestOn(At at, unsigned seed) {
  std::mt19937 rng(seed);
  GridSamples g;
  g.add(0, 20, 20, at, 0.001, rng);
  const auto shapes = GridShapeRansac(curvedParams()).detect(g.points, g.normals, g.cells);
  if (shapes.empty()) {
    ADD_FAILURE() << "no shape found";
    return {};
  }
  const GridShapeRansac::Shape found = largest(shapes);
  EXPECT_GE(found.indices.size(), 0.8 * g.points.size());
  return found;
}

}  // namespace

TEST(GridShapeRansac, FindsACylinderWithItsRadiusAndAxis) {
  const auto found = largestOn(cylinderAt(0.1), 1);
  EXPECT_EQ(found.shape.quadric_class, QuadricClass::kCylinder);
  EXPECT_NEAR(found.shape.size, 0.1, 0.005);
  EXPECT_LT(axisAngle(found.shape.direction, Eigen::Vector3d::UnitY()), 0.05);
}

// A short cylinder (visible height about its diameter, like a mug on a table) with scattered
// normals is proposed as a cylinder: the verification could not make a cylinder of a sphere
// candidate. (This case passes without kSphereMargin too; the margin's evidence is the real mOSD
// cups, 16 -> 20 of 21 upright cylinders.)
TEST(GridShapeRansac, AShortCylinderIsACylinderNotASphere) {
  int cylinders = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    std::mt19937 rng(seed);
    GridSamples g;
    g.add(
        0, 16, 10,
        [](double s, double t) {
          const double a = (s - 0.5) * 140.0 * M_PI / 180.0;
          const Eigen::Vector3d radial(std::sin(a), 0, -std::cos(a));
          return PointNormal{Eigen::Vector3d(0, -0.035 + 0.07 * t, 0.8) + 0.05 * radial, radial};
        },
        0.003, rng);
    // Measured normals scatter by several degrees.
    std::normal_distribution<double> tilt(0.0, 0.1);
    for (Eigen::Vector3d& n : g.normals)
      n = (n + Eigen::Vector3d(tilt(rng), tilt(rng), tilt(rng))).normalized();
    GridShapeRansac::Params p = curvedParams();
    p.random_seed = seed;
    const auto shapes = GridShapeRansac(p).detect(g.points, g.normals, g.cells);
    cylinders += !shapes.empty() && largest(shapes).shape.quadric_class == QuadricClass::kCylinder;
  }
  EXPECT_GE(cylinders, 9);
}

TEST(GridShapeRansac, FindsASphereWithItsRadius) {
  const auto found = largestOn(sphereAt(0.15), 2);
  EXPECT_EQ(found.shape.quadric_class, QuadricClass::kSphere);
  EXPECT_NEAR(found.shape.size, 0.15, 0.005);
  EXPECT_LT((found.shape.point - Eigen::Vector3d(0, 0, 1.6)).norm(), 0.01);
}

TEST(GridShapeRansac, FindsAConeWithItsHalfAngleAndOpening) {
  const auto found = largestOn(coneAt(0.35), 3);
  EXPECT_EQ(found.shape.quadric_class, QuadricClass::kCone);
  EXPECT_NEAR(found.shape.size, 0.35, 0.05);
  // The axis points from the apex into the opening, towards the points.
  EXPECT_GT(found.shape.direction.dot(Eigen::Vector3d::UnitY()), 0.99);
}

TEST(GridShapeRansac, TellsAPlaneFromACylinderInOneComponent) {
  std::mt19937 rng(4);
  GridSamples g;
  g.add(0, 12, 20, planeAt(-0.6), 0.001, rng);          // cells 0..11
  g.add(12, 20, 20, cylinderAt(0.1, 0.2), 0.001, rng);  // cells 12..31, beside it
  const int plane_points = 12 * 20;
  const auto shapes = GridShapeRansac(curvedParams()).detect(g.points, g.normals, g.cells);
  int planes = 0, cylinders = 0;
  for (const auto& shape : shapes) {
    int on_plane = 0;
    for (int i : shape.indices)
      on_plane += i < plane_points;
    const double share = static_cast<double>(on_plane) / shape.indices.size();
    if (shape.shape.quadric_class == QuadricClass::kPlane && share > 0.95 &&
        shape.indices.size() >= 0.8 * plane_points)
      ++planes;
    if (shape.shape.quadric_class == QuadricClass::kCylinder && share < 0.05 &&
        std::abs(shape.shape.size - 0.1) < 0.005)
      ++cylinders;
  }
  EXPECT_EQ(planes, 1);
  EXPECT_EQ(cylinders, 1);
}

TEST(GridShapeRansac, SameInputGivesTheSameShapes) {
  std::mt19937 rng(5);
  GridSamples g;
  g.add(0, 20, 20, coneAt(0.3), 0.003, rng);
  const GridShapeRansac ransac(curvedParams());
  const auto first = ransac.detect(g.points, g.normals, g.cells);
  const auto second = ransac.detect(g.points, g.normals, g.cells);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_EQ(first[k].indices, second[k].indices);
    EXPECT_EQ(first[k].shape.point, second[k].shape.point);
  }
}

TEST(GridShapeRansac, TooFewPointsGiveNoShapeAndUnequalInputsThrow) {
  std::mt19937 rng(6);
  GridSamples g;
  g.add(0, 6, 6, cylinderAt(0.1), 0.001, rng);  // 36 points, under min_points
  EXPECT_TRUE(GridShapeRansac(curvedParams()).detect(g.points, g.normals, g.cells).empty());
  g.cells.pop_back();
  EXPECT_THROW(GridShapeRansac(curvedParams()).detect(g.points, g.normals, g.cells),
               std::invalid_argument);
}
