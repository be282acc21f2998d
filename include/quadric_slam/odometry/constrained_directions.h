// Which directions of the point-to-plane ICP normal equations H delta = -b the data constrain,
// judged against what the normals' noise alone would put into H (issue 12).
//
// Each correspondence adds J J^T to H with J = [n; p x n] (n the keyframe normal). A normal
// estimated from noisy depth is tilted by a random error e (n = n_true + e, e tangent to the
// surface), so H also holds the sum of J_e J_e^T, J_e = [e; p x e]: information along the
// surface that no geometry provides. For a single plane seen from 3-4 m (normal noise of 15-25
// degrees on a Kinect v1) it is a few thousandths of the information along the normal, enough to
// pass an eigenvalue-ratio test, and the pose along the plane then lands wherever the noise puts
// it. So a direction v counts as constrained only when
//   v^T H v > min_eigenvalue_ratio * lambda_max(H) |v|^2 + noise_information_factor * v^T N v,
// N the expected noise part of H. That is the generalised eigenproblem H v = mu B v with
// B = min_eigenvalue_ratio * lambda_max(H) I + noise_information_factor * N: directions with
// mu <= 1 are unconstrained. With N = 0 it is the classic eigenvalue-ratio test.
//
// The update and covariance live on the orthogonal complement of the unconstrained directions, not
// on the span of the constrained generalised eigenvectors: those are B-orthogonal to the
// unconstrained ones, and B couples a translation along a surface with the rotation whose lever arm
// moves the surface's points that way (the normals' noise is tangential). A step along them would
// carry the camera along a far wall, several centimetres a frame, while nothing measures it.
#pragma once

#include <Eigen/Core>

#include "quadric_slam/odometry/pose_math.h"

namespace quadric_slam {

class ConstrainedDirections {
 public:
  // H: the (weighted) normal matrix; noise_information: N above (symmetric, positive
  // semi-definite; zero to use the eigenvalue-ratio test alone).
  ConstrainedDirections(const Matrix6d& H, const Matrix6d& noise_information,
                        double min_eigenvalue_ratio, double noise_information_factor);

  // Number of constrained directions, 0..6.
  int constrained() const { return constrained_; }
  // The Gauss-Newton step solving H delta = -b on the orthogonal complement of the unconstrained
  // directions; it is zero along those, which keep the start (solution remapping, Zhang, Kaess &
  // Singh 2016).
  Vector6d step(const Vector6d& b) const;
  // sigma2 H^-1 on the constrained complement and degenerate_variance along the unconstrained
  // directions (orthonormalised).
  Matrix6d covariance(double sigma2, double degenerate_variance) const;
  // Smallest over largest eigenvalue of H alone (1: evenly constrained, 0: a free direction).
  double eigenvalueRatio() const { return eigenvalue_ratio_; }
  // Smallest mu: above 1 when every direction is constrained.
  double weakestMargin() const { return mu_(0); }

  // The smallest ratio v^T H v / v^T N v over all directions: how many times the information
  // along the weakest direction exceeds what the normals' noise explains (about 1 when the noise
  // explains all of it). Infinite when N is zero.
  static double informationOverNoise(const Matrix6d& H, const Matrix6d& noise_information);

 private:
  Vector6d mu_;  // generalised eigenvalues, ascending
  // With C an orthonormal basis of the complement of the unconstrained directions:
  // K = C (C^T H C)^-1 C^T (step -K b, covariance sigma2 K) ...
  Matrix6d complement_inverse_;
  // ... and the orthogonal projector onto the unconstrained directions.
  Matrix6d unconstrained_projector_;
  int constrained_ = 0;
  double eigenvalue_ratio_ = 0;
};

}  // namespace quadric_slam
