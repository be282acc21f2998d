// SE(3) and SO(3) Lie-group tools in the paper's twist convention xi = [rho; phi] (translation part
// first, eqs. 12-13), and the [+]/[-] operators of SE(3) x D^3 (eqs. 10-17).
//
// Choice of [+]/[-] (documented deviation): the paper writes T [+] xi = exp(xi^) T (eq. 11, a LEFT
// perturbation) and T [-] T' = log(T'^-1 T)^vee (eq. 14, the inverse of a RIGHT perturbation); as
// written they are not inverses of each other. The quadric pose operators here use the RIGHT
// (body-frame) pair
//     T [+] xi = T exp(xi^),      T [-] T' = log(T'^-1 T)^vee          (eq. 14 exactly)
// so that (T [+] d) [-] T = d holds exactly. This is eq. 11 applied to the matrix that eq. 4
// actually multiplies, T_QW = T_WQ^-1, with the twist negated: (T_WQ exp(xi))^-1 = exp(-xi) T_QW.
// The body-frame choice is what makes Table II work: its selection matrices name QUADRIC-frame
// axes (plane normal = quadric x, cylinder/cone axis = quadric z), which are the invariant
// directions only when xi is expressed in the quadric frame. The left pair (plusLeft/minusLeft)
// is provided too for completeness.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace quadric_slam {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// phi^x, the skew-symmetric matrix of eq. 13.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);
// xi^ (eq. 12) and its inverse ^vee (eq. 15).
Eigen::Matrix4d hat(const Vector6d& xi);
Vector6d vee(const Eigen::Matrix4d& xi_hat);

// SO(3) exponential/logarithm (rotation vector <-> rotation matrix); log returns |phi| <= pi.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi);
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);
// SO(3) left Jacobian J_l(phi) and its inverse; J_r(phi) = J_l(-phi).
Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& phi);
Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& phi);

// SE(3) exponential/logarithm with xi = [rho; phi]: exp(xi^) = [exp(phi^x), J_l(phi) rho; 0, 1].
Eigen::Isometry3d expSE3(const Vector6d& xi);
Vector6d logSE3(const Eigen::Isometry3d& T);
// Adjoint: T exp(xi^) T^-1 = exp((Ad_T xi)^), Ad_T = [R, t^x R; 0, R].
Matrix6d adjointSE3(const Eigen::Isometry3d& T);
// SE(3) left Jacobian and inverses (Barfoot, State Estimation for Robotics, 7.85-7.95):
// log(exp(d^) exp(xi^)) ~ xi + J_l^-1(xi) d,  log(exp(xi^) exp(d^)) ~ xi + J_r^-1(xi) d.
Matrix6d leftJacobianSE3(const Vector6d& xi);
Matrix6d leftJacobianInverseSE3(const Vector6d& xi);
Matrix6d rightJacobianInverseSE3(const Vector6d& xi);

// Body-frame [+]/[-] used for quadric and camera poses (see the header comment).
Eigen::Isometry3d plus(const Eigen::Isometry3d& T, const Vector6d& xi);        // T exp(xi^)
Vector6d minus(const Eigen::Isometry3d& T, const Eigen::Isometry3d& T_prime);  // eq. 14
// World-frame pair: exp(xi^) T (eq. 11 as written) and its exact inverse log(T T'^-1)^vee.
Eigen::Isometry3d plusLeft(const Eigen::Isometry3d& T, const Vector6d& xi);
Vector6d minusLeft(const Eigen::Isometry3d& T, const Eigen::Isometry3d& T_prime);

// Proper rigid transform from a rotation matrix that may carry round-off (re-orthonormalised).
Eigen::Isometry3d makeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

}  // namespace quadric_slam
