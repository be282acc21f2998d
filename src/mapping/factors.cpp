#include "quadric_slam/mapping/factors.h"

#include <Eigen/Cholesky>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {

namespace {
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}  // namespace

Eigen::MatrixXd sqrtInformation(const Eigen::MatrixXd& covariance, const char* what) {
  if (covariance.rows() != covariance.cols() || covariance.rows() == 0)
    throw std::invalid_argument(std::string(what) + ": covariance must be square and non-empty");
  if (!covariance.allFinite() || (covariance - covariance.transpose()).cwiseAbs().maxCoeff() >
                                     1e-9 * covariance.cwiseAbs().maxCoeff())
    throw std::invalid_argument(std::string(what) + ": covariance must be finite and symmetric");
  const Eigen::LLT<Eigen::MatrixXd> llt_cov(covariance);
  if (llt_cov.info() != Eigen::Success)
    throw std::invalid_argument(std::string(what) + ": covariance must be positive definite");
  const Eigen::MatrixXd information =
      llt_cov.solve(Eigen::MatrixXd::Identity(covariance.rows(), covariance.cols()));
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (information + information.transpose()));
  return llt.matrixU();
}

QuadricObservationCost::QuadricObservationCost(const QuadricModel& z_camera,
                                               const Eigen::MatrixXd& sqrt_information)
    : z_(z_camera), T_quadric_camera_z_(z_camera.pose().inverse()) {
  const int k = classDefinition(z_camera.quadricClass()).minimal_dimension;
  if (sqrt_information.rows() != k || sqrt_information.cols() != k)
    throw std::invalid_argument("QuadricObservationCost: sqrt_information must be " +
                                std::to_string(k) + "x" + std::to_string(k) + " for a " +
                                toString(z_camera.quadricClass()));
  sqrt_information_ = sqrt_information;
  basis_pinv_ = basisPseudoInverse(z_camera.quadricClass());
  for (int index : classDefinition(z_camera.quadricClass()).dropped_pose_indices)
    dropped_.at(num_dropped_++) = index;
  set_num_residuals(k);
  mutable_parameter_block_sizes()->push_back(kPoseParameterSize);
  mutable_parameter_block_sizes()->push_back(kQuadricParameterSize);
}

ceres::CostFunction* QuadricObservationCost::Create(const QuadricModel& z_camera,
                                                    const Eigen::MatrixXd& covariance) {
  return new QuadricObservationCost(z_camera,
                                    sqrtInformation(covariance, "QuadricObservationCost"));
}

namespace {

// The parts of the residual and its rates that do not depend on the class's minimal dimension k.
struct AlignedError {
  Eigen::Isometry3d G;  // the symmetry alignment of z
  Vector9d r9;          // [e; s_h - s_zG]
  Matrix6d K;           // de / d delta
  Matrix6d dM6;         // Ad_G ad(e) Gamma: the whitening's rate through G
  Matrix6d Ad_h_inv;    // camera tangent -> delta
};

// The k-dependent products with k fixed at compile time (vectorised, no heap): r = L M B^+ r9,
// L N = L M B^+_6 K - L B^+_6 dM6, dr/d camera = -L N Ad_{h^-1}, dr/d [dq; ds] = [L N, L M B^+_s],
// with M = minimalAdjoint(G) = B^+ blockdiag(Ad_G, I) B (a general quadric's relabelling of the
// scale block is left to minimalAdjoint itself).
template <int K>
void whiten(QuadricClass c, const QuadricObservationCost::MatrixKK& sqrt_information,
            const QuadricObservationCost::MatrixK9& basis_pinv, const AlignedError& a,
            bool jacobians, double* residuals, QuadricObservationCost::MatrixK6* J_camera,
            QuadricObservationCost::MatrixK9* J_general) {
  using MatrixKK = Eigen::Matrix<double, K, K>;
  using MatrixK9 = Eigen::Matrix<double, K, 9>;
  using MatrixK6 = Eigen::Matrix<double, K, 6>;
  const MatrixKK L = sqrt_information;
  const MatrixK9 B_pinv = basis_pinv;
  MatrixKK M;
  if (c == QuadricClass::kGeneral) {
    M = minimalAdjoint(c, a.G);
  } else {
    Eigen::Matrix<double, 9, 9> ad = Eigen::Matrix<double, 9, 9>::Identity();
    ad.template topLeftCorner<6, 6>() = adjointSE3(a.G);
    const Eigen::Matrix<double, 9, K> B = classDefinition(c).basis;
    M = B_pinv * ad * B;
  }
  const MatrixKK LM = L * M;
  Eigen::Map<Eigen::Matrix<double, K, 1>> r(residuals);
  r = LM * (B_pinv * a.r9);
  if (!jacobians)
    return;
  const MatrixK6 LN = LM * (B_pinv.template leftCols<6>() * a.K) -
                      L * (B_pinv.template leftCols<6>() * a.dM6);
  *J_camera = -LN * a.Ad_h_inv;
  J_general->resize(K, 9);
  J_general->template leftCols<6>() = LN;
  J_general->template rightCols<3>() = LM * B_pinv.template rightCols<3>();
}

}  // namespace

