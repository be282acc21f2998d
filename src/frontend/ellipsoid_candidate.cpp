#include "quadric_slam/frontend/ellipsoid_candidate.h"

#include <stdexcept>

#include "quadric_slam/frontend/central_quadric.h"

namespace quadric_slam {

namespace {
const Eigen::Vector4d kEllipsoidSignature(1, 1, 1, -1);
}  // namespace

Eigen::Vector3d semiAxes(const QuadricModel& quadric) {
  if (quadric.quadricClass() != QuadricClass::kGeneral || quadric.signature() != kEllipsoidSignature)
    return Eigen::Vector3d::Zero();
  return quadric.scale().cwiseInverse();
}

bool plausibleEllipsoid(const QuadricModel& quadric, double min_semi_axis, double max_semi_axis) {
  const Eigen::Vector3d axes = semiAxes(quadric);
  return axes.allFinite() && axes.minCoeff() >= min_semi_axis && axes.maxCoeff() <= max_semi_axis &&
         quadric.pose().matrix().allFinite();
}

std::optional<PrimitiveShape> ellipsoidCandidate(const GeneralQuadricFit& fit,
                                                 double min_semi_axis, double max_semi_axis) {
  if (!fit.ok)
    return std::nullopt;
  try {
    const QuadricModel quadric = centralQuadricFromFit(fit);
    if (!plausibleEllipsoid(quadric, min_semi_axis, max_semi_axis))
      return std::nullopt;
    return PrimitiveShape::general(quadric);
  } catch (const std::invalid_argument&) {  // degenerate, imaginary or not central
    return std::nullopt;
  }
}

Eigen::MatrixXd ellipsoidModelCovariance(const QuadricModel& quadric, double sigma) {
  const Eigen::Vector3d axes = semiAxes(quadric);
  if (!(axes.minCoeff() > 0.0))
    throw std::invalid_argument("ellipsoidModelCovariance: the quadric is not an ellipsoid");
  if (!(sigma >= 0.0))
    throw std::invalid_argument("ellipsoidModelCovariance: sigma must be >= 0 m");
  Eigen::VectorXd variances(9);
  const double rotation = sigma / axes.minCoeff();
  variances << sigma * sigma, sigma * sigma, sigma * sigma, rotation * rotation,
      rotation * rotation, rotation * rotation,
      (sigma * quadric.scale().array().square()).square().matrix();
  return variances.asDiagonal();
}

}  // namespace quadric_slam
