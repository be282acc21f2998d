#include "quadric_slam/mapping/surface_fusion.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {

namespace {

void requireSquare(const Eigen::MatrixXd& m, int k, const char* what) {
  if (m.rows() != k || m.cols() != k)
    throw std::invalid_argument(std::string("surface fusion: ") + what + " is " +
                                std::to_string(m.rows()) + "x" + std::to_string(m.cols()) +
                                ", expected " + std::to_string(k) + "x" + std::to_string(k));
}

// b G = aligned: G = b^-1 aligned (in b's quadric frame).
Eigen::Isometry3d symmetryElement(const QuadricModel& b, const QuadricModel& aligned) {
  return b.pose().inverse() * aligned.pose();
}

}  // namespace

AlignedSurface alignCovariance(const QuadricModel& b, const Eigen::MatrixXd& covariance,
                               const QuadricModel& reference) {
  const QuadricClass c = b.quadricClass();
  if (reference.quadricClass() != c)
    throw std::invalid_argument("alignCovariance: classes differ");
  requireSquare(covariance, minimalDimension(c), "covariance");
  AlignedSurface out{alignToReference(b, reference), {}, {}};
  out.transform = minimalAdjoint(c, symmetryElement(b, out.quadric).inverse());
  const Eigen::MatrixXd& M = out.transform;
  out.matrix = M * covariance * M.transpose();
  out.matrix = 0.5 * (out.matrix + out.matrix.transpose()).eval();
  return out;
}

AlignedSurface alignInformation(const QuadricModel& b, const Eigen::MatrixXd& information,
                                const QuadricModel& reference) {
  const QuadricClass c = b.quadricClass();
  if (reference.quadricClass() != c)
    throw std::invalid_argument("alignInformation: classes differ");
  requireSquare(information, minimalDimension(c), "information");
  AlignedSurface out{alignToReference(b, reference), {}, {}};
  out.transform = minimalAdjoint(c, symmetryElement(b, out.quadric));
  const Eigen::MatrixXd& N = out.transform;
  out.matrix = N.transpose() * information * N;
  out.matrix = 0.5 * (out.matrix + out.matrix.transpose()).eval();
  return out;
}

Eigen::VectorXd surfaceOffset(const QuadricModel& a, const QuadricModel& b) {
  // surfaceMinus(a, b) = a [-] b' = [log(b'^-1 a); s_a - s_b], and log(T^-1) = -log(T).
  return -surfaceMinus(a, b);
}

SurfaceInformation fuseSurfaces(const SurfaceInformation& a, const SurfaceInformation& b) {
  const QuadricClass c = a.mean.quadricClass();
  const int k = minimalDimension(c);
  requireSquare(a.information, k, "information of the first estimate");
  const AlignedSurface b_aligned = alignInformation(b.mean, b.information, a.mean);
  const Eigen::VectorXd x = b_aligned.quadric.minusMinimal(a.mean);
  SurfaceInformation out;
  out.information = a.information + b_aligned.matrix;
  out.information = 0.5 * (out.information + out.information.transpose()).eval();
  // delta = I^-1 I_b' x; a rank-deficient I (priors) gets the minimum-norm solution.
  const Eigen::VectorXd rhs = b_aligned.matrix * x;
  const Eigen::VectorXd delta = out.information.completeOrthogonalDecomposition().solve(rhs);
  out.mean = delta.allFinite() ? a.mean.plusMinimal(delta) : a.mean;
  return out;
}

Eigen::MatrixXd diagonalMinimalCovariance(const QuadricModel& quadric, double translation_sigma,
                                          double rotation_sigma, double scale_fraction) {
  const QuadricClassDefinition& def = classDefinition(quadric.quadricClass());
  const int k = def.minimal_dimension;
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(k, k);
  for (int j = 0; j < k; ++j) {
    int row = 0;
    def.basis.col(j).cwiseAbs().maxCoeff(&row);
    double sigma = 0.0;
    if (row < 3) {
      sigma = translation_sigma;
    } else if (row < 6) {
      sigma = rotation_sigma;
    } else {
      const Eigen::Vector3d column = def.basis.col(j).tail<3>();
      sigma = scale_fraction * column.cwiseProduct(quadric.scale()).cwiseAbs().sum() /
              column.cwiseAbs().sum();
    }
    covariance(j, j) = sigma * sigma;
  }
  return covariance;
}

}  // namespace quadric_slam
