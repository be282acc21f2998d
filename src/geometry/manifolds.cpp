#include "quadric_slam/geometry/manifolds.h"

#include <algorithm>

#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {

namespace {

using RowMajor76 = Eigen::Matrix<double, 7, 6, Eigen::RowMajor>;
using RowMajor67 = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;

Eigen::Quaterniond quaternionAt(const double* x) {
  return Eigen::Quaterniond(x[6], x[3], x[4], x[5]).normalized();
}

// x [+] xi = x exp(xi^) on the 7-vector layout (first six entries of `delta`).
void posePlus(const double* x, const double* delta, double* out) {
  Vector6d xi;
  for (int i = 0; i < 6; ++i)
    xi[i] = delta[i];
  poseToParameters(plus(poseFromParameters(x), xi), out);
}

Vector6d poseMinus(const double* y, const double* x) {
  return minus(poseFromParameters(y), poseFromParameters(x));  // eq. 14
}

}  // namespace

void poseToParameters(const Eigen::Isometry3d& T, double* p) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(T.linear()).normalized();
  p[0] = T.translation().x();
  p[1] = T.translation().y();
  p[2] = T.translation().z();
  p[3] = q.x();
  p[4] = q.y();
  p[5] = q.z();
  p[6] = q.w();
}

Eigen::Isometry3d poseFromParameters(const double* p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = quaternionAt(p).toRotationMatrix();
  T.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return T;
}

void quadricToParameters(const QuadricModel& quadric, double* p) {
  poseToParameters(quadric.pose(), p);
  for (int i = 0; i < 3; ++i)
    p[7 + i] = quadric.scale()[i];
}

QuadricModel quadricFromParameters(const double* p, QuadricClass quadric_class,
                                   const Eigen::Vector4d& signature) {
  return QuadricModel(quadric_class, poseFromParameters(p), Eigen::Vector3d(p[7], p[8], p[9]),
                      signature);
}

Eigen::Matrix<double, 7, 6> posePlusJacobian(const double* x) {
  const Eigen::Quaterniond q = quaternionAt(x);
  const Eigen::Vector3d v = q.vec();
  Eigen::Matrix<double, 7, 6> J = Eigen::Matrix<double, 7, 6>::Zero();
  J.block<3, 3>(0, 0) = q.toRotationMatrix();  // t + R rho
  // q (x) [phi/2; 1]: d vec/d phi = (w I + v^x)/2, d w/d phi = -v^T/2
  J.block<3, 3>(3, 3) = 0.5 * (q.w() * Eigen::Matrix3d::Identity() + skew(v));
  J.block<1, 3>(6, 3) = -0.5 * v.transpose();
  return J;
}

Eigen::Matrix<double, 6, 7> poseMinusJacobian(const double* x) {
  const Eigen::Quaterniond q = quaternionAt(x);
  const Eigen::Vector3d v = q.vec();
  Eigen::Matrix<double, 6, 7> J = Eigen::Matrix<double, 6, 7>::Zero();
  J.block<3, 3>(0, 0) = q.toRotationMatrix().transpose();  // rho = R^T (t_y - t_x)
  // phi = 2 vec(q_x^-1 (x) q_y)
  J.block<3, 3>(3, 3) = 2.0 * (q.w() * Eigen::Matrix3d::Identity() - skew(v));
  J.block<3, 1>(3, 6) = -2.0 * v;
  return J;
}

Eigen::Matrix<double, 10, 9> quadricGeneralPlusJacobian(const double* x) {
  Eigen::Matrix<double, 10, 9> J = Eigen::Matrix<double, 10, 9>::Zero();
  J.topLeftCorner<7, 6>() = posePlusJacobian(x);
  J.bottomRightCorner<3, 3>().setIdentity();
  return J;
}

Eigen::Matrix<double, 9, 10> quadricGeneralMinusJacobian(const double* x) {
  Eigen::Matrix<double, 9, 10> J = Eigen::Matrix<double, 9, 10>::Zero();
  J.topLeftCorner<6, 7>() = poseMinusJacobian(x);
  J.bottomRightCorner<3, 3>().setIdentity();
  return J;
}

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  posePlus(x, delta, x_plus_delta);
  return true;
}

bool PoseManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<RowMajor76>{jacobian} = posePlusJacobian(x);
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<Vector6d>{y_minus_x} = poseMinus(y, x);
  return true;
}

bool PoseManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<RowMajor67>{jacobian} = poseMinusJacobian(x);
  return true;
}

QuadricManifold::QuadricManifold(QuadricClass quadric_class)
    : class_(quadric_class),
      basis_(classDefinition(quadric_class).basis),
      basis_pinv_(basisPseudoInverse(quadric_class)) {}

// eqs. 9, 11, 16 through Table II's B
bool QuadricManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::VectorXd> d(delta, basis_.cols());
  const Vector9d general = basis_ * d;
  posePlus(x, general.data(), x_plus_delta);
  // S lives in D^3, the positive diagonal matrices: as QuadricModel::plus, a step that would take a
  // scale through zero stops at kMinScaleStepFraction of it. The map is continuous and the
  // identity near the optimum (the Jacobians at delta = 0 are unchanged); refusing the step
  // instead (returning false) makes Ceres end the whole solve when its projected-gradient test,
  // Plus(x, -gradient), fails.
  for (int i = 0; i < 3; ++i)
    x_plus_delta[7 + i] = QuadricModel::stepScale(x[7 + i], general[6 + i]);
  return true;
}

bool QuadricManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 10, Eigen::Dynamic, Eigen::RowMajor>>(
      jacobian, 10, basis_.cols()) = quadricGeneralPlusJacobian(x) * basis_;
  return true;
}

// eqs. 10, 14, 17 through B^+
bool QuadricManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Vector9d general;
  general.head<6>() = poseMinus(y, x);
  for (int i = 0; i < 3; ++i)
    general[6 + i] = y[7 + i] - x[7 + i];
  Eigen::Map<Eigen::VectorXd>(y_minus_x, basis_.cols()) = basis_pinv_ * general;
  return true;
}

bool QuadricManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 10, Eigen::RowMajor>>(
      jacobian, basis_.cols(), 10) = basis_pinv_ * quadricGeneralMinusJacobian(x);
  return true;
}

}  // namespace quadric_slam
