#include "quadric_slam/geometry/symmetry.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace quadric_slam {

namespace {

// Rotation by pi about a unit axis (an axis flip of the canonical quadric).
Eigen::Matrix3d halfTurn(const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(M_PI, axis).toRotationMatrix();
}

// Twist part of R about a unit axis a, with R = R_twist * R_swing (swing axis orthogonal to a).
Eigen::Matrix3d twistAbout(const Eigen::Matrix3d& R, const Eigen::Vector3d& a) {
  const Eigen::Quaterniond q(R);
  const double along = q.vec().dot(a);
  const double n = std::hypot(q.w(), along);
  if (n < 1e-12)  // a half-turn swing: the twist is undefined; any choice is exact
    return Eigen::Matrix3d::Identity();
  const Eigen::Quaterniond twist(q.w() / n, along / n * a.x(), along / n * a.y(),
                                 along / n * a.z());
  return twist.toRotationMatrix();
}

// |R| rounded when R is a signed permutation matrix (a relabelling of the axes), else I.
Eigen::Matrix3d axisPermutationOf(const Eigen::Matrix3d& R) {
  const Eigen::Matrix3d A = R.cwiseAbs();
  const Eigen::Matrix3d rounded = A.array().round().matrix();
  const bool permutation = (A - rounded).cwiseAbs().maxCoeff() < 1e-9 &&
                           (rounded.rowwise().sum().array() == 1.0).all() &&
                           (rounded.colwise().sum().array() == 1.0).all();
  return permutation ? rounded : Eigen::Matrix3d::Identity();
}

}  // namespace

std::vector<Eigen::Matrix3d> generalAxisRelabellings(const Eigen::Vector4d& signature) {
  std::vector<Eigen::Matrix3d> out;
  std::array<int, 3> order = {0, 1, 2};
  do {
    // Column j of P is +-e_order[j]: new axis j = old axis order[j] (same signature entry).
    if (signature[order[0]] != signature[0] || signature[order[1]] != signature[1] ||
        signature[order[2]] != signature[2])
      continue;
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
      for (int j = 0; j < 3; ++j)
        P(order[j], j) = (signs >> j) & 1 ? -1.0 : 1.0;
      if (P.determinant() > 0)
        out.push_back(P);
    }
  } while (std::next_permutation(order.begin(), order.end()));
  return out;  // std::next_permutation starts at the identity order, signs 0 first
}

Eigen::Isometry3d symmetryAlignment(const QuadricModel& z, const Eigen::Isometry3d& T_z_h) {
  if (z.quadricClass() != QuadricClass::kGeneral)
    return symmetryAlignment(z.quadricClass(), T_z_h);
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  double best = -1e9;
  for (const Eigen::Matrix3d& P : generalAxisRelabellings(z.signature())) {
    const double trace = (P.transpose() * T_z_h.linear()).trace();
    if (trace > best + 1e-12) {
      best = trace;
      G.linear() = P;
    }
  }
  return G;
}

QuadricModel withSymmetry(const QuadricModel& z, const Eigen::Isometry3d& G) {
  Eigen::Vector3d scale = z.scale();
  if (z.quadricClass() == QuadricClass::kGeneral)
    scale = axisPermutationOf(G.linear()).transpose() * z.scale();
  return QuadricModel(z.quadricClass(), z.pose() * G, scale, z.signature());
}

