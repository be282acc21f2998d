// Ceres manifolds for SE(3) camera poses and for quadrics of each class (Table II), over flat
// ambient parameter blocks, with analytic Plus/Minus Jacobians.
//
// Ambient layouts (documented, shared with mapping/factors.h):
//   pose block    (7):  [tx, ty, tz, qx, qy, qz, qw]                 T_world_frame, unit quaternion
//   quadric block (10): [tx, ty, tz, qx, qy, qz, qw, alpha, beta, gamma]   T_world_quadric and
//   diag(S)
// Tangent spaces: pose [rho; phi] (6) applied in the body frame, x [+] xi = x exp(xi^) (se3.h);
// quadric: the class's minimal vector (Table II, k = 3..9), mapped into [rho; phi; s] by the
// class's B (quadric_classes.h): x [+] d = (T exp((B d)_pose^), S + D((B d)_scale)) (eqs. 9-17),
// Minus(y, x) = B^+ [log(T_x^-1 T_y)^vee; s_y - s_x]. The quadric Plus keeps S positive: a step
// that would take a scale below a thousandth of its value stops there.
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/quadric_class.h"

namespace quadric_slam {

constexpr int kPoseParameterSize = 7;
constexpr int kPoseTangentSize = 6;
constexpr int kQuadricParameterSize = 10;

void poseToParameters(const Eigen::Isometry3d& T, double* parameters);
Eigen::Isometry3d poseFromParameters(const double* parameters);
void quadricToParameters(const QuadricModel& quadric, double* parameters);
// Throws std::invalid_argument (from QuadricModel) when the block holds an invalid quadric.
QuadricModel quadricFromParameters(const double* parameters, QuadricClass quadric_class,
                                   const Eigen::Vector4d& signature);

// d(ambient)/d(tangent) of the pose Plus at delta = 0 (7 x 6) and a left inverse of it, the
// Minus Jacobian at y = x (6 x 7); (Minus * Plus = I).
Eigen::Matrix<double, 7, 6> posePlusJacobian(const double* x);
Eigen::Matrix<double, 6, 7> poseMinusJacobian(const double* x);
// The same for the general quadric tangent [rho; phi; s] (10 x 9 and 9 x 10).
Eigen::Matrix<double, 10, 9> quadricGeneralPlusJacobian(const double* x);
Eigen::Matrix<double, 9, 10> quadricGeneralMinusJacobian(const double* x);

class PoseManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseParameterSize; }
  int TangentSize() const override { return kPoseTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

class QuadricManifold : public ceres::Manifold {
 public:
  explicit QuadricManifold(QuadricClass quadric_class);
  int AmbientSize() const override { return kQuadricParameterSize; }
  int TangentSize() const override { return static_cast<int>(basis_.cols()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
  QuadricClass quadricClass() const { return class_; }

 private:
  QuadricClass class_;
  Eigen::Matrix<double, 9, Eigen::Dynamic> basis_;       // B (9 x k)
  Eigen::Matrix<double, Eigen::Dynamic, 9> basis_pinv_;  // B^+ (k x 9)
};

}  // namespace quadric_slam
