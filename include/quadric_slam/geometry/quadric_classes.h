// Table II in one place: for each quadric class, how its minimal vector maps into the general
// tangent delta_pi = [rho; phi; s] (9, eq. 10), which pose directions are the class's symmetries,
// and which discrete frame flips leave the surface unchanged. Every other file (manifolds, factors,
// symmetry canonicalisation) reads these definitions instead of switching on the class.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "quadric_slam/geometry/quadric_class.h"

namespace quadric_slam {

using Matrix9Xd = Eigen::Matrix<double, 9, Eigen::Dynamic>;

// The continuous symmetry group of a class, acting on the quadric frame by right multiplication
// T_WQ -> T_WQ G (G in the quadric frame). Its generators are the tangent directions the class
// drops.
enum class SymmetryGroup {
  kNone,            // general: only the discrete flips
  kRotations,       // sphere: SO(3) about the centre (drops phi1..3)
  kAxialScrew,      // cylinder: rotation about and translation along quadric z (drops rho3, phi3)
  kAxialRotation,   // cone: rotation about quadric z through the apex (drops phi3)
  kInPlaneMotions,  // plane: SE(2) of the quadric y-z plane (drops rho2, rho3, phi1)
};

struct QuadricClassDefinition {
  QuadricClass quadric_class;
  Eigen::Vector4d signature;  // eq. 4 (for kGeneral: the ellipsoid, per quadric otherwise)
  int minimal_dimension;      // Table II: 3, 4, 5, 6, 9
  // B (9 x k): general tangent [rho; phi; s] = B * minimal vector. Pose columns are unit vectors
  // (Table II's d xi / d xi_Q); scale columns tie entries: sphere (1,1,1), cylinder/cone (1,1,0).
  Matrix9Xd basis;
  // Pose tangent indices (0..5 into [rho; phi]) that are NOT in the minimal vector: the generators
  // of the class's continuous symmetry group.
  std::vector<int> dropped_pose_indices;
  SymmetryGroup symmetry;
  // Unit axis used for the discrete flip and swing-twist canonicalisation: quadric z for cylinder
  // and cone, quadric x for the plane (its normal); unused for sphere and general.
  Eigen::Vector3d symmetry_axis;
  // Scale entries fixed by the class (plane (1,1,1); gamma = 1 for cylinder and cone): mask and
  // value. Free entries are estimated through the scale columns of `basis`.
  Eigen::Vector3d fixed_scale_mask;
  Eigen::Vector3d fixed_scale_value;
  // B^+ = (B^T B)^-1 B^T (k x 9), precomputed.
  Eigen::Matrix<double, Eigen::Dynamic, 9> basis_pinv;
};

// The definition of a class (a static table; never throws for a valid enum value).
const QuadricClassDefinition& classDefinition(QuadricClass quadric_class);

// Pseudo-inverse B^+ = (B^T B)^-1 B^T (k x 9): minimal vector of a general tangent vector. For the
// orthonormal pose columns it selects; for the tied scale columns it averages.
const Eigen::Matrix<double, Eigen::Dynamic, 9>& basisPseudoInverse(QuadricClass quadric_class);

// Scale diagonal (alpha, beta, gamma) obeying the class's ties and fixed values, from any input:
// tied entries are averaged, fixed entries overwritten.
Eigen::Vector3d constrainScale(QuadricClass quadric_class, const Eigen::Vector3d& scale);

}  // namespace quadric_slam
