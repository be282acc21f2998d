#include "quadric_slam/frontend/central_quadric.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {

Eigen::Matrix4d quadricMatrix(const GeneralQuadricFit& fit) {
  // f(x) = c0 x^2 + c1 y^2 + c2 z^2 + c3 xy + c4 xz + c5 yz + c6 x + c7 y + c8 z + c9 = x~^T Q_n x~.
  const Eigen::Matrix<double, 10, 1>& c = fit.coefficients;
  Eigen::Matrix4d Q_n;
  Q_n << c[0], c[3] / 2, c[4] / 2, c[6] / 2,  //
      c[3] / 2, c[1], c[5] / 2, c[7] / 2,     //
      c[4] / 2, c[5] / 2, c[2], c[8] / 2,     //
      c[6] / 2, c[7] / 2, c[8] / 2, c[9];
  Eigen::Matrix4d N = Eigen::Matrix4d::Identity();
  N.topLeftCorner<3, 3>() /= fit.spread;
  N.topRightCorner<3, 1>() = -fit.centre / fit.spread;
  const Eigen::Matrix4d Q = N.transpose() * Q_n * N;
  return 0.5 * (Q + Q.transpose());
}

QuadricModel withCanonicalAxisOrder(const QuadricModel& quadric) {
  if (quadric.quadricClass() != QuadricClass::kGeneral)
    return quadric;
  const Eigen::Vector4d& sigma = quadric.signature();
  const Eigen::Vector3d& scale = quadric.scale();
  // Stable: the groups of equal signature entries (+1, -1, 0 in that order) keep their places.
  std::array<int, 3> order = {0, 1, 2};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return sigma[a] != sigma[b] ? sigma[a] > sigma[b] : scale[a] < scale[b];
  });
  for (int j = 0; j < 3; ++j)
    if (sigma[order[j]] != sigma[j])
      return quadric;  // not in the core's +1, -1, 0 order: leave it
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  for (int j = 0; j < 3; ++j)
    P(order[j], j) = 1.0;
  if (P.determinant() < 0)
    P.col(2) = -P.col(2);  // a half-turn more: the same axes, a right-handed frame
  G.linear() = P;
  return withSymmetry(quadric, G);
}

QuadricModel centralQuadricFromFit(const GeneralQuadricFit& fit) {
  if (!fit.ok)
    throw std::invalid_argument("centralQuadricFromFit: the fit failed (too few points)");
  // fromMatrix throws for degenerate, imaginary and non-central (paraboloid) quadrics.
  const QuadricModel quadric = QuadricModel::fromMatrix(quadricMatrix(fit), QuadricClass::kGeneral);
  const Eigen::Vector4d& sigma = quadric.signature();
  if ((sigma.array() == 0.0).any())
    throw std::invalid_argument(
        "centralQuadricFromFit: not a central quadric with a finite centre and no null axis "
        "(a cylinder or cone)");
  return withCanonicalAxisOrder(quadric);
}

}  // namespace quadric_slam
