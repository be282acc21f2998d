// PrimitiveShape: its core quadric (geometry/shapes.h) checked against the quadric equation
// (S p_Q)^T D(sigma) (S p_Q) + sigma_4 = 0 (eq. 5), round trips, distances, the minimal
// perturbation (the core's Table II plusMinimal); ShapeRefiner on exact and noisy samples.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include "quadric_slam/frontend/primitive_shape.h"
#include "quadric_slam/frontend/shape_refiner.h"
#include "quadric_slam/geometry/quadric_classes.h"

namespace qs = quadric_slam;
using qs::PrimitiveShape;
using qs::QuadricClass;

namespace {

std::vector<PrimitiveShape> someShapes() {
  return {
      PrimitiveShape::plane(Eigen::Vector3d(0.2, -0.9, -0.3), -1.1),
      PrimitiveShape::sphere(Eigen::Vector3d(0.3, -0.2, 1.5), 0.17),
      PrimitiveShape::cylinder(Eigen::Vector3d(0.1, 0.4, 1.8), Eigen::Vector3d(0.1, -1, 0.2), 0.06),
      PrimitiveShape::cone(Eigen::Vector3d(-0.3, 0.1, 1.4), Eigen::Vector3d(0, 1, 0.3), 0.35)};
}

// Points exactly on the surface, in the shape's frame: built in the canonical quadric frame.
std::vector<Eigen::Vector3d> surfaceSamples(const PrimitiveShape& s, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const Eigen::Isometry3d T = s.quadric().pose();
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d q;
    const double a = M_PI * uni(rng) * 0.6, h = uni(rng);
    switch (s.quadric_class) {
      case QuadricClass::kPlane:
        q = Eigen::Vector3d(0, 0.5 * h, 0.5 * uni(rng));
        break;
      case QuadricClass::kSphere: {
        const double e = 0.6 * uni(rng);
        q = s.size *
            Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
        break;
      }
      case QuadricClass::kCylinder:
        q = Eigen::Vector3d(s.size * std::cos(a), s.size * std::sin(a), 0.2 * h);
        break;
      default: {
        const double z = 0.3 + 0.2 * h;
        const double r = z * std::tan(s.size);
        q = Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z);
      }
    }
    points.push_back(T * q);
  }
  return points;
}

}  // namespace

TEST(PrimitiveShape, PoseAndScaleSatisfyTheQuadricEquationOfTheMessageConvention) {
  for (const PrimitiveShape& s : someShapes()) {
    const Eigen::Isometry3d T_frame_quadric = s.quadric().pose();
    const Eigen::Vector3d scale = s.quadric().scale();
    const Eigen::Vector4d sigma = qs::defaultSignature(s.quadric_class);
    for (const Eigen::Vector3d& p : surfaceSamples(s, 50, 3)) {
      EXPECT_NEAR(s.distance(p), 0.0, 1e-9);
      const Eigen::Vector3d sp = scale.asDiagonal() * (T_frame_quadric.inverse() * p);
      const double value =
          sigma[0] * sp[0] * sp[0] + sigma[1] * sp[1] * sp[1] + sigma[2] * sp[2] * sp[2] + sigma[3];
      EXPECT_NEAR(value, 0.0, 1e-9) << qs::toString(s.quadric_class);
    }
    // A point off the surface does not satisfy it.
    const Eigen::Vector3d off = s.quadric().pose() * Eigen::Vector3d(0.5, 0.4, 0.3);
    EXPECT_GT(std::abs(s.distance(off)), 1e-3);
  }
  // Plane normal = quadric x axis; cylinder/cone axis = quadric z; cone apex = origin.
  const auto shapes = someShapes();
  EXPECT_NEAR((shapes[0].quadric().pose().linear().col(0) - shapes[0].direction).norm(), 0, 1e-12);
  EXPECT_NEAR((shapes[2].quadric().pose().linear().col(2) - shapes[2].direction).norm(), 0, 1e-12);
  EXPECT_NEAR((shapes[3].quadric().pose().translation() - shapes[3].point).norm(), 0, 1e-12);
  EXPECT_NEAR(shapes[3].quadric().scale().x(), 1.0 / std::tan(0.35), 1e-12);
  EXPECT_NEAR(shapes[2].quadric().scale().x(), 1.0 / 0.06, 1e-9);
  EXPECT_DOUBLE_EQ(shapes[2].quadric().scale().z(), 1.0);
}

