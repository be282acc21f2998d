#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "../test_support.h"
#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/surface_distance.h"

namespace quadric_slam {
namespace {

// Points on the canonical surface, mapped by T_WQ: solve f = 0 along random rays from a point
// where f < 0 (inside/between sheets) to one where f > 0.
std::vector<Eigen::Vector3d> surfacePoints(const QuadricModel& q, std::mt19937& rng, int n) {
  std::vector<Eigen::Vector3d> out;
  for (int tries = 0; tries < 200 * n && static_cast<int>(out.size()) < n; ++tries) {
    Eigen::Vector3d a = q.pose() * test::randomVector(rng, 3.0);
    Eigen::Vector3d b = q.pose() * test::randomVector(rng, 3.0);
    double fa = algebraicDistance(q, a), fb = algebraicDistance(q, b);
    if (fa * fb >= 0)
      continue;
    for (int i = 0; i < 200; ++i) {  // bisection
      const Eigen::Vector3d m = 0.5 * (a + b);
      const double fm = algebraicDistance(q, m);
      if ((fm < 0) == (fa < 0)) {
        a = m;
        fa = fm;
      } else {
        b = m;
      }
    }
    out.push_back(0.5 * (a + b));
  }
  return out;
}

void expectDecomposeRoundTrip(QuadricClass c, const Eigen::Vector4d& signature, int seed) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 20; ++trial) {
    const QuadricModel q = test::randomQuadric(c, rng, signature);
    const double projective = test::uniform(rng, 0.1, 10.0) * (trial % 2 ? -1.0 : 1.0);
    const QuadricModel d = QuadricModel::fromMatrix(projective * q.matrix(), c);
    EXPECT_EQ(d.quadricClass(), c);
    EXPECT_EQ(d.signature(), q.signature()) << "trial " << trial;
    EXPECT_LT((test::normalizedMatrix(d.matrix()) - test::normalizedMatrix(q.matrix()))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9)
        << "trial " << trial;
    // Same surface: points of q lie on d.
    std::mt19937 prng(seed + trial);
    for (const Eigen::Vector3d& p : surfacePoints(q, prng, 5))
      EXPECT_LT(firstOrderDistance(d, p), 1e-9);
    // The scale is unique for every class except the ordering of equal-sign general axes.
    if (c != QuadricClass::kGeneral) {
      EXPECT_LT((d.scale() - q.scale()).norm(), 1e-9 * q.scale().norm());
    }
  }
}

TEST(PlaneQuadric, DecomposeRoundTrip) {
  expectDecomposeRoundTrip(QuadricClass::kPlane, Eigen::Vector4d(1, 0, 0, 0), 1);
}
TEST(SphereQuadric, DecomposeRoundTrip) {
  expectDecomposeRoundTrip(QuadricClass::kSphere, Eigen::Vector4d(1, 1, 1, -1), 2);
}
TEST(CylinderQuadric, DecomposeRoundTrip) {
  expectDecomposeRoundTrip(QuadricClass::kCylinder, Eigen::Vector4d(1, 1, 0, -1), 3);
}
TEST(ConeQuadric, DecomposeRoundTrip) {
  expectDecomposeRoundTrip(QuadricClass::kCone, Eigen::Vector4d(1, 1, -1, 0), 4);
}
TEST(GeneralQuadric, DecomposeRoundTripEllipsoid) {
  expectDecomposeRoundTrip(QuadricClass::kGeneral, Eigen::Vector4d(1, 1, 1, -1), 5);
}
TEST(GeneralQuadric, DecomposeRoundTripHyperboloidOneSheet) {
  expectDecomposeRoundTrip(QuadricClass::kGeneral, Eigen::Vector4d(1, 1, -1, -1), 6);
}
TEST(GeneralQuadric, DecomposeRoundTripHyperboloidTwoSheets) {
  expectDecomposeRoundTrip(QuadricClass::kGeneral, Eigen::Vector4d(1, 1, -1, 1), 7);
}
TEST(GeneralQuadric, DecomposeRoundTripEllipticCone) {
  expectDecomposeRoundTrip(QuadricClass::kGeneral, Eigen::Vector4d(1, 1, -1, 0), 8);
}
TEST(GeneralQuadric, DecomposeRoundTripEllipticCylinder) {
  expectDecomposeRoundTrip(QuadricClass::kGeneral, Eigen::Vector4d(1, 1, 0, -1), 9);
}
TEST(GeneralQuadric, DecomposeRoundTripHyperbolicCylinder) {
  expectDecomposeRoundTrip(QuadricClass::kGeneral, Eigen::Vector4d(1, -1, 0, -1), 10);
}

