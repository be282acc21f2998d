#include "quadric_slam/frontend/ray_residual.h"

#include <algorithm>
#include <cmath>

namespace quadric_slam {

std::optional<double> rayResidual(const Eigen::Matrix4d& Q, const Eigen::Vector3d& point) {
  const double range = point.norm();
  if (!(range > 0))
    return std::nullopt;
  // Along the ray x(t) = point + t r (r unit): x^T Q x = a t^2 + b t + c.
  const Eigen::Vector4d x(point.x(), point.y(), point.z(), 1.0);
  const Eigen::Vector4d r(point.x() / range, point.y() / range, point.z() / range, 0.0);
  const Eigen::Vector4d Qr = Q * r;
  const double a = r.dot(Qr), b = 2.0 * x.dot(Qr), c = x.dot(Q * x);
  const double scale = std::max({std::abs(a), std::abs(b), std::abs(c)});
  if (!(scale > 0) || !std::isfinite(scale))
    return std::nullopt;
  if (std::abs(a) <= 1e-12 * scale) {  // the ray runs along an asymptotic direction: linear
    if (std::abs(b) <= 1e-12 * scale)
      return std::nullopt;
    return -c / b;
  }
  const double discriminant = b * b - 4.0 * a * c;
  if (discriminant < 0)
    return std::nullopt;
  // The two roots without cancellation; the one nearer the point.
  const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
  const double t1 = q / a;
  const double t2 = q != 0 ? c / q : t1;
  return std::abs(t1) < std::abs(t2) ? t1 : t2;
}

RayResidualStats rayResidualStats(const Eigen::Matrix4d& Q,
                                  const std::vector<Eigen::Vector3d>& points, double miss) {
  RayResidualStats stats;
  if (points.empty())
    return stats;
  double sum_sq = 0.0;
  int misses = 0;
  for (const Eigen::Vector3d& p : points) {
    const std::optional<double> t = rayResidual(Q, p);
    if (!t)
      ++misses;
    const double d = t ? std::min(std::abs(*t), miss) : miss;
    sum_sq += d * d;
  }
  const double n = static_cast<double>(points.size());
  stats.rms = std::sqrt(sum_sq / n);
  stats.miss_share = misses / n;
  return stats;
}

}  // namespace quadric_slam