TEST(PrimitiveShape, FromQuadricInvertsQuadric) {
  for (const PrimitiveShape& s : someShapes()) {
    const PrimitiveShape back = PrimitiveShape::fromQuadric(s.quadric());
    const std::vector<double> a = s.shapeVector(), b = back.shapeVector();
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      EXPECT_NEAR(a[i], b[i], 1e-9);
  }
}

TEST(PrimitiveShape, PerturbationHasTheTableTwoDimensionAndMovesTheSurface) {
  for (const PrimitiveShape& s : someShapes()) {
    const int k = qs::minimalDimension(s.quadric_class);
    EXPECT_EQ(static_cast<int>(qs::minimalIndices(s.quadric_class).size()), k);
    const PrimitiveShape same = qs::perturb(s, Eigen::VectorXd::Zero(k));
    const Eigen::Vector3d probe = s.quadric().pose() * Eigen::Vector3d(0.3, 0.2, 0.4);
    EXPECT_NEAR(same.distance(probe), s.distance(probe), 1e-12);
    // Every minimal direction changes the surface (no gauge direction in the minimal set).
    const std::vector<Eigen::Vector3d> samples = surfaceSamples(s, 200, 5);
    for (int j = 0; j < k; ++j) {
      Eigen::VectorXd delta = Eigen::VectorXd::Zero(k);
      delta[j] = 1e-3;
      EXPECT_GT(qs::rmsDistance(qs::perturb(s, delta), samples), 1e-6)
          << qs::toString(s.quadric_class) << " coordinate " << j;
    }
  }
  EXPECT_THROW(qs::perturb(someShapes()[0], Eigen::VectorXd::Zero(4)), std::invalid_argument);
}

TEST(PrimitiveShape, MinimalIndicesAreTheTableTwoBasisAndPerturbIsTheCorePlus) {
  for (const PrimitiveShape& s : someShapes()) {
    const qs::QuadricClassDefinition& def = qs::classDefinition(s.quadric_class);
    const std::vector<int>& idx = qs::minimalIndices(s.quadric_class);
    ASSERT_EQ(static_cast<int>(idx.size()), def.minimal_dimension);
    for (std::size_t j = 0; j < idx.size(); ++j) {
      // Pose entries 0..5 are the unit column; the scale entry 6 is the tied scale column.
      const int row = idx[j] < 6 ? idx[j] : 6;
      EXPECT_DOUBLE_EQ(def.basis(row, static_cast<int>(j)), 1.0)
          << qs::toString(s.quadric_class) << " column " << j;
    }
    // perturb() and the core's plusMinimal give the same surface.
    const int k = def.minimal_dimension;
    Eigen::VectorXd delta = Eigen::VectorXd::LinSpaced(k, 0.01, 0.02);
    const PrimitiveShape moved = qs::perturb(s, delta);
    const qs::QuadricModel core = s.quadric().plusMinimal(delta);
    const std::vector<Eigen::Vector3d> samples = surfaceSamples(moved, 100, 4);
    for (const Eigen::Vector3d& p : samples) {
      const Eigen::Vector3d sp = core.scale().asDiagonal() * (core.pose().inverse() * p);
      const Eigen::Vector4d sig = core.signature();
      EXPECT_NEAR(sig[0] * sp[0] * sp[0] + sig[1] * sp[1] * sp[1] + sig[2] * sp[2] * sp[2] + sig[3],
                  0.0, 1e-9)
          << qs::toString(s.quadric_class);
    }
  }
}