TEST(QuadricModel, ComposeFollowsEquationFive) {
  // Paper, Table I row 2: T = I, S = diag(1, 0.5, 2), ellipsoid x^2 + y^2/4 + 4 z^2 = 1.
  const QuadricModel q(QuadricClass::kGeneral, Eigen::Isometry3d::Identity(),
                       Eigen::Vector3d(1, 0.5, 2), Eigen::Vector4d(1, 1, 1, -1));
  EXPECT_LT((q.matrix() - Eigen::Vector4d(1, 0.25, 4, -1).asDiagonal().toDenseMatrix()).norm(),
            1e-15);
  EXPECT_NEAR(algebraicDistance(q, Eigen::Vector3d(0, 2, 0)), 0, 1e-15);
  EXPECT_NEAR(algebraicDistance(q, Eigen::Vector3d(0, 0, 0.5)), 0, 1e-15);
  // A plane: quadric x = 0 through (1, 2, 3) with normal along world z.
  Eigen::Matrix3d R;
  R << 0, 1, 0, 0, 0, 1, 1, 0, 0;  // quadric x -> world z
  const QuadricModel plane(QuadricClass::kPlane, makeIsometry(R, Eigen::Vector3d(1, 2, 3)),
                           Eigen::Vector3d::Ones());
  EXPECT_NEAR(algebraicDistance(plane, Eigen::Vector3d(-5, 7, 3)), 0, 1e-12);
  EXPECT_NEAR(algebraicDistance(plane, Eigen::Vector3d(-5, 7, 4)), 1, 1e-12);  // (alpha x)^2
}

TEST(QuadricModel, PaperTableOneRowThree) {
  // T_WQ = [1 0 0 0; 0 0 1 3; 0 -1 0 0; 0 0 0 1], S = diag(1, 0.5, 2): the ellipsoid with
  // semi-axes (1, 2, 0.5) along quadric x, y, z = world x, -z, y, centred at (0, 3, 0).
  Eigen::Matrix4d T;
  T << 1, 0, 0, 0, 0, 0, 1, 3, 0, -1, 0, 0, 0, 0, 0, 1;
  const QuadricModel q(QuadricClass::kGeneral, Eigen::Isometry3d(T), Eigen::Vector3d(1, 0.5, 2),
                       Eigen::Vector4d(1, 1, 1, -1));
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(1, 3, 0), Eigen::Vector3d(0, 3, -2),
                                   Eigen::Vector3d(0, 3, 2), Eigen::Vector3d(0, 3.5, 0)}) {
    const Eigen::Vector4d ph(p.x(), p.y(), p.z(), 1);
    EXPECT_NEAR(ph.dot(q.matrix() * ph), 0, 1e-12) << p.transpose();  // z^T Q z = 0 (eq. 2)
  }
  const Eigen::Vector4d centre(0, 3, 0, 1);
  EXPECT_NEAR(centre.dot(q.matrix() * centre), -1, 1e-12);
}

