// A depth frame and its pinhole intrinsics, and their back-projection into an organized cloud.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// Back-projection limits and sub-sampling of a depth image.
struct BackProjectionParams {
  int decimation = 1;      // keep every decimation-th pixel in u and v (1 = full resolution)
  double min_range = 0.1;  // depths below this are treated as no data (m)
  double max_range = 8.0;  // depths beyond this are treated as no data (m)

  // Throws std::invalid_argument naming the bad field and its allowed range.
  void validate() const;
};

// A read-only view of a row-major depth image with pixels of type T (float metres or uint16
// millimetres); row_step_bytes may exceed width * sizeof(T) (padded rows, as in ROS images).
template <typename T>
struct DepthImageView {
  const std::uint8_t* data = nullptr;
  int width = 0, height = 0;
  std::size_t row_step_bytes = 0;
  double metres_per_unit =
      1.0;  // 1 for 32FC1 metres, 0.001 for 16UC1 millimetres, 1/5000 for TUM PNG

  T at(int u, int v) const {
    return *reinterpret_cast<const T*>(data + static_cast<std::size_t>(v) * row_step_bytes +
                                       static_cast<std::size_t>(u) * sizeof(T));
  }
};

// Converts one raw depth value to metres, or NaN when it holds no data (0, NaN, inf, out of range).
template <typename T>
inline float depthInMetres(T raw, double metres_per_unit, const BackProjectionParams& params) {
  const double z = static_cast<double>(raw) * metres_per_unit;
  if (!std::isfinite(z) || z < params.min_range || z > params.max_range) {
    return std::numeric_limits<float>::quiet_NaN();
  }
  return static_cast<float>(z);
}

// Organized cloud of size (width / decimation) x (height / decimation), point (u, v) back-projected
// from pixel (u * decimation, v * decimation) with the full-resolution intrinsics; NaN where there
// is no data. The image size must match the intrinsics (the caller checks: see problem()).
template <typename T>
pcl::PointCloud<pcl::PointXYZ> backProject(const DepthImageView<T>& depth,
                                           const CameraIntrinsics& intrinsics,
                                           const BackProjectionParams& params) {
  const int step = params.decimation;
  pcl::PointCloud<pcl::PointXYZ> cloud(depth.width / step, depth.height / step);
  cloud.is_dense = false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double inv_fx = 1.0 / intrinsics.fx, inv_fy = 1.0 / intrinsics.fy;
  for (int row = 0; row < static_cast<int>(cloud.height); ++row) {
    const int v = row * step;
    for (int col = 0; col < static_cast<int>(cloud.width); ++col) {
      const int u = col * step;
      pcl::PointXYZ& p = cloud(col, row);
      const float z = depthInMetres(depth.at(u, v), depth.metres_per_unit, params);
      if (std::isnan(z)) {
        p.x = p.y = p.z = nan;
        continue;
      }
      p.x = static_cast<float>((u - intrinsics.cx) * z * inv_fx);
      p.y = static_cast<float>((v - intrinsics.cy) * z * inv_fy);
      p.z = z;
    }
  }
  return cloud;
}

}  // namespace quadric_slam
