#include "quadric_slam/frontend/boundary_labels.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "quadric_slam/frontend/plane_region_grower.h"

namespace quadric_slam {

namespace {

// Calls fn(index) for each of the indices in order, with the cloud's point a few indices ahead
// requested from memory meanwhile: the rim's pixels are scattered over the 15 MB cloud, and
// reading them one at a time waited on memory for most of the stage.
template <typename Fn>
void forEachPoint(const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<int>& indices,
                  Fn fn) {
  constexpr std::size_t kAhead = 16;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (k + kAhead < indices.size())
      __builtin_prefetch(&cloud.points[indices[k + kAhead]]);
    fn(indices[k]);
  }
}

}  // namespace

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
  // Each detection's own noise level: rim points must fit as well as its supporting points.
  std::vector<double> gate(n);
  for (int k = 0; k < n; ++k)
    gate[k] = std::max(1e-3, settings.rms_multiple * segmentation.detections[k].fit_rms);
  // Labels of detections only (defensive: a label without a detection is never spread).
  const auto owner = [&](std::uint16_t label) { return label >= 1 && label <= n ? label : 0; };

  // A pixel may join when it is unlabelled, has depth in range and no normal. Only pixels next to
  // the labels are examined (the label image is read first, the cloud only there), so the work
  // follows the rim, not the image.
  const auto mayJoin = [&](const pcl::PointNormal& q) {
    return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
           q.z >= settings.min_range && q.z <= settings.max_range && !std::isfinite(q.normal_x);
  };
  const auto forEachNeighbour = [&](int index, auto fn) {
    const int u = index % width, v = index / width;
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        const int nu = u + du, nv = v + dv;
        if ((du != 0 || dv != 0) && nu >= 0 && nv >= 0 && nu < width && nv < height)
          fn(nv * width + nu, nu, nv);
      }
    }
  };
  std::vector<std::uint8_t> queued(cloud.size(), 0);
  // The first front: candidates next to a labelled pixel, found with a 3x3 dilation of the mask of
  // the labelled pixels (OpenCV's vectorised mask operations: about a tenth of a millisecond on a
  // VGA frame, where a pixel-by-pixel scan took most of a millisecond). The cloud is read only
  // there.
  cv::Mat labelled, near_label;
  cv::inRange(labels, cv::Scalar(1), cv::Scalar(n), labelled);
  cv::dilate(labelled, near_label, cv::Mat::ones(3, 3, CV_8U));
  near_label.setTo(0, labels != 0);
  // A candidate keeps its point: the ring reads it again only after the whole image was scanned,
  // when the cloud's memory there has left the cache.
  struct Candidate {
    int index;
    Eigen::Vector3f point;
  };
  // The mask is mostly zero: it is read eight pixels at a time (0.3 -> 0.04 ms a frame).
  std::vector<int> near_pixels;
  for (int v = 0; v < height; ++v) {
    const std::uint8_t* near = near_label.ptr<std::uint8_t>(v);
    for (int u0 = 0; u0 < width; u0 += 8) {
      const int u1 = std::min(width, u0 + 8);
      std::uint64_t eight = 1;
      if (u1 - u0 == 8)
        std::memcpy(&eight, near + u0, sizeof(eight));
      if (eight == 0)
        continue;
      for (int u = u0; u < u1; ++u)
        if (near[u] != 0)
          near_pixels.push_back(v * width + u);
    }
  }
  std::vector<Candidate> front;
  forEachPoint(cloud, near_pixels, [&](int index) {
    if (mayJoin(cloud.points[index])) {
      queued[index] = 1;
      front.push_back({index, cloud.points[index].getVector3fMap()});
    }
  });
  for (int ring = 0; ring < settings.rings && !front.empty(); ++ring) {
    // Each ring reads the labels of the previous one only, so growth is one pixel per ring.
    std::vector<std::pair<Candidate, std::uint16_t>> joined;
    for (const Candidate& candidate : front) {
      const int index = candidate.index;
      const Eigen::Vector3d point = candidate.point.cast<double>();
      const double threshold =
          depthThreshold(point.z(), settings.distance_factor, settings.min_distance);
      double best_distance = threshold;
      std::uint16_t best = 0;
      std::uint16_t tried[8];  // each bordering surface is measured once
      int tried_count = 0;
      forEachNeighbour(index, [&](int, int nu, int nv) {
        const std::uint16_t label = owner(labels.at<std::uint16_t>(nv, nu));
        if (label == 0 || std::find(tried, tried + tried_count, label) != tried + tried_count)
          return;
        tried[tried_count++] = label;
        const QuadricDetection& detection = segmentation.detections[label - 1];
        const double distance = std::abs(detection.shape.distance(point));
        if (distance < best_distance && distance < gate[label - 1]) {
          best_distance = distance;
          best = label;
        }
      });
      if (best != 0)
        joined.push_back({candidate, best});
      else
        queued[index] = 0;  // may be reached again from a neighbour that joins later
    }
    std::vector<Candidate> next_front;
    for (const auto& [candidate, label] : joined) {
      const int index = candidate.index;
      const int u = index % width, v = index / width;
      labels.at<std::uint16_t>(v, u) = label;
      QuadricDetection& detection = segmentation.detections[label - 1];
      ++detection.num_points;
      const Eigen::Vector3d local = T_quadric_camera[label - 1] * candidate.point.cast<double>();
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
    // The next front: the free neighbours of the joined pixels, each listed once (marked while
    // listed), then read from the cloud; those that may not join are unmarked again.
    std::vector<int> neighbours;
    for (const auto& [candidate, label] : joined) {
      forEachNeighbour(candidate.index, [&](int neighbour, int nu, int nv) {
        if (!queued[neighbour] && labels.at<std::uint16_t>(nv, nu) == 0) {
          queued[neighbour] = 1;
          neighbours.push_back(neighbour);
        }
      });
    }
    forEachPoint(cloud, neighbours, [&](int index) {
      if (mayJoin(cloud.points[index]))
        next_front.push_back({index, cloud.points[index].getVector3fMap()});
      else
        queued[index] = 0;
    });
    front.swap(next_front);
  }
}

}  // namespace quadric_slam
