// Ceres cost functions for the paper's factor graph (Fig. 3): quadric observations (eq. 20-22),
// odometry (relative pose) and a prior on a pose. Parameter blocks use the layouts of
// geometry/manifolds.h (pose 7, quadric 10); set PoseManifold / QuadricManifold on them.
// Jacobians are analytic, w.r.t. the ambient blocks, built as J_tangent * MinusJacobian(x) so that
// Ceres' product with PlusJacobian(x) gives exactly the tangent Jacobian.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {

// Upper-triangular L with L^T L = covariance^-1; throws std::invalid_argument naming `what` when
// the covariance is not square, not symmetric or not positive definite.
Eigen::MatrixXd sqrtInformation(const Eigen::MatrixXd& covariance, const char* what);

// Quadric observation factor. Measurement z = _C pi~ (quadric in the camera frame) of the class of
// the landmark, covariance Sigma (k x k) in the class's minimal space (Table II), expressed in z's
// own frame: z = h [+] nu, nu ~ N(0, Sigma) (eq. 18).
//
// Derivation. Prediction h = T_WC^-1 T_WQ (eq. 19). With D = z^-1 h and G = symmetryAlignment(z, D)
// (geometry/symmetry.h: z G is the member of z's symmetry orbit closest to h),
//   e = log(G^-1 z^-1 h)^vee  (eq. 14: h [-] zG),  x = B^+ [e; s_h - s_zG]  (eq. 17, Table II)
// (s_zG = s_z except for a general quadric whose G relabels the axes: s_zG = |R_G|^T s_z)
// and the dropped (symmetry) components of e are zero, so x depends on the surfaces only. The noise
// of zG is Ad(G^-1) nu, so x ~ N(0, A Sigma A^T) with A = minimalAdjoint(G^-1); whitening with
// L A^-1 = L M, M = minimalAdjoint(G), L^T L = Sigma^-1, gives the residual (eq. 22)
//   r = L M(G) x,
// which is then also independent of the frame the front-end chose for z (with its Sigma).
// Perturbations (body frame): T_WQ exp(dq^) -> D exp(dq^); T_WC exp(dc^) -> D exp(-(Ad_{h^-1}
// dc)^). For D exp(delta^): de = K delta with K = alignedErrorJacobian(e), and G -> G exp(gamma^)
// with gamma = Gamma delta (alignmentGeneratorRate), so dM x = B^+ [Ad_G ad(gamma) e; 0] = -B^+
// [Ad_G ad(e) Gamma delta; 0]. Hence dr/d delta = L (M B^+ [K; 0] - B^+ [Ad_G ad(e) Gamma; 0]) =: L
// N,
//   dr/d(quadric tangent [dq; ds]) = [L N, L M B^+_s],   dr/d(camera tangent) = -L N Ad_{h^-1}.
class QuadricObservationCost : public ceres::CostFunction {
 public:
  QuadricObservationCost(const QuadricModel& z_camera, const Eigen::MatrixXd& sqrt_information);
  static ceres::CostFunction* Create(const QuadricModel& z_camera, const Eigen::MatrixXd& covariance);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // k <= 9: the per-evaluation matrices live on the stack (the cost is evaluated for every
  // association pair and every window residual; heap traffic was a third of its cost).
  using MatrixK6 = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::ColMajor, 9, 6>;
  using MatrixK9 = Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::ColMajor, 9, 9>;
  using MatrixKK = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 9, 9>;
  // The residual (k) at the pose and quadric blocks, and when both pointers are given its
  // Jacobians in the tangent spaces: w.r.t. the camera pose tangent (k x 6, = -L N Ad_{h^-1}) and
  // the landmark's general tangent [rho; phi; s] (k x 9, = [L N, L M B^+_s]). Evaluate chains them
  // with the blocks' MinusJacobians; the class's basis B maps the latter to its minimal tangent.
  void evaluateTangent(double const* const* parameters, double* residuals, MatrixK6* J_camera,
                       MatrixK9* J_general) const;

 private:
  QuadricModel z_;
  Eigen::Isometry3d T_quadric_camera_z_;  // z^-1
  MatrixKK sqrt_information_;             // L (k x k)
  MatrixK9 basis_pinv_;                   // B^+ (k x 9)
  std::array<int, 6> dropped_{};          // the class's dropped pose components (P's rows)
  int num_dropped_ = 0;
};

// Relative pose (odometry) factor between T_WCi and T_WCj with measurement T_ij~ = T_i^-1 T_j:
//   e = log(T_ij~^-1 T_i^-1 T_j)^vee,  r = L e (6).
// T_j exp(dj^): de = J_r^-1(e) dj.  T_i exp(di^): T_i^-1 T_j -> exp(-di^) T_i^-1 T_j, so
//   de = -J_r^-1(e) Ad_{T_j^-1 T_i} di.
class RelativePoseCost : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePoseCost(const Eigen::Isometry3d& T_i_j, const Matrix6d& sqrt_information);
  static ceres::CostFunction* Create(const Eigen::Isometry3d& T_i_j, const Matrix6d& covariance);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Isometry3d T_j_i_measured_;  // T_ij~^-1
  Matrix6d sqrt_information_;
};

// Prior on a pose T_WC with mean T_prior: e = log(T_prior^-1 T_WC)^vee (eq. 14), r = L e;
// de = J_r^-1(e) d for T_WC exp(d^).
class PosePriorCost : public ceres::SizedCostFunction<6, 7> {
 public:
  PosePriorCost(const Eigen::Isometry3d& T_prior, const Matrix6d& sqrt_information);
  static ceres::CostFunction* Create(const Eigen::Isometry3d& T_prior, const Matrix6d& covariance);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Isometry3d T_prior_inverse_;
  Matrix6d sqrt_information_;
};

}  // namespace quadric_slam
