// sensor_msgs/Image and CameraInfo into the core's depth types: both depth encodings (32FC1 metres,
// 16UC1 millimetres) go through one templated back-projection.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <string>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/ros/message_validation.h"

namespace quadric_slam {

// Intrinsics from camera_info's K and size (check .problem() before use).
CameraIntrinsics intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info);

// Back-projects a depth image into an organized cloud. Returns the problem that prevents it
// (depthImageProblem() of message_validation.h, the image size not matching the intrinsics, or a
// decimated cloud smaller than kMinGridSide on a side); cloud is untouched then.
std::string depthImageToCloud(const sensor_msgs::Image& image, const CameraIntrinsics& intrinsics,
                              const BackProjectionParams& params,
                              pcl::PointCloud<pcl::PointXYZ>& cloud);

}  // namespace quadric_slam
