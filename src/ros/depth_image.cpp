#include "quadric_slam/ros/depth_image.h"

#include <sensor_msgs/image_encodings.h>

#include <cstdint>

namespace quadric_slam {
namespace {

namespace enc = sensor_msgs::image_encodings;

bool isMetres(const std::string& encoding) {
  return encoding == enc::TYPE_32FC1;
}

template <typename T>
DepthImageView<T> viewOf(const sensor_msgs::Image& image, double metres_per_unit) {
  DepthImageView<T> view;
  view.data = image.data.data();
  view.width = static_cast<int>(image.width);
  view.height = static_cast<int>(image.height);
  view.row_step_bytes = image.step;
  view.metres_per_unit = metres_per_unit;
  return view;
}

}  // namespace

CameraIntrinsics intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info) {
  CameraIntrinsics intrinsics;
  intrinsics.fx = info.K[0];
  intrinsics.fy = info.K[4];
  intrinsics.cx = info.K[2];
  intrinsics.cy = info.K[5];
  intrinsics.width = static_cast<int>(info.width);
  intrinsics.height = static_cast<int>(info.height);
  return intrinsics;
}

std::string depthImageToCloud(const sensor_msgs::Image& image, const CameraIntrinsics& intrinsics,
                              const BackProjectionParams& params,
                              pcl::PointCloud<pcl::PointXYZ>& cloud) {
  std::string problem = depthImageProblem(image);
  if (problem.empty()) {
    problem =
        imageSizeProblem(intrinsics, static_cast<int>(image.width), static_cast<int>(image.height));
  }
  if (!problem.empty())
    return problem;
  const int d = params.decimation;
  if (d < 1 || image.width / d < kMinGridSide || image.height / d < kMinGridSide) {
    return "depth image " + std::to_string(image.width) + " x " + std::to_string(image.height) +
           " at decimation " + std::to_string(d) + " leaves fewer than " +
           std::to_string(kMinGridSide) + " x " + std::to_string(kMinGridSide) + " points";
  }
  if (isMetres(image.encoding)) {
    cloud = backProject(viewOf<float>(image, 1.0), intrinsics, params);
  } else {
    cloud = backProject(viewOf<std::uint16_t>(image, 0.001), intrinsics, params);
  }
  return "";
}

}  // namespace quadric_slam
