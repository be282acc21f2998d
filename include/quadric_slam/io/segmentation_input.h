// One frame for the offline segmenter, its tests and its benchmark: a TUM-style depth PNG
// (back-projected with given intrinsics) or an organized PCD (x y z fields, e.g. the OSD scenes).
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>

#include "quadric_slam/frontend/frame.h"

namespace quadric_slam {

// path ending in .pcd: loads the organized cloud's x y z (intrinsics and units_per_metre unused);
// otherwise a 16-bit depth PNG with units_per_metre units per metre, back-projected at full
// resolution with intrinsics (width/height taken from the image). Throws std::runtime_error naming
// the file on failure (unreadable, not organized, not 16-bit).
pcl::PointCloud<pcl::PointXYZ> loadOrganizedCloud(const std::string& path,
                                                  const CameraIntrinsics& intrinsics,
                                                  double units_per_metre = 5000.0);

}  // namespace quadric_slam
