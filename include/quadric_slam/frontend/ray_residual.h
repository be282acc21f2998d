// The residual a depth camera makes: its error lies along the ray through the pixel, so a surface
// model explains a measured point by how far along that ray the surface lies. An orthogonal or
// first-order (Sampson) distance can be much smaller than that where the model bends away within
// the noise band: a general quadric fitted to a noisy strip of a cylinder 2 m away scored a third
// lower RMS than the cylinder by its Sampson distance while a tenth of the strip's rays missed it
// altogether and, along the rays, it fitted no better than the cylinder.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace quadric_slam {

// Signed distance (m) from point along the ray from the camera centre (the origin) through it to
// the nearest intersection with the quadric x^T Q x = 0 (x homogeneous, camera coordinates):
// positive when the surface lies beyond the point. None when the ray's line misses the surface.
std::optional<double> rayResidual(const Eigen::Matrix4d& Q, const Eigen::Vector3d& point);

struct RayResidualStats {
  double rms = 0.0;         // RMS over the points, each miss counted as the miss distance (m)
  double miss_share = 0.0;  // share of the points whose ray misses the surface
};

// The ray residuals of points, each miss (and each residual beyond it) counted as `miss` (m).
RayResidualStats rayResidualStats(const Eigen::Matrix4d& Q,
                                  const std::vector<Eigen::Vector3d>& points, double miss);

}  // namespace quadric_slam
