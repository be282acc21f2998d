#include "quadric_slam/frontend/segmentation_frame.h"

#include <algorithm>
#include <limits>

namespace quadric_slam {

std::vector<Eigen::Vector3d> pointsOf(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                      const std::vector<int>& indices) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(indices.size());
  for (int i : indices)
    points.push_back(pointOf(cloud.points[i]));
  return points;
}

double medianDepth(const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<int>& indices) {
  std::vector<float> z;
  z.reserve(indices.size());
  for (int i : indices)
    z.push_back(cloud.points[i].z);
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  return z[z.size() / 2];
}

ImageRoi roiOf(const std::vector<int>& indices, int width) {
  int x_min = std::numeric_limits<int>::max(), y_min = x_min, x_max = -1, y_max = -1;
  for (int i : indices) {
    const int x = i % width, y = i / width;
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
    y_min = std::min(y_min, y);
    y_max = std::max(y_max, y);
  }
  ImageRoi roi;
  if (x_max < 0)
    return roi;
  roi.x_offset = x_min;
  roi.y_offset = y_min;
  roi.width = x_max - x_min + 1;
  roi.height = y_max - y_min + 1;
  return roi;
}

ImageRoi grown(const ImageRoi& roi, int margin, int width, int height) {
  ImageRoi g;
  g.x_offset = std::max(0, roi.x_offset - margin);
  g.y_offset = std::max(0, roi.y_offset - margin);
  g.width = std::min(width, roi.x_offset + roi.width + margin) - g.x_offset;
  g.height = std::min(height, roi.y_offset + roi.height + margin) - g.y_offset;
  return g;
}

ImageRoi unite(const ImageRoi& a, const ImageRoi& b) {
  ImageRoi u;
  u.x_offset = std::min(a.x_offset, b.x_offset);
  u.y_offset = std::min(a.y_offset, b.y_offset);
  u.width = std::max(a.x_offset + a.width, b.x_offset + b.width) - u.x_offset;
  u.height = std::max(a.y_offset + a.height, b.y_offset + b.height) - u.y_offset;
  return u;
}

}  // namespace quadric_slam
