// Real TUM depth frames (test/data/tum_frames, shipped with the package) for the unit tests.
#pragma once

#include <filesystem>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/tum_folder_reader.h"
#include "test_data.h"

namespace quadric_slam {
namespace test {

// The first fr3_long_office_household depth frame (desk, globe, floor), relative to test/data.
inline constexpr char kFr3HouseholdDepth[] =
    "tum_frames/fr3_long_office_household/1341847980.723020.png";

// That frame back-projected with the Freiburg 3 intrinsics (throws if the file is missing).
inline pcl::PointCloud<pcl::PointXYZ> fr3HouseholdCloud() {
  const cv::Mat depth_m = readTumDepthPng(shippedData(kFr3HouseholdDepth).string());
  CameraIntrinsics k = tumIntrinsicsForSequence("fr3_long_office_household");
  k.width = depth_m.cols;
  k.height = depth_m.rows;
  return backProject(depthViewOf(depth_m), k, {});
}

}  // namespace test
}  // namespace quadric_slam