void QuadricObservationCost::evaluateTangent(double const* const* parameters, double* residuals,
                                             MatrixK6* J_camera, MatrixK9* J_general) const {
  const QuadricClass c = z_.quadricClass();
  const Eigen::Isometry3d T_world_camera = poseFromParameters(parameters[0]);
  const Eigen::Isometry3d T_world_quadric = poseFromParameters(parameters[1]);
  const Eigen::Vector3d scale(parameters[1][7], parameters[1][8], parameters[1][9]);
  const Eigen::Isometry3d h = T_world_camera.inverse() * T_world_quadric;  // eq. 19
  const Eigen::Isometry3d D = T_quadric_camera_z_ * h;
  AlignedError a;
  // The member z G of the measurement's symmetry orbit closest to h; for a general quadric G may
  // also relabel the axes, and the measured scales follow them (geometry/symmetry.h).
  a.G = symmetryAlignment(z_, D);
  a.r9.head<6>() = logSE3(a.G.inverse() * D);              // eq. 14: h [-] z G
  a.r9.tail<3>() = scale - withSymmetry(z_, a.G).scale();  // eq. 17
  const bool jacobians = J_camera != nullptr && J_general != nullptr;
  if (jacobians) {
    const Vector6d e = a.r9.head<6>();
    // J_l^-1 and J_r^-1 at e once, for both rates below (geometry/symmetry.h):
    //   Gamma = P^T (P J_l^-1 P^T)^-1 P J_r^-1  (alignmentGeneratorRate),
    //   K = J_r^-1 - J_l^-1 Gamma               (alignedErrorJacobian).
    const Matrix6d Jl_inv = leftJacobianInverseSE3(e);
    const Matrix6d Jr_inv = rightJacobianInverseSE3(e);
    Matrix6d Gamma = Matrix6d::Zero();
    // m = 1..3 dropped components: P J_l^-1 P^T is at most 3 x 3 (closed-form inverse).
    auto rate = [&](auto dropped_count) {
      constexpr int kM = decltype(dropped_count)::value;
      Eigen::Matrix<double, kM, kM> PJP;
      Eigen::Matrix<double, kM, 6> PJr;
      for (int i = 0; i < kM; ++i) {
        PJr.row(i) = Jr_inv.row(dropped_[i]);
        for (int j = 0; j < kM; ++j)
          PJP(i, j) = Jl_inv(dropped_[i], dropped_[j]);
      }
      const Eigen::Matrix<double, kM, 6> rows = PJP.inverse() * PJr;
      for (int i = 0; i < kM; ++i)
        Gamma.row(dropped_[i]) = rows.row(i);
    };
    if (num_dropped_ == 1)
      rate(std::integral_constant<int, 1>());
    else if (num_dropped_ == 2)
      rate(std::integral_constant<int, 2>());
    else if (num_dropped_ == 3)
      rate(std::integral_constant<int, 3>());
    a.K = Jr_inv - Jl_inv * Gamma;
    // d r / d delta (D exp(delta^)), k x 6: the error's rate and the whitening's rate through G
    // (the scale rows of both are zero, so only B^+'s pose columns take part).
    a.dM6 = adjointSE3(a.G) * adSE3(e) * Gamma;
    a.Ad_h_inv = adjointSE3(h.inverse());
  }
  switch (num_residuals()) {
    case 3:
      return whiten<3>(c, sqrt_information_, basis_pinv_, a, jacobians, residuals, J_camera,
                       J_general);
    case 4:
      return whiten<4>(c, sqrt_information_, basis_pinv_, a, jacobians, residuals, J_camera,
                       J_general);
    case 5:
      return whiten<5>(c, sqrt_information_, basis_pinv_, a, jacobians, residuals, J_camera,
                       J_general);
    case 6:
      return whiten<6>(c, sqrt_information_, basis_pinv_, a, jacobians, residuals, J_camera,
                       J_general);
    case 9:
      return whiten<9>(c, sqrt_information_, basis_pinv_, a, jacobians, residuals, J_camera,
                       J_general);
    default:
      throw std::logic_error("QuadricObservationCost: no class has " +
                             std::to_string(num_residuals()) + " minimal dimensions");
  }
}