Eigen::Isometry3d symmetryAlignment(QuadricClass quadric_class, const Eigen::Isometry3d& T_z_h) {
  const QuadricClassDefinition& def = classDefinition(quadric_class);
  const Eigen::Matrix3d R_D = T_z_h.linear();
  const Eigen::Vector3d t_D = T_z_h.translation();
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  switch (def.symmetry) {
    case SymmetryGroup::kNone: {
      // Discrete flips only: the half-turn about a quadric axis closest to R_D.
      const std::array<Eigen::Matrix3d, 4> flips = {
          Eigen::Matrix3d::Identity(), halfTurn(Eigen::Vector3d::UnitX()),
          halfTurn(Eigen::Vector3d::UnitY()), halfTurn(Eigen::Vector3d::UnitZ())};
      double best = -1e9;
      for (const Eigen::Matrix3d& F : flips) {
        const double trace = (F.transpose() * R_D).trace();
        if (trace > best + 1e-12) {
          best = trace;
          G.linear() = F;
        }
      }
      return G;
    }
    case SymmetryGroup::kRotations:
      G.linear() = R_D;  // log(G^-1 D) is a pure translation
      return G;
    default:
      break;
  }
  // Axial classes (cylinder, cone) and the plane: flip, then remove the twist about the axis.
  const Eigen::Vector3d a = def.symmetry_axis;
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  if ((R_D * a).dot(a) < 0) {
    // plane: half-turn about quadric z (x -> -x); cylinder/cone: about quadric x (z -> -z)
    F = halfTurn(a.isApprox(Eigen::Vector3d::UnitX()) ? Eigen::Vector3d::UnitZ()
                                                      : Eigen::Vector3d::UnitX());
  }
  const Eigen::Matrix3d R1 = F.transpose() * R_D;
  const Eigen::Vector3d t1 = F.transpose() * t_D;
  const Eigen::Matrix3d R_twist = twistAbout(R1, a);
  const Eigen::Matrix3d R_swing = R_twist.transpose() * R1;
  const Eigen::Vector3d a_t = R_twist.transpose() * t1;  // translation before sliding
  Eigen::Vector3d slide = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d V_inv = leftJacobianInverseSO3(logSO3(R_swing));
  if (def.symmetry == SymmetryGroup::kAxialScrew) {
    // rho = V^-1 (a_t - s e_z); choose s with rho_3 = 0.
    const double s = (V_inv * a_t).z() / V_inv(2, 2);
    slide = s * Eigen::Vector3d::UnitZ();
  } else if (def.symmetry == SymmetryGroup::kInPlaneMotions) {
    // rho = V^-1 (a_t - (0, y, z)); choose y, z with rho_2 = rho_3 = 0.
    const Eigen::Vector2d yz = V_inv.bottomRightCorner<2, 2>().lu().solve((V_inv * a_t).tail<2>());
    slide = Eigen::Vector3d(0, yz.x(), yz.y());
  }
  Eigen::Isometry3d G_c = Eigen::Isometry3d::Identity();
  G_c.linear() = R_twist;
  G_c.translation() = R_twist * slide;  // G_c = (R_twist, 0) * (I, slide)
  Eigen::Isometry3d G_f = Eigen::Isometry3d::Identity();
  G_f.linear() = F;
  return G_f * G_c;
}

Matrix6d alignmentGeneratorRate(QuadricClass quadric_class, const Vector6d& e) {
  const QuadricClassDefinition& def = classDefinition(quadric_class);
  const int m = static_cast<int>(def.dropped_pose_indices.size());
  if (m == 0)
    return Matrix6d::Zero();
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(m, 6);
  for (int i = 0; i < m; ++i)
    P(i, def.dropped_pose_indices[i]) = 1.0;
  const Eigen::MatrixXd PJP = P * leftJacobianInverseSE3(e) * P.transpose();
  return P.transpose() * PJP.inverse() * P * rightJacobianInverseSE3(e);
}

Matrix6d alignedErrorJacobian(QuadricClass quadric_class, const Vector6d& e) {
  return rightJacobianInverseSE3(e) -
         leftJacobianInverseSE3(e) * alignmentGeneratorRate(quadric_class, e);
}

Matrix6d adSE3(const Vector6d& xi) {
  Matrix6d ad = Matrix6d::Zero();
  ad.topLeftCorner<3, 3>() = skew(xi.tail<3>());
  ad.bottomRightCorner<3, 3>() = skew(xi.tail<3>());
  ad.topRightCorner<3, 3>() = skew(xi.head<3>());
  return ad;
}

Eigen::MatrixXd minimalAdjoint(QuadricClass quadric_class, const Eigen::Isometry3d& G) {
  const Matrix9Xd& B = classDefinition(quadric_class).basis;
  Eigen::Matrix<double, 9, 9> ad = Eigen::Matrix<double, 9, 9>::Identity();
  ad.topLeftCorner<6, 6>() = adjointSE3(G);
  if (quadric_class == QuadricClass::kGeneral)
    ad.bottomRightCorner<3, 3>() = axisPermutationOf(G.linear());
  return basisPseudoInverse(quadric_class) * ad * B;
}

QuadricModel alignToReference(const QuadricModel& z, const QuadricModel& reference) {
  const Eigen::Isometry3d T_z_h = z.pose().inverse() * reference.pose();
  return withSymmetry(z, symmetryAlignment(z, T_z_h));
}

Eigen::VectorXd surfaceMinus(const QuadricModel& a, const QuadricModel& b) {
  if (a.quadricClass() != b.quadricClass())
    throw std::invalid_argument("surfaceMinus: classes differ (" + toString(a.quadricClass()) +
                                " vs " + toString(b.quadricClass()) + ")");
  return a.minusMinimal(alignToReference(b, a));
}

}  // namespace quadric_slam
