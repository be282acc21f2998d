// Fast normals for organized clouds: box-smoothed central differences, with the smoothing window
// shrunk so that it never contains a depth discontinuity or a pixel without data (the idea of
// Holzer et al. 2012, as in PCL's AVERAGE_3D_GRADIENT, written for speed).
//
// How it is fast (bench_normals compares it with PCL's methods in the same run):
// - summed-area tables in 32-bit fixed point with wrap-around arithmetic: a box sum is exact as
// long
//   as the box's own sum fits in 32 bits, which the scale guarantees, so a cell is 16 bytes (x, y,
//   z and the edge count) instead of PCL's doubles;
// - the tables live in a ring of rows per thread (a few hundred kilobytes, in cache) built as the
//   estimation sweeps down the image, never as a whole-frame table;
// - the edge count in the same table answers "does this window touch an edge?" in four look-ups,
//   so no distance transform is needed;
// - a normal is estimated at every stride-th pixel and shared within its block (not across edges);
// - every output point is written once.
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
  int stride = 1;   // estimate at every stride-th pixel in u and v, share within its block
};

// Points farther than this from the sensor (any coordinate, metres) are treated as no data: the
// fixed-point scale is chosen from the largest coordinate in the frame.
constexpr double kBoxGradientMaxCoordinate = 1000.0;

// Gives out the input's size (its storage reused when it already has it), header and is_dense =
// false: the output shape of every normal estimation method.
void shapeNormalsOutput(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                        pcl::PointCloud<pcl::PointNormal>& out);

// Fills out (resized to the input's size, its storage reused when it already has that size) with
// the input's points, their normals facing the sensor origin, and curvature NaN (not estimated by
// this method). Pixels without data, on an edge, or without room for a third of the smoothing
// window get NaN normals.
void computeBoxGradientNormals(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                               const BoxGradientSettings& settings,
                               pcl::PointCloud<pcl::PointNormal>& out);

}  // namespace quadric_slam
