#include "quadric_slam/frontend/boundary_labels.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "quadric_slam/frontend/plane_region_grower.h"

namespace quadric_slam {

void completeBoundaryLabels(const pcl::PointCloud<pcl::PointNormal>& cloud,
                            const BoundaryCompletion& settings, Segmentation& segmentation) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  cv::Mat& labels = segmentation.labels;
  const int n = static_cast<int>(segmentation.detections.size());
  if (settings.rings <= 0 || n == 0 || labels.rows != height || labels.cols != width)
    return;
  std::vector<Eigen::Isometry3d> T_quadric_camera(n);
  for (int k = 0; k < n; ++k)
    T_quadric_camera[k] = segmentation.detections[k].shape.quadric().pose().inverse();
  // Labels of detections only (defensive: a label without a detection is never spread).
  const auto owner = [&](std::uint16_t label) { return label >= 1 && label <= n ? label : 0; };

  std::vector<int> candidates;  // pixels with depth, without a normal, unlabelled
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const pcl::PointNormal& q = cloud(u, v);
      if (labels.at<std::uint16_t>(v, u) == 0 && std::isfinite(q.x) && std::isfinite(q.y) &&
          std::isfinite(q.z) && q.z >= settings.min_range && q.z <= settings.max_range &&
          !std::isfinite(q.normal_x))
        candidates.push_back(v * width + u);
    }
  }
  for (int ring = 0; ring < settings.rings && !candidates.empty(); ++ring) {
    // Each ring reads the labels of the previous one only, so growth is one pixel per ring.
    std::vector<std::pair<int, std::uint16_t>> joined;
    std::vector<int> remaining;
    for (const int index : candidates) {
      const int u = index % width, v = index / width;
      const pcl::PointNormal& q = cloud.points[index];
      const Eigen::Vector3d point(q.x, q.y, q.z);
      double best_distance = depthThreshold(q.z, settings.distance_factor, settings.min_distance);
      std::uint16_t best = 0;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const int nu = u + du, nv = v + dv;
          if ((du == 0 && dv == 0) || nu < 0 || nv < 0 || nu >= width || nv >= height)
            continue;
          const std::uint16_t label = owner(labels.at<std::uint16_t>(nv, nu));
          if (label == 0 || label == best)
            continue;
          const double distance =
              std::abs(segmentation.detections[label - 1].shape.distance(point));
          if (distance < best_distance) {
            best_distance = distance;
            best = label;
          }
        }
      }
      if (best != 0)
        joined.emplace_back(index, best);
      else
        remaining.push_back(index);
    }
    if (joined.empty())
      break;
    for (const auto& [index, label] : joined) {
      const int u = index % width, v = index / width;
      labels.at<std::uint16_t>(v, u) = label;
      QuadricDetection& detection = segmentation.detections[label - 1];
      ++detection.num_points;
      const pcl::PointNormal& q = cloud.points[index];
      const Eigen::Vector3d local = T_quadric_camera[label - 1] * Eigen::Vector3d(q.x, q.y, q.z);
      detection.extent_min = detection.extent_min.cwiseMin(local);
      detection.extent_max = detection.extent_max.cwiseMax(local);
      ImageRoi& roi = detection.roi;
      const int x1 = std::max(roi.x_offset + roi.width - 1, u);
      const int y1 = std::max(roi.y_offset + roi.height - 1, v);
      roi.x_offset = std::min(roi.x_offset, u);
      roi.y_offset = std::min(roi.y_offset, v);
      roi.width = x1 - roi.x_offset + 1;
      roi.height = y1 - roi.y_offset + 1;
    }
    candidates.swap(remaining);
  }
}

}  // namespace quadric_slam
