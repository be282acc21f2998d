// One frame as the segmenter's steps share it: the organized cloud with normals, which of its points
// are valid (finite, in range) and which a segment has already taken; and small helpers on pixel
// indices of such a grid (points, normals, median depth, image boxes).
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "quadric_slam/types/observation.h"  // ImageRoi

namespace quadric_slam {

struct SegmentationFrame {
  const pcl::PointCloud<pcl::PointNormal>& cloud;
  int width, height;
  std::vector<std::uint8_t> valid, used;  // per pixel, 0 or 1
};

inline Eigen::Vector3d pointOf(const pcl::PointNormal& p) {
  return Eigen::Vector3d(p.x, p.y, p.z);
}
inline Eigen::Vector3d normalOf(const pcl::PointNormal& p) {
  return Eigen::Vector3d(p.normal_x, p.normal_y, p.normal_z);
}

// The points of the given pixel indices.
std::vector<Eigen::Vector3d> pointsOf(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                      const std::vector<int>& indices);
// Median depth (z) of the given pixels; requires at least one.
double medianDepth(const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<int>& indices);
// The bounding box of pixel indices on a grid of the given width (empty ImageRoi when none).
ImageRoi roiOf(const std::vector<int>& indices, int width);
// roi grown by margin pixels on each side, clipped to the width x height image.
ImageRoi grown(const ImageRoi& roi, int margin, int width, int height);
// The smallest box holding both.
ImageRoi unite(const ImageRoi& a, const ImageRoi& b);

}  // namespace quadric_slam
