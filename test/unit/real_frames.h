// Real TUM depth frames of ../shared/data/tum_frames for the unit tests.
#pragma once

#include <opencv2/imgcodecs.hpp>

#include <filesystem>

#include "quadric_slam/frontend/frame.h"

namespace quadric_slam {
namespace test {

// The first fr3_long_office_household depth frame (desk, globe, floor), back-projected with the
// Freiburg 3 intrinsics (shared/data/README.md); an empty cloud when the data is absent.
inline pcl::PointCloud<pcl::PointXYZ> fr3HouseholdCloud() {
  const std::filesystem::path file = std::filesystem::path(QUADRIC_SLAM_SHARED_DATA_DIR) /
                                     "tum_frames/fr3_long_office_household/1341847980.723020.png";
  const cv::Mat raw = cv::imread(file.string(), cv::IMREAD_ANYDEPTH);
  if (raw.empty() || raw.type() != CV_16UC1)
    return {};
  CameraIntrinsics k;
  k.fx = 535.4;
  k.fy = 539.2;
  k.cx = 320.1;
  k.cy = 247.6;
  k.width = raw.cols;
  k.height = raw.rows;
  DepthImageView<std::uint16_t> view;
  view.data = raw.data;
  view.width = raw.cols;
  view.height = raw.rows;
  view.row_step_bytes = raw.step;
  view.metres_per_unit = 1.0 / 5000.0;  // TUM PNG depth
  return backProject(view, k, {});
}

}  // namespace test
}  // namespace quadric_slam