TEST(QuadricModel, MeasurementTransformsLikeAQuadric) {
  // eq. 19: h(T_WC, pi) = (T_WC^-1 T_WQ, S), and then Q_C = T_WC^T Q_W T_WC.
  std::mt19937 rng(12);
  for (QuadricClass c : kAllQuadricClasses) {
    const QuadricModel q = test::randomQuadric(c, rng);
    const Eigen::Isometry3d T_WC = test::randomPose(rng);
    const QuadricModel h = predictMeasurement(T_WC, q);
    EXPECT_LT((h.pose().matrix() - (T_WC.inverse() * q.pose()).matrix()).norm(), 1e-12);
    EXPECT_EQ(h.scale(), q.scale());
    const Eigen::Matrix4d expected = T_WC.matrix().transpose() * q.matrix() * T_WC.matrix();
    EXPECT_LT((h.matrix() - expected).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(QuadricModel, PlusMinusRoundTrip) {
  std::mt19937 rng(13);
  for (QuadricClass c : kAllQuadricClasses) {
    for (int trial = 0; trial < 10; ++trial) {
      const QuadricModel q = test::randomQuadric(c, rng);
      Vector9d d;
      for (int i = 0; i < 9; ++i)
        d[i] = test::uniform(rng, -0.5, 0.5);
      const QuadricModel general = QuadricModel(QuadricClass::kGeneral, q.pose(), q.scale() * 2.0,
                                                Eigen::Vector4d(1, 1, 1, -1));
      EXPECT_LT((general.plus(d).minus(general) - d).norm(), 1e-10);  // eqs. 10-17
      const int k = minimalDimension(c);
      Eigen::VectorXd m(k);
      for (int i = 0; i < k; ++i)
        m[i] = test::uniform(rng, -0.3, 0.3);
      const QuadricModel moved = q.plusMinimal(m);
      EXPECT_LT((moved.minusMinimal(q) - m).norm(), 1e-10) << toString(c);
      EXPECT_EQ(moved.quadricClass(), c);
      // the class's ties survive [+]
      EXPECT_NO_THROW(QuadricModel(c, moved.pose(), moved.scale()));
    }
  }
}

TEST(QuadricModel, DecomposeRejectsDegenerateAndUnsupported) {
  Eigen::Matrix4d Q = Eigen::Matrix4d::Zero();
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral), std::invalid_argument);
  Q = Eigen::Vector4d(1, 1, 1, -1).asDiagonal();
  Q(0, 1) = 0.5;  // not symmetric
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral), std::invalid_argument);
  Q = Eigen::Vector4d(1, 1, 1, 1).asDiagonal();  // x^2 + y^2 + z^2 + 1 = 0: no real points
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral), std::invalid_argument);
  Q = Eigen::Vector4d(1, -1, 0, 0).asDiagonal();  // x^2 - y^2 = 0: pair of planes
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral), std::invalid_argument);
  Q = Eigen::Vector4d(1, 1, 1, 0).asDiagonal();  // a single point
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral), std::invalid_argument);
  Q = Eigen::Matrix4d::Zero();  // paraboloid x^2 + y^2 - z = 0
  Q(0, 0) = Q(1, 1) = 1;
  Q(2, 3) = Q(3, 2) = -0.5;
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral), std::invalid_argument);
  Q = Eigen::Matrix4d::Zero();  // single plane in linear form: z = 0
  Q(2, 3) = Q(3, 2) = 0.5;
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral), std::invalid_argument);
  Q = Eigen::Vector4d(1, 0.25, 4, -1).asDiagonal();  // ellipsoid is not a sphere
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kSphere), std::invalid_argument);
  EXPECT_NO_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kGeneral));
  Q = Eigen::Vector4d(1, 1, 0, -1).asDiagonal();  // a cylinder is not a cone or a plane
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kCone), std::invalid_argument);
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kPlane), std::invalid_argument);
  Q = Eigen::Vector4d(1, 0, 0, -1).asDiagonal();  // x^2 = 1: two parallel planes
  EXPECT_THROW(QuadricModel::fromMatrix(Q, QuadricClass::kPlane), std::invalid_argument);
}

TEST(QuadricModel, ConstructorValidates) {
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  EXPECT_THROW(QuadricModel(QuadricClass::kSphere, I, Eigen::Vector3d(1, 2, 1)),
               std::invalid_argument);
  EXPECT_THROW(QuadricModel(QuadricClass::kCylinder, I, Eigen::Vector3d(2, 2, 3)),
               std::invalid_argument);
  EXPECT_THROW(QuadricModel(QuadricClass::kSphere, I, Eigen::Vector3d(-1, -1, -1)),
               std::invalid_argument);
  EXPECT_THROW(
      QuadricModel(QuadricClass::kCone, I, Eigen::Vector3d(1, 1, 1), Eigen::Vector4d(1, 1, 1, -1)),
      std::invalid_argument);
  EXPECT_THROW(QuadricModel(QuadricClass::kGeneral, I, Eigen::Vector3d(1, 1, 1),
                            Eigen::Vector4d(1, 0.5, 1, -1)),
               std::invalid_argument);
  EXPECT_NO_THROW(QuadricModel(QuadricClass::kCylinder, I, Eigen::Vector3d(2, 2, 1)));
}

TEST(QuadricPlus, AScaleStepThroughZeroStopsAboveZero) {
  // A cone of opening 0.06: a fused estimate once asked it for -0.06. S stays in D^3, so the
  // result is still a cone, and every check of the class (the constructor's) holds.
  const QuadricModel cone(QuadricClass::kCone, Eigen::Isometry3d::Identity(),
                          Eigen::Vector3d(0.06, 0.06, 1.0));
  Vector9d delta = Vector9d::Zero();
  delta.tail<3>() << -0.12, -0.12, 0.0;
  const QuadricModel stepped = cone.plus(delta);
  EXPECT_NEAR(stepped.scale().x(), 0.06 * QuadricModel::kMinScaleStepFraction, 1e-15);
  EXPECT_EQ(stepped.scale().y(), stepped.scale().x());
  EXPECT_EQ(stepped.scale().z(), 1.0);
  EXPECT_NO_THROW(
      QuadricModel(stepped.quadricClass(), stepped.pose(), stepped.scale(), stepped.signature()));
  // Inside D^3 the step is the sum, and minus() undoes it.
  delta.tail<3>() << -0.02, -0.02, 0.0;
  EXPECT_LT((cone.plus(delta).minus(cone) - delta).norm(), 1e-15);
}

}  // namespace
}  // namespace quadric_slam
