// Real TUM depth frames of ../shared/data/tum_frames for the unit tests.
#pragma once

#include <filesystem>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/tum_folder_reader.h"

namespace quadric_slam {
namespace test {

// The first fr3_long_office_household depth frame (desk, globe, floor), back-projected with the
// Freiburg 3 intrinsics; an empty cloud when the data is absent.
inline pcl::PointCloud<pcl::PointXYZ> fr3HouseholdCloud() {
  const std::filesystem::path file = std::filesystem::path(QUADRIC_SLAM_SHARED_DATA_DIR) /
                                     "tum_frames/fr3_long_office_household/1341847980.723020.png";
  if (!std::filesystem::exists(file))
    return {};
  const cv::Mat depth_m = readTumDepthPng(file.string());
  CameraIntrinsics k = tumIntrinsicsForSequence("fr3_long_office_household");
  k.width = depth_m.cols;
  k.height = depth_m.rows;
  return backProject(depthViewOf(depth_m), k, {});
}

}  // namespace test
}  // namespace quadric_slam