bool QuadricObservationCost::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr)) {
    evaluateTangent(parameters, residuals, nullptr, nullptr);
    return true;
  }
  MatrixK6 J_camera;
  MatrixK9 J_general;
  evaluateTangent(parameters, residuals, &J_camera, &J_general);
  const int k = num_residuals();
  if (jacobians[0] != nullptr)
    Eigen::Map<RowMajorMatrix>(jacobians[0], k, kPoseParameterSize) =
        J_camera.lazyProduct(poseMinusJacobian(parameters[0]));
  if (jacobians[1] != nullptr)
    Eigen::Map<RowMajorMatrix>(jacobians[1], k, kQuadricParameterSize) =
        J_general.lazyProduct(quadricGeneralMinusJacobian(parameters[1]));
  return true;
}

RelativePoseCost::RelativePoseCost(const Eigen::Isometry3d& T_i_j, const Matrix6d& sqrt_information)
    : T_j_i_measured_(T_i_j.inverse()), sqrt_information_(sqrt_information) {}

ceres::CostFunction* RelativePoseCost::Create(const Eigen::Isometry3d& T_i_j,
                                              const Matrix6d& covariance) {
  return new RelativePoseCost(T_i_j, sqrtInformation(covariance, "RelativePoseCost"));
}

bool RelativePoseCost::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  const Eigen::Isometry3d T_w_i = poseFromParameters(parameters[0]);
  const Eigen::Isometry3d T_w_j = poseFromParameters(parameters[1]);
  const Eigen::Isometry3d T_i_j = T_w_i.inverse() * T_w_j;
  const Vector6d e = logSE3(T_j_i_measured_ * T_i_j);
  Eigen::Map<Vector6d>{residuals} = sqrt_information_ * e;
  if (jacobians == nullptr)
    return true;
  const Matrix6d LJ = sqrt_information_ * rightJacobianInverseSE3(e);
  using RowMajor67 = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
  if (jacobians[0] != nullptr)
    Eigen::Map<RowMajor67>{jacobians[0]} =
        -LJ * adjointSE3(T_i_j.inverse()) * poseMinusJacobian(parameters[0]);
  if (jacobians[1] != nullptr)
    Eigen::Map<RowMajor67>{jacobians[1]} = LJ * poseMinusJacobian(parameters[1]);
  return true;
}

PosePriorCost::PosePriorCost(const Eigen::Isometry3d& T_prior, const Matrix6d& sqrt_information)
    : T_prior_inverse_(T_prior.inverse()), sqrt_information_(sqrt_information) {}

ceres::CostFunction* PosePriorCost::Create(const Eigen::Isometry3d& T_prior,
                                           const Matrix6d& covariance) {
  return new PosePriorCost(T_prior, sqrtInformation(covariance, "PosePriorCost"));
}

bool PosePriorCost::Evaluate(double const* const* parameters, double* residuals,
                             double** jacobians) const {
  const Eigen::Isometry3d T = poseFromParameters(parameters[0]);
  const Vector6d e = logSE3(T_prior_inverse_ * T);
  Eigen::Map<Vector6d>{residuals} = sqrt_information_ * e;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    using RowMajor67 = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
    Eigen::Map<RowMajor67>{jacobians[0]} =
        sqrt_information_ * rightJacobianInverseSE3(e) * poseMinusJacobian(parameters[0]);
  }
  return true;
}

}  // namespace quadric_slam
