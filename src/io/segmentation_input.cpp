#include "quadric_slam/io/segmentation_input.h"

#include <pcl/io/pcd_io.h>

#include <stdexcept>

#include "quadric_slam/io/depth_png.h"

namespace quadric_slam {

pcl::PointCloud<pcl::PointXYZ> loadOrganizedCloud(const std::string& path,
                                                  const CameraIntrinsics& intrinsics,
                                                  double units_per_metre) {
  const bool pcd = path.size() > 4 && path.compare(path.size() - 4, 4, ".pcd") == 0;
  if (pcd) {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    if (pcl::io::loadPCDFile(path, cloud) != 0)
      throw std::runtime_error("cannot read the PCD file " + path);
    if (!cloud.isOrganized())
      throw std::runtime_error(path + " is not an organized cloud");
    return cloud;
  }
  const cv::Mat metres = readTumDepthPng(path, units_per_metre);
  CameraIntrinsics k = intrinsics;
  k.width = metres.cols;
  k.height = metres.rows;
  const std::string problem = k.problem();
  if (!problem.empty())
    throw std::runtime_error("intrinsics for " + path + ": " + problem);
  DepthImageView<float> view;
  view.data = metres.data;
  view.width = metres.cols;
  view.height = metres.rows;
  view.row_step_bytes = metres.step[0];
  view.metres_per_unit = 1.0;
  return backProject(view, k, BackProjectionParams());
}

}  // namespace quadric_slam
