#include "quadric_slam/frontend/curved_shape_starts.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace quadric_slam {

PrimitiveShape cylinderFromCone(const PrimitiveShape& cone,
                                const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d d = cone.direction;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& q : points)
    mean += q;
  mean /= static_cast<double>(points.size());
  const Eigen::Vector3d on_axis = cone.point + d.dot(mean - cone.point) * d;
  double radius = 0;
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - on_axis;
    radius += (v - d.dot(v) * d).norm();
  }
  return PrimitiveShape::cylinder(on_axis, d, radius / points.size());
}

PrimitiveShape coneFromCylinder(const PrimitiveShape& cylinder,
                                const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d d = cylinder.direction;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - cylinder.point;
    const double z = d.dot(v);
    const double rho = (v - z * d).norm();
    const Eigen::Vector2d row(1.0, z);
    A += row * row.transpose();
    b += row * rho;
  }
  PrimitiveShape cone = PrimitiveShape::cone(cylinder.point, d, 0.0);
  if (std::abs(A.determinant()) < 1e-18)
    return cone;
  const Eigen::Vector2d x = A.ldlt().solve(b);
  const double r0 = x[0], k = x[1];
  if (!(std::abs(k) > 1e-6) || !std::isfinite(r0))
    return cone;
  // Apex where the radius vanishes; the axis points from it into the opening.
  cone.point = cylinder.point - (r0 / k) * d;
  cone.direction = k > 0 ? d : Eigen::Vector3d(-d);
  cone.size = std::atan(std::abs(k));
  return cone;
}

PrimitiveShape coneFromTiltedCylinder(const PrimitiveShape& cylinder,
                                      const std::vector<Eigen::Vector3d>& points, double tilt,
                                      double sign) {
  const Eigen::Vector3d& d = cylinder.direction;
  // The mean direction from the axis to the points, normal to the axis.
  Eigen::Vector3d towards = Eigen::Vector3d::Zero();
  for (const auto& q : points) {
    Eigen::Vector3d radial = q - cylinder.point;
    radial -= d.dot(radial) * d;
    const double norm = radial.norm();
    if (norm > 0)
      towards += radial / norm;
  }
  towards -= d.dot(towards) * d;
  if (!(towards.norm() > 1e-9))
    return PrimitiveShape::cone(cylinder.point, d, 0.0);
  PrimitiveShape tilted = cylinder;
  tilted.direction =
      (std::cos(tilt) * d + sign * std::sin(tilt) * towards.normalized()).normalized();
  return coneFromCylinder(tilted, points);
}

PrimitiveShape coneFromNormals(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector3d>& normals) {
  PrimitiveShape cone = PrimitiveShape::cone(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0);
  if (points.size() < 10 || points.size() != normals.size())
    return cone;
  Eigen::Vector3d mean_n = Eigen::Vector3d::Zero();
  for (const auto& n : normals)
    mean_n += n;
  mean_n /= static_cast<double>(normals.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero(), A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    C += (normals[i] - mean_n) * (normals[i] - mean_n).transpose();
    A += normals[i] * normals[i].transpose();
    b += normals[i] * normals[i].dot(points[i]);
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig_a(A);
  if (eig.info() != Eigen::Success || eig_a.info() != Eigen::Success ||
      eig_a.eigenvalues()[0] < 1e-6 * eig_a.eigenvalues()[2])
    return cone;
  Eigen::Vector3d axis = eig.eigenvectors().col(0);
  const Eigen::Vector3d apex = A.ldlt().solve(b);
  double mean_z = 0;
  for (const auto& q : points)
    mean_z += axis.dot(q - apex);
  if (mean_z < 0)
    axis = -axis;
  double angle = 0;
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - apex;
    const double z = axis.dot(v);
    angle += std::atan2((v - z * axis).norm(), z);
  }
  cone.point = apex;
  cone.direction = axis;
  cone.size = angle / static_cast<double>(points.size());
  return cone;
}

namespace {

// A cylinder's axis from its normals, which are all perpendicular to it: the least-variance
// direction of the (uncentred) normals. None when the eigen-decomposition fails.
std::optional<Eigen::Vector3d> axisFromNormals(const std::vector<Eigen::Vector3d>& normals) {
  Eigen::Matrix3d N = Eigen::Matrix3d::Zero();
  for (const auto& n : normals)
    N += n * n.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(N);
  if (eig.info() != Eigen::Success)
    return std::nullopt;
  return Eigen::Vector3d(eig.eigenvectors().col(0));
}

}  // namespace

PrimitiveShape cylinderFromNormals(const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<Eigen::Vector3d>& normals, double curvature) {
  PrimitiveShape cylinder =
      PrimitiveShape::cylinder(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0);
  if (points.size() < 10 || points.size() != normals.size() || !(curvature > 0))
    return cylinder;
  const std::optional<Eigen::Vector3d> found = axisFromNormals(normals);
  if (!found)
    return cylinder;
  const Eigen::Vector3d axis = *found;
  const double radius = 1.0 / curvature;
  double best_scatter = std::numeric_limits<double>::max();
  for (const double sign : {-1.0, 1.0}) {
    // Feet on the axis, projected onto the plane perpendicular to it.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double sum_sq = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      Eigen::Vector3d foot = points[i] + sign * radius * normals[i];
      foot -= axis.dot(foot) * axis;
      mean += foot;
      sum_sq += foot.squaredNorm();
    }
    mean /= static_cast<double>(points.size());
    const double scatter = sum_sq / static_cast<double>(points.size()) - mean.squaredNorm();
    if (scatter < best_scatter) {
      best_scatter = scatter;
      cylinder = PrimitiveShape::cylinder(mean, axis, radius);
    }
  }
  return cylinder;
}

double cylinderCurvatureFromNormals(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<Eigen::Vector3d>& normals) {
  if (points.size() < 10 || points.size() != normals.size())
    return 0.0;
  const std::optional<Eigen::Vector3d> found = axisFromNormals(normals);
  if (!found)
    return 0.0;
  const Eigen::Vector3d axis = *found;
  Eigen::Vector3d mean_point = Eigen::Vector3d::Zero(), mean_normal = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    mean_point += points[i];
    mean_normal += normals[i];
  }
  const double n = static_cast<double>(points.size());
  mean_point /= n;
  mean_normal /= n;
  // Normals turned towards the camera point out of a cylinder's outside: the regression's sign
  // does not matter for the curvature's size.
  double cross = 0, squares = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector3d dp = points[i] - mean_point;
    dp -= axis.dot(dp) * axis;
    cross += (normals[i] - mean_normal).dot(dp);
    squares += dp.squaredNorm();
  }
  return squares > 0 ? std::abs(cross) / squares : 0.0;
}

double shapeCurvature(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points) {
  if (shape.quadric_class != QuadricClass::kCone)
    return shape.size > 0 ? 1.0 / shape.size : 0.0;
  const double cos_half_angle = std::cos(shape.size);
  double sum = 0;
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - shape.point;
    sum += cos_half_angle / std::max((v - shape.direction.dot(v) * shape.direction).norm(), 1e-3);
  }
  return points.empty() ? 0.0 : sum / static_cast<double>(points.size());
}

}  // namespace quadric_slam
