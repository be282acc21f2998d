#include "quadric_slam/geometry/se3.h"

#include <cmath>

namespace quadric_slam {

namespace {
// Below this rotation angle the closed forms cancel badly; Taylor series are used instead.
constexpr double kSmallAngle = 1e-1;
}  // namespace

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// eq. 12
Eigen::Matrix4d hat(const Vector6d& xi) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m.topLeftCorner<3, 3>() = skew(xi.tail<3>());
  m.topRightCorner<3, 1>() = xi.head<3>();
  return m;
}

// eq. 15
Vector6d vee(const Eigen::Matrix4d& m) {
  Vector6d xi;
  xi << m(0, 3), m(1, 3), m(2, 3), m(2, 1), m(0, 2), m(1, 0);
  return xi;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < 1e-12)
    return Eigen::Matrix3d::Identity() + skew(phi);
  return Eigen::AngleAxisd(theta, phi / theta).toRotationMatrix();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  const double vnorm = q.vec().norm();
  if (vnorm < 1e-12)
    return 2.0 * q.vec() / q.w();
  double w = q.w();
  Eigen::Vector3d v = q.vec();
  if (w < 0) {  // keep |phi| <= pi
    w = -w;
    v = -v;
  }
  const double theta = 2.0 * std::atan2(vnorm, w);
  return theta / vnorm * v;
}

Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& phi) {
  const double t = phi.norm();
  const Eigen::Matrix3d P = skew(phi);
  double a, b;  // (1 - cos t)/t^2, (t - sin t)/t^3
  if (t < kSmallAngle) {
    const double t2 = t * t;
    a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  } else {
    a = (1.0 - std::cos(t)) / (t * t);
    b = (t - std::sin(t)) / (t * t * t);
  }
  return Eigen::Matrix3d::Identity() + a * P + b * P * P;
}

Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& phi) {
  const double t = phi.norm();
  const Eigen::Matrix3d P = skew(phi);
  double c;  // 1/t^2 - (1 + cos t) / (2 t sin t)
  if (t < kSmallAngle) {
    const double t2 = t * t;
    c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  } else {
    c = 1.0 / (t * t) - (1.0 + std::cos(t)) / (2.0 * t * std::sin(t));
  }
  return Eigen::Matrix3d::Identity() - 0.5 * P + c * P * P;
}

Eigen::Isometry3d expSE3(const Vector6d& xi) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSO3(xi.tail<3>());
  T.translation() = leftJacobianSO3(xi.tail<3>()) * xi.head<3>();
  return T;
}

Vector6d logSE3(const Eigen::Isometry3d& T) {
  Vector6d xi;
  const Eigen::Vector3d phi = logSO3(T.linear());
  xi.tail<3>() = phi;
  xi.head<3>() = leftJacobianInverseSO3(phi) * T.translation();
  return xi;
}

Matrix6d adjointSE3(const Eigen::Isometry3d& T) {
  Matrix6d ad = Matrix6d::Zero();
  const Eigen::Matrix3d R = T.linear();
  ad.topLeftCorner<3, 3>() = R;
  ad.bottomRightCorner<3, 3>() = R;
  ad.topRightCorner<3, 3>() = skew(T.translation()) * R;
  return ad;
}

namespace {
// Barfoot's Q(rho, phi), the top-right block of the SE(3) left Jacobian.
Eigen::Matrix3d barfootQ(const Eigen::Vector3d& rho, const Eigen::Vector3d& phi) {
  const double t = phi.norm();
  const Eigen::Matrix3d P = skew(phi);
  const Eigen::Matrix3d Rh = skew(rho);
  // c1 = (t - sin t)/t^3, c2 = (t^2 + 2 cos t - 2)/(2 t^4), c3 = (2t - 3 sin t + t cos t)/(2 t^5)
  double c1, c2, c3;
  if (t < kSmallAngle) {
    const double t2 = t * t;
    c1 = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
    c2 = 1.0 / 24.0 - t2 / 720.0 + t2 * t2 / 40320.0;
    c3 = 1.0 / 120.0 - t2 / 2520.0 + t2 * t2 / 120960.0;
  } else {
    const double t2 = t * t, t3 = t2 * t;
    c1 = (t - std::sin(t)) / t3;
    c2 = (t2 + 2.0 * std::cos(t) - 2.0) / (2.0 * t2 * t2);
    c3 = (2.0 * t - 3.0 * std::sin(t) + t * std::cos(t)) / (2.0 * t3 * t2);
  }
  const Eigen::Matrix3d PR = P * Rh, RP = Rh * P, PRP = P * Rh * P;
  return 0.5 * Rh + c1 * (PR + RP + PRP) + c2 * (P * PR + RP * P - 3.0 * PRP) +
         c3 * (PRP * P + P * PRP);
}
}  // namespace

Matrix6d leftJacobianSE3(const Vector6d& xi) {
  Matrix6d J = Matrix6d::Zero();
  const Eigen::Matrix3d Jl = leftJacobianSO3(xi.tail<3>());
  J.topLeftCorner<3, 3>() = Jl;
  J.bottomRightCorner<3, 3>() = Jl;
  J.topRightCorner<3, 3>() = barfootQ(xi.head<3>(), xi.tail<3>());
  return J;
}

Matrix6d leftJacobianInverseSE3(const Vector6d& xi) {
  Matrix6d J = Matrix6d::Zero();
  const Eigen::Matrix3d Jinv = leftJacobianInverseSO3(xi.tail<3>());
  J.topLeftCorner<3, 3>() = Jinv;
  J.bottomRightCorner<3, 3>() = Jinv;
  J.topRightCorner<3, 3>() = -Jinv * barfootQ(xi.head<3>(), xi.tail<3>()) * Jinv;
  return J;
}

// J_r(xi) = J_l(-xi)
Matrix6d rightJacobianInverseSE3(const Vector6d& xi) {
  return leftJacobianInverseSE3(-xi);
}

Eigen::Isometry3d plus(const Eigen::Isometry3d& T, const Vector6d& xi) {
  return T * expSE3(xi);
}

// eq. 14
Vector6d minus(const Eigen::Isometry3d& T, const Eigen::Isometry3d& T_prime) {
  return logSE3(T_prime.inverse() * T);
}

// eq. 11
Eigen::Isometry3d plusLeft(const Eigen::Isometry3d& T, const Vector6d& xi) {
  return expSE3(xi) * T;
}

Vector6d minusLeft(const Eigen::Isometry3d& T, const Eigen::Isometry3d& T_prime) {
  return logSE3(T * T_prime.inverse());
}

Eigen::Isometry3d makeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace quadric_slam