TEST(ShapeRefiner, RecoversEachClassFromAPerturbedStartAndScalesCovarianceWithNoise) {
  const qs::ShapeRefiner refiner;
  std::mt19937 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (const PrimitiveShape& truth : someShapes()) {
    const int k = qs::minimalDimension(truth.quadric_class);
    std::vector<Eigen::Vector3d> points = surfaceSamples(truth, 1500, 9);
    Eigen::VectorXd delta(k);
    for (int j = 0; j < k; ++j)
      delta[j] = 0.01 * ((j % 2) ? 1 : -1);
    const PrimitiveShape start = qs::perturb(truth, delta);
    const qs::ShapeRefiner::Result exact = refiner.refine(start, points);
    EXPECT_LT(exact.rms, 1e-6) << qs::toString(truth.quadric_class);
    const std::vector<double> a = truth.shapeVector(), b = exact.shape.shapeVector();
    // The same surface: the exact samples lie on it (cylinder/cone axis points are free).
    EXPECT_LT(qs::rmsDistance(exact.shape, surfaceSamples(truth, 300, 21)), 1e-6);
    if (truth.quadric_class == QuadricClass::kSphere ||
        truth.quadric_class == QuadricClass::kPlane) {
      for (std::size_t i = 0; i < a.size(); ++i)
        EXPECT_NEAR(a[i], b[i], 1e-5) << qs::toString(truth.quadric_class) << " entry " << i;
    } else {
      EXPECT_NEAR(a.back(), b.back(), 1e-6);  // radius / half angle
    }

    // With 2 mm noise the RMS is ~2 mm and the covariance is positive definite and small.
    for (auto& p : points)
      p += 0.002 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)) / std::sqrt(3.0);
    const qs::ShapeRefiner::Result noisy = refiner.refine(start, points);
    EXPECT_TRUE(noisy.ok);
    EXPECT_NEAR(noisy.rms, 0.002 / std::sqrt(3.0), 0.0005);
    ASSERT_EQ(noisy.covariance.rows(), k);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(noisy.covariance);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  }
}

TEST(ShapeRefiner, ParamsValidateNamesTheField) {
  qs::ShapeRefiner::Params p;
  p.max_iterations = 0;
  try {
    p.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_iterations"), std::string::npos);
  }
}

TEST(ShapeRefiner, AShapeWithoutACoreQuadricIsNotRefinedAndDoesNotThrow) {
  // A RANSAC cone may come with a half angle beyond pi/2: no quadric, no perturbation.
  const PrimitiveShape bad =
      PrimitiveShape::cone(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1), 2.2);
  EXPECT_THROW(bad.quadric(), std::invalid_argument);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 50; ++i)
    points.emplace_back(0.01 * i, 0.02 * (i % 7), 1.5);
  const qs::ShapeRefiner refiner;
  EXPECT_FALSE(refiner.refine(bad, points).ok);
  EXPECT_FALSE(refiner.evaluate(bad, points).ok);
}

TEST(PrimitiveShape, PerturbThrowsWhenTheScaleStepLeavesTheClass) {
  // A step through alpha = 0 (the core's [+] stops it at a thousandth of the scale) used to come
  // back as a cylinder of negative radius or a cone with a half angle beyond pi/2 (no core
  // quadric), and the refiner's next Jacobian threw from perturb() outside its guarded step (a real
  // frame aborted bench_segmentation).
  const PrimitiveShape cylinder =
      PrimitiveShape::cylinder(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitY(), 0.1);
  Eigen::VectorXd step = Eigen::VectorXd::Zero(5);
  step[4] = -20;  // alpha = 1 / r: 10 -> -10
  EXPECT_THROW(perturb(cylinder, step), std::invalid_argument);
  step[4] = -5;  // 10 -> 5: radius 0.2
  EXPECT_NEAR(perturb(cylinder, step).size, 0.2, 1e-12);

  const PrimitiveShape cone =
      PrimitiveShape::cone(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitZ(), 1.0);
  Eigen::VectorXd cone_step = Eigen::VectorXd::Zero(6);
  cone_step[5] = -1.0;  // alpha = 1 / tan(1.0) = 0.64 -> -0.36
  EXPECT_THROW(perturb(cone, cone_step), std::invalid_argument);

  const PrimitiveShape sphere = PrimitiveShape::sphere(Eigen::Vector3d(0, 0, 1), 0.1);
  Eigen::VectorXd sphere_step = Eigen::VectorXd::Zero(4);
  sphere_step[3] = -10;  // alpha 10 -> 0
  EXPECT_THROW(perturb(sphere, sphere_step), std::invalid_argument);
}

