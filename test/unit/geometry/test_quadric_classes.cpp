#include <gtest/gtest.h>

#include <algorithm>

#include "quadric_slam/geometry/quadric_classes.h"

namespace quadric_slam {
namespace {

// Table II's minimal parameters as indices into [rho1 rho2 rho3 phi1 phi2 phi3 alpha beta gamma]
// (scale columns listed separately).
void expectBasis(QuadricClass c, const std::vector<int>& pose_rows,
                 const std::vector<Eigen::Vector3d>& scale_columns) {
  const QuadricClassDefinition& def = classDefinition(c);
  ASSERT_EQ(def.basis.cols(), static_cast<int>(pose_rows.size() + scale_columns.size()));
  EXPECT_EQ(def.minimal_dimension, minimalDimension(c));
  EXPECT_EQ(def.signature, defaultSignature(c));
  int col = 0;
  for (int row : pose_rows) {
    Eigen::Matrix<double, 9, 1> expected = Eigen::Matrix<double, 9, 1>::Zero();
    expected[row] = 1;
    EXPECT_EQ(def.basis.col(col++), expected) << toString(c);
  }
  for (const Eigen::Vector3d& s : scale_columns) {
    Eigen::Matrix<double, 9, 1> expected = Eigen::Matrix<double, 9, 1>::Zero();
    expected.tail<3>() = s;
    EXPECT_EQ(def.basis.col(col++), expected) << toString(c);
  }
  // The dropped pose directions are exactly the complement of the kept ones.
  for (int i = 0; i < 6; ++i) {
    const bool kept = std::count(pose_rows.begin(), pose_rows.end(), i) > 0;
    const bool dropped =
        std::count(def.dropped_pose_indices.begin(), def.dropped_pose_indices.end(), i) > 0;
    EXPECT_NE(kept, dropped) << toString(c) << " index " << i;
  }
  const Eigen::MatrixXd pinv = basisPseudoInverse(c);
  EXPECT_LT((pinv * def.basis - Eigen::MatrixXd::Identity(def.basis.cols(), def.basis.cols()))
                .cwiseAbs()
                .maxCoeff(),
            1e-15);
}

TEST(QuadricClassTable, BasisFollowsTableTwo) {
  expectBasis(QuadricClass::kPlane, {0, 4, 5}, {});                                // rho1 phi2 phi3
  expectBasis(QuadricClass::kSphere, {0, 1, 2}, {Eigen::Vector3d(1, 1, 1)});       // rho, alpha
  expectBasis(QuadricClass::kCylinder, {0, 1, 3, 4}, {Eigen::Vector3d(1, 1, 0)});  // rho12 phi12 a
  expectBasis(QuadricClass::kCone, {0, 1, 2, 3, 4}, {Eigen::Vector3d(1, 1, 0)});   // rho phi12 a
  expectBasis(QuadricClass::kGeneral, {0, 1, 2, 3, 4, 5},
              {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()});
}

TEST(QuadricClassTable, ConstrainScaleAppliesTiesAndFixedValues) {
  EXPECT_EQ(constrainScale(QuadricClass::kSphere, Eigen::Vector3d(1, 2, 3)),
            Eigen::Vector3d(2, 2, 2));
  EXPECT_EQ(constrainScale(QuadricClass::kCylinder, Eigen::Vector3d(1, 3, 7)),
            Eigen::Vector3d(2, 2, 1));
  EXPECT_EQ(constrainScale(QuadricClass::kCone, Eigen::Vector3d(4, 2, 0.5)),
            Eigen::Vector3d(3, 3, 1));
  EXPECT_EQ(constrainScale(QuadricClass::kPlane, Eigen::Vector3d(4, 2, 0.5)),
            Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(constrainScale(QuadricClass::kGeneral, Eigen::Vector3d(4, 2, 0.5)),
            Eigen::Vector3d(4, 2, 0.5));
}

}  // namespace
}  // namespace quadric_slam
