#include "quadric_slam/geometry/quadric_classes.h"

#include <Eigen/LU>
#include <array>
#include <stdexcept>

namespace quadric_slam {

namespace {

// Indices into the general tangent [rho1 rho2 rho3 phi1 phi2 phi3 alpha beta gamma].
enum : int { kRho1 = 0, kRho2, kRho3, kPhi1, kPhi2, kPhi3, kAlpha, kBeta, kGamma };

// Builds B from the kept pose indices and the scale columns (each a 3-vector over alpha..gamma).
Matrix9Xd makeBasis(const std::vector<int>& pose_columns,
                    const std::vector<Eigen::Vector3d>& scale_columns) {
  Matrix9Xd B = Matrix9Xd::Zero(9, pose_columns.size() + scale_columns.size());
  int col = 0;
  for (int index : pose_columns)
    B(index, col++) = 1.0;
  for (const Eigen::Vector3d& s : scale_columns)
    B.block<3, 1>(kAlpha, col++) = s;
  return B;
}

std::array<QuadricClassDefinition, 5> makeTable() {
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  std::array<QuadricClassDefinition, 5> t;
  // Table II, row "Plane": (rho1, phi2, phi3), S = I fixed.
  t[0] = {QuadricClass::kPlane,
          Eigen::Vector4d(1, 0, 0, 0),
          3,
          makeBasis({kRho1, kPhi2, kPhi3}, {}),
          {kRho2, kRho3, kPhi1},
          SymmetryGroup::kInPlaneMotions,
          Eigen::Vector3d::UnitX(),
          Eigen::Vector3d(1, 1, 1),
          Eigen::Vector3d(1, 1, 1),
          Eigen::Matrix<double, Eigen::Dynamic, 9>()};
  // Table II, row "Sphere": (rho1, rho2, rho3, alpha), alpha = beta = gamma.
  t[1] = {QuadricClass::kSphere,
          Eigen::Vector4d(1, 1, 1, -1),
          4,
          makeBasis({kRho1, kRho2, kRho3}, {Eigen::Vector3d(1, 1, 1)}),
          {kPhi1, kPhi2, kPhi3},
          SymmetryGroup::kRotations,
          none,
          none,
          none,
          Eigen::Matrix<double, Eigen::Dynamic, 9>()};
  // Table II, row "Circular Cylinder": (rho1, rho2, phi1, phi2, alpha), S = (alpha, alpha, 1).
  t[2] = {QuadricClass::kCylinder,
          Eigen::Vector4d(1, 1, 0, -1),
          5,
          makeBasis({kRho1, kRho2, kPhi1, kPhi2}, {Eigen::Vector3d(1, 1, 0)}),
          {kRho3, kPhi3},
          SymmetryGroup::kAxialScrew,
          Eigen::Vector3d::UnitZ(),
          Eigen::Vector3d(0, 0, 1),
          Eigen::Vector3d(0, 0, 1),
          Eigen::Matrix<double, Eigen::Dynamic, 9>()};
  // Table II, row "Circular Cone": (rho1, rho2, rho3, phi1, phi2, alpha), S = (alpha, alpha, 1).
  t[3] = {QuadricClass::kCone,
          Eigen::Vector4d(1, 1, -1, 0),
          6,
          makeBasis({kRho1, kRho2, kRho3, kPhi1, kPhi2}, {Eigen::Vector3d(1, 1, 0)}),
          {kPhi3},
          SymmetryGroup::kAxialRotation,
          Eigen::Vector3d::UnitZ(),
          Eigen::Vector3d(0, 0, 1),
          Eigen::Vector3d(0, 0, 1),
          Eigen::Matrix<double, Eigen::Dynamic, 9>()};
  // Table II, row "General": all nine.
  t[4] = {QuadricClass::kGeneral,
          Eigen::Vector4d(1, 1, 1, -1),
          9,
          makeBasis({kRho1, kRho2, kRho3, kPhi1, kPhi2, kPhi3},
                    {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()}),
          {},
          SymmetryGroup::kNone,
          none,
          none,
          none,
          Eigen::Matrix<double, Eigen::Dynamic, 9>()};
  for (QuadricClassDefinition& def : t)
    def.basis_pinv = (def.basis.transpose() * def.basis).inverse() * def.basis.transpose();
  return t;
}

}  // namespace

const QuadricClassDefinition& classDefinition(QuadricClass quadric_class) {
  static const std::array<QuadricClassDefinition, 5> table = makeTable();
  const int index = static_cast<int>(quadric_class);
  if (index < 0 || index >= static_cast<int>(table.size()))
    throw std::invalid_argument("classDefinition: invalid QuadricClass " + std::to_string(index));
  return table[index];
}

const Eigen::Matrix<double, Eigen::Dynamic, 9>& basisPseudoInverse(QuadricClass quadric_class) {
  return classDefinition(quadric_class).basis_pinv;
}

Eigen::Vector3d constrainScale(QuadricClass quadric_class, const Eigen::Vector3d& scale) {
  const QuadricClassDefinition& def = classDefinition(quadric_class);
  // Project onto the span of the scale columns, then overwrite the fixed entries.
  const Eigen::MatrixXd Bs = def.basis.bottomRows<3>();
  Eigen::Vector3d free = Eigen::Vector3d::Zero();
  for (int c = 0; c < Bs.cols(); ++c) {
    const Eigen::Vector3d col = Bs.col(c);
    if (col.squaredNorm() > 0)
      free += col * (col.dot(scale) / col.squaredNorm());
  }
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i)
    out[i] = def.fixed_scale_mask[i] > 0 ? def.fixed_scale_value[i] : free[i];
  return out;
}

}  // namespace quadric_slam