namespace {

// distanceJacobian(s, points) against central differences of the distances through perturb, per
// point and minimal coordinate (what names the shape in the failure messages).
void expectDistanceJacobianMatchesCentralDifferences(const PrimitiveShape& s,
                                                     const std::vector<Eigen::Vector3d>& points,
                                                     const std::string& what) {
  const int k = qs::minimalDimension(s.quadric_class);
  const Eigen::MatrixXd J = qs::distanceJacobian(s, points);
  ASSERT_EQ(J.rows(), static_cast<Eigen::Index>(points.size()));
  ASSERT_EQ(J.cols(), k);
  constexpr double h = 1e-6;
  for (int j = 0; j < k; ++j) {
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(k);
    delta[j] = h;
    const PrimitiveShape plus = qs::perturb(s, delta);
    delta[j] = -h;
    const PrimitiveShape minus = qs::perturb(s, delta);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double numeric = (plus.distance(points[i]) - minus.distance(points[i])) / (2 * h);
      EXPECT_NEAR(J(static_cast<Eigen::Index>(i), j), numeric, 1e-6 * (1 + std::abs(numeric)))
          << what << " point " << i << " coordinate " << j;
    }
  }
}

}  // namespace

// The refiner's analytic Jacobian (per-point gradient chained through perturb) against central
// differences of the distances through perturb, for every class at points on, in front of and
// behind the surface; and distanceGradient itself against differences in (point, direction, size).
TEST(ShapeRefiner, AnalyticDistanceJacobianMatchesNumericDifferentiation) {
  std::mt19937 rng(17);
  std::normal_distribution<double> off_surface(0.0, 0.02);
  for (const PrimitiveShape& s : someShapes()) {
    std::vector<Eigen::Vector3d> points = surfaceSamples(s, 60, 3);
    for (Eigen::Vector3d& p : points)
      p += off_surface(rng) * s.normalAt(p);
    expectDistanceJacobianMatchesCentralDifferences(s, points, qs::toString(s.quadric_class));
    // distanceGradient in the shape's own parameters.
    constexpr double h = 1e-6;
    const Eigen::Vector3d probe = points[7];
    const Eigen::Matrix<double, 7, 1> g = s.distanceGradient(probe);
    for (int j = 0; j < 7; ++j) {
      PrimitiveShape a = s, b = s;
      if (j < 3) {
        a.point[j] += h;
        b.point[j] -= h;
      } else if (j < 6) {
        a.direction[j - 3] += h;
        b.direction[j - 3] -= h;
      } else {
        a.size += h;
        b.size -= h;
      }
      EXPECT_NEAR(g[j], (a.distance(probe) - b.distance(probe)) / (2 * h), 1e-6)
          << qs::toString(s.quadric_class) << " parameter " << j;
    }
  }
}

// The same for general quadrics (an ellipsoid, a hyperboloid of one sheet), whose distance is the
// first-order f / |grad f|: the closed-form 9-coordinate Jacobian against central differences
// through perturb, at points scattered around the surface (off it by up to a few cm).
TEST(ShapeRefiner, GeneralQuadricDistanceJacobianMatchesNumericDifferentiation) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1, 0.4).normalized()).matrix();
  T.translation() = Eigen::Vector3d(0.2, -0.1, 1.6);
  const std::vector<PrimitiveShape> shapes = {
      PrimitiveShape::general(qs::QuadricModel(QuadricClass::kGeneral, T,
                                               Eigen::Vector3d(1 / 0.25, 1 / 0.15, 1 / 0.1))),
      PrimitiveShape::general(qs::QuadricModel(QuadricClass::kGeneral, T,
                                               Eigen::Vector3d(1 / 0.2, 1 / 0.3, 1 / 0.5),
                                               Eigen::Vector4d(1, 1, -1, -1)))};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-0.4, 0.4);
  for (const PrimitiveShape& s : shapes) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 80; ++i)
      points.push_back(T * Eigen::Vector3d(uni(rng), uni(rng), uni(rng)));
    std::ostringstream what;
    what << "general, signature " << s.general_quadric.signature().transpose();
    expectDistanceJacobianMatchesCentralDifferences(s, points, what.str());
  }
}
