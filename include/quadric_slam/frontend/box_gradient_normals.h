// Fast normals for organized clouds: box-smoothed central differences from integral images, with
// the smoothing window shrunk near depth discontinuities (the idea of Holzer et al. 2012, as in
// PCL's AVERAGE_3D_GRADIENT, written for speed: one pass to build the integral images, one distance
// transform, then a fixed number of look-ups per pixel, rows split over threads).
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace quadric_slam {

struct BoxGradientSettings {
  int max_half_window = 10;               // largest half-window of the smoothing box (pixels)
  double max_depth_change_factor = 0.02;  // neighbours differing by > factor * depth are an edge
  bool depth_dependent_smoothing =
      true;         // shrink the window for near points (half-window * z / 2 m)
  int threads = 2;  // worker threads over image rows
  int stride = 1;  // estimate at every stride-th pixel in u and v, share within its block
};

// Writes normals (facing the sensor origin) and curvature (NaN: not estimated by this method) into
// out, which has the input's size and already holds its points. Pixels on an edge, without data or
// without enough support get NaN normals.
void computeBoxGradientNormals(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                               const BoxGradientSettings& settings,
                               pcl::PointCloud<pcl::PointNormal>& out);

}  // namespace quadric_slam
