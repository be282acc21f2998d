#include "quadric_slam/ros/depth_image.h"

#include <sensor_msgs/image_encodings.h>

#include <cstdint>
#include <sstream>

namespace quadric_slam {
namespace {

namespace enc = sensor_msgs::image_encodings;

bool isMetres(const std::string& encoding) {
  return encoding == enc::TYPE_32FC1;
}
bool isMillimetres(const std::string& encoding) {
  return encoding == enc::TYPE_16UC1 || encoding == enc::MONO16;
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

std::string depthImageProblem(const sensor_msgs::Image& image) {
  std::size_t pixel_bytes = 0;
  if (isMetres(image.encoding)) {
    pixel_bytes = sizeof(float);
  } else if (isMillimetres(image.encoding)) {
    pixel_bytes = sizeof(std::uint16_t);
  } else {
    return "unsupported depth encoding '" + image.encoding +
           "' (expected 32FC1 metres or 16UC1 millimetres)";
  }
  if (image.is_bigendian)
    return "big-endian depth images are not supported";
  if (image.step < image.width * pixel_bytes ||
      image.data.size() < static_cast<std::size_t>(image.step) * image.height) {
    std::ostringstream why;
    why << "malformed " << image.encoding << " image (" << image.width << " x " << image.height
        << ", step " << image.step << ", " << image.data.size() << " bytes)";
    return why.str();
  }
  return "";
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
  if (isMetres(image.encoding)) {
    cloud = backProject(viewOf<float>(image, 1.0), intrinsics, params);
  } else {
    cloud = backProject(viewOf<std::uint16_t>(image, 0.001), intrinsics, params);
  }
  return "";
}

}  // namespace quadric_slam
