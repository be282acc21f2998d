// Two Gaussian estimates of one surface, compared and fused in the class's minimal space (Table
// II), to first order on the manifold.
//
// An estimate is a quadric pi and a covariance (or information) in the minimal tangent at pi
// (body frame, the convention of the window's marginals and of the measurements: the surface is
// pi [+] B nu, eq. 18). A second estimate b of the same surface is first re-expressed by the member
// b' = b G of its symmetry orbit closest to a (geometry/symmetry.h), so that the frames of a and b'
// differ only in the directions the class keeps; its covariance becomes M C M^T with
// M = minimalAdjoint(G^-1) (information N^T I N, N = minimalAdjoint(G) = M^-1). Then
//   x = b' [-] a  (minimal, eqs. 10, 14, 17): b' = a [+] B x,
// and to first order (x small, so the Jacobians of [-] are the identity) x ~ N(0, C_a + C_b') when
// a and b are the same surface. Fusion (information form): I = I_a + I_b',
//   mean = a [+] B (I^-1 I_b' x),   covariance I^-1 (no larger than either part: I >= I_a, I_b').
#pragma once

#include <Eigen/Core>

#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

// A surface estimate in information form: k x k information in the minimal tangent at `mean`
// (may be singular: a prior that constrains only some directions).
struct SurfaceInformation {
  QuadricModel mean;
  Eigen::MatrixXd information;
};

// `b` (covariance or information in its own minimal tangent) re-expressed by the member of its
// symmetry orbit closest to `reference`. The returned matrix is in the tangent of the returned
// quadric. Throws std::invalid_argument when the classes differ or the matrix is not k x k.
// `transform` maps b's minimal tangent to the returned one (M above; for alignInformation, N): a
// cross-covariance Cov(z, b) of b with another estimate z becomes Cov(z, b) M^T.
struct AlignedSurface {
  QuadricModel quadric;
  Eigen::MatrixXd matrix;
  Eigen::MatrixXd transform;
};
AlignedSurface alignCovariance(const QuadricModel& b, const Eigen::MatrixXd& covariance,
                               const QuadricModel& reference);
AlignedSurface alignInformation(const QuadricModel& b, const Eigen::MatrixXd& information,
                                const QuadricModel& reference);

// x = b' [-] a (minimal, k): where b lies in a's minimal tangent (b' = b aligned to a).
Eigen::VectorXd surfaceOffset(const QuadricModel& a, const QuadricModel& b);

// The fusion above. Returns a's mean and the summed information when the sum is singular in the
// direction of x (nothing to move along). Throws std::invalid_argument when the classes differ or a
// matrix is not k x k.
SurfaceInformation fuseSurfaces(const SurfaceInformation& a, const SurfaceInformation& b);

// Diagonal covariance in the class's minimal space with 1-sigma `translation_sigma` (m) on
// translation entries, `rotation_sigma` (rad) on rotation entries and `scale_fraction` of the
// quadric's own scale on scale entries (each minimal column of B is one of the three kinds).
Eigen::MatrixXd diagonalMinimalCovariance(const QuadricModel& quadric, double translation_sigma,
                                          double rotation_sigma, double scale_fraction);

}  // namespace quadric_slam
