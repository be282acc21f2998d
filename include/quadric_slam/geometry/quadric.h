// A quadric surface in the paper's minimal representation pi = (T_WQ, S, sigma) (Section III):
// composition of the 4x4 matrix Q (eqs. 4-5), its decomposition back into (T, S, sigma), the
// [+]/[-] operators over SE(3) x D^3 (eqs. 10-17, body-frame convention, see se3.h) and the
// measurement prediction h(T_WC, pi) (eq. 19).
// Equation numbers count the paper's numbered equations in order: 2 z^T Q z = 0, 4 the
// decomposition of Q, 5 S = diag(alpha, beta, gamma), 9-10 compound [+]/[-], 11 SE(3) [+],
// 12-13 hat, 14 SE(3) [-], 15 vee, 16-17 D^3 [+]/[-], 18 noise, 19 h, 22 the cost.
// (msg/QuadricSurface.msg cites "eq. 5" for the composition: eqs. 4 and 5 together.)
#pragma once

#include <algorithm>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {

using Vector9d = Eigen::Matrix<double, 9, 1>;

// The paper's quadric pi = (T_WQ, S, sigma) with its class. (Named QuadricModel because the message
// quadric_slam::Quadric, a map landmark, lives in the same C++ namespace.)
class QuadricModel {
 public:
  // Unit sphere at the origin.
  QuadricModel();
  // Throws std::invalid_argument when a scale entry is not finite and positive, the signature is
  // not made of +1/-1/0 entries, or a non-general class is given a signature other than its own.
  // For the classes of revolution the scale must obey the class's ties (sphere alpha=beta=gamma,
  // cylinder/cone alpha=beta with gamma=1, plane (1,1,1)) to relative 1e-6.
  QuadricModel(QuadricClass quadric_class, const Eigen::Isometry3d& T_frame_quadric,
               const Eigen::Vector3d& scale);
  QuadricModel(QuadricClass quadric_class, const Eigen::Isometry3d& T_frame_quadric,
               const Eigen::Vector3d& scale, const Eigen::Vector4d& signature);

  QuadricClass quadricClass() const { return class_; }
  // T_frame_quadric: maps canonical-quadric-frame points into the frame the quadric lives in.
  const Eigen::Isometry3d& pose() const { return T_frame_quadric_; }
  const Eigen::Vector3d& scale() const { return scale_; }  // diagonal of S (alpha, beta, gamma)
  const Eigen::Vector4d& signature() const { return signature_; }

  // Q = T^T [S 0; 0 1]^T D(sigma) [S 0; 0 1] T with T = T_frame_quadric^-1 (eqs. 4-5).
  Eigen::Matrix4d matrix() const;

  // Decomposes a real symmetric 4x4 Q (any nonzero projective scale and sign) into (T, S, sigma)
  // by an eigen-decomposition of its upper 3x3 and Sylvester's law of inertia (eq. 4), the centre
  // from the linear part. Supported: the double plane (alpha x)^2 = 0 (rank-1 Q), ellipsoid,
  // hyperboloids of one and two sheets, elliptic cone, elliptic and hyperbolic cylinders.
  // Signature convention: spatial entries +1 first, then -1, then 0 (the axis of a cylinder is
  // quadric z); the overall sign of Q is chosen so that +1 entries outnumber -1 entries among the
  // spatial ones (ties: sigma4 = -1). Scale normalisation: |sigma4| = 1; for cones the -1 axis has
  // scale 1; null (cylinder) axes have scale 1. Throws std::invalid_argument for a non-symmetric or
  // non-finite Q, degenerate Q (zero, pairs of planes, single point), quadrics without real points,
  // paraboloids and parabolic cylinders (not supported), or when the result is not of the requested
  // class (e.g. unequal scales for kSphere) to within relative_tolerance.
  static QuadricModel fromMatrix(const Eigen::Matrix4d& Q, QuadricClass quadric_class,
                                 double relative_tolerance = 1e-6);

  // This quadric expressed in frame A, given T_A_frame (the quadric currently lives in `frame`).
  QuadricModel transformed(const Eigen::Isometry3d& T_A_frame) const;

  // pi [+] delta = (T exp(xi^), S + D(s)) with delta = [rho; phi; s] (eqs. 9, 11, 16; body frame).
  // The class is kept; the caller keeps delta within the class (see plusMinimal). S stays in D^3
  // (positive): a step that would take a scale below kMinScaleStepFraction of its value stops
  // there (an information-weighted fusion of two cone estimates once asked for a radius of
  // -0.06 m).
  QuadricModel plus(const Vector9d& delta) const;
  static constexpr double kMinScaleStepFraction = 1e-3;
  // One scale after a step, as plus() takes it: scale + step, but not below
  // kMinScaleStepFraction * scale.
  static double stepScale(double scale, double step) {
    return std::max(scale + step, kMinScaleStepFraction * scale);
  }
  // pi [-] pi' = [log(T'^-1 T)^vee; D^-1(S - S')] (eqs. 10, 14, 17). Exact inverse of plus() where
  // plus() leaves the scales above that bound.
  Vector9d minus(const QuadricModel& other) const;
  // The same through the class's minimal vector (Table II): plus(B delta), B^+ minus(other).
  QuadricModel plusMinimal(const Eigen::VectorXd& delta) const;
  Eigen::VectorXd minusMinimal(const QuadricModel& other) const;

 private:
  QuadricClass class_ = QuadricClass::kSphere;
  Eigen::Isometry3d T_frame_quadric_ = Eigen::Isometry3d::Identity();
  Eigen::Vector3d scale_ = Eigen::Vector3d::Ones();
  Eigen::Vector4d signature_ = Eigen::Vector4d(1, 1, 1, -1);
};

// The measurement prediction h(T_WC, pi) = (T_WC^-1 T_WQ, S) (eq. 19): the quadric in the camera
// frame.
QuadricModel predictMeasurement(const Eigen::Isometry3d& T_world_camera,
                                const QuadricModel& quadric_world);

}  // namespace quadric_slam
