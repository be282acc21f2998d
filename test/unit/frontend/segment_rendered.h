// A rendered depth image (CV_32FC1 metres, the Kinect VGA intrinsics of kinect_vga.h) through the
// project's normal estimator and segmenter with default parameters; what the segments hold of a
// rendered primitive's pixels.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "../kinect_vga.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/frame_source.h"

namespace quadric_slam {
namespace test {

inline Segmentation segmentRendered(const cv::Mat& depth) {
  const pcl::PointCloud<pcl::PointXYZ> cloud =
      backProject(depthViewOf(depth), kinectVga(), BackProjectionParams());
  const pcl::PointCloud<pcl::PointNormal> with_normals =
      NormalEstimator(NormalEstimator::Params()).compute(cloud);
  return QuadricSegmenter(QuadricSegmenter::Params()).segment(with_normals);
}

// How many of primitive t's pixels (truth label t + 1) each segment label holds (index 0: none);
// *total receives their number.
inline std::vector<int> labelCountsOn(const Segmentation& result, const cv::Mat& truth, int t,
                                      int* total) {
  std::vector<int> count(result.detections.size() + 1, 0);
  *total = 0;
  for (int y = 0; y < truth.rows; ++y)
    for (int x = 0; x < truth.cols; ++x)
      if (truth.at<std::uint16_t>(y, x) == t + 1) {
        ++*total;
        const std::uint16_t label = result.labels.at<std::uint16_t>(y, x);
        if (label < count.size())
          ++count[label];
      }
  return count;
}

}  // namespace test
}  // namespace quadric_slam
