// A textured wall facing the reference camera, rendered as an organized cloud with normals and a
// grey image registered to it from any camera pose: the view that depth alone leaves free along
// the wall (tests of the photometric refinement, unit and nodelet).
#pragma once

#include <cmath>
#include <cstdint>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "synthetic_scene.h"

namespace quadric_slam {
namespace synthetic {

// A wall at Z = kWallZ of the reference frame, textured by smooth waves of a few centimetres to
// decimetres (grey levels).
constexpr double kWallZ = 2.0;
inline double texture(double X, double Y) {
  return 128 + 40 * std::sin(9 * X) + 35 * std::cos(7 * Y) + 20 * std::sin(31 * (X + 0.5 * Y)) +
         15 * std::cos(23 * X - 17 * Y);
}

struct View {
  cv::Mat image;                            // CV_8UC1
  pcl::PointCloud<pcl::PointNormal> cloud;  // organized, camera frame
};

// The wall seen by a camera at T_reference_camera; uniform: a wall without texture.
inline View render(const Eigen::Isometry3d& T_reference_camera, bool uniform = false) {
  const CameraIntrinsics k = vgaIntrinsics();
  View view;
  view.image = cv::Mat(k.height, k.width, CV_8UC1);
  view.cloud = pcl::PointCloud<pcl::PointNormal>(k.width, k.height);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Eigen::Vector3d direction = T_reference_camera.linear() * ray;
      const double s = (kWallZ - T_reference_camera.translation().z()) / direction.z();
      const Eigen::Vector3d X = T_reference_camera.translation() + s * direction;
      const double grey = uniform ? 128.0 : texture(X.x(), X.y());
      view.image.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(std::round(grey));
      pcl::PointNormal& q = view.cloud(u, v);
      const Eigen::Vector3d P = s * ray;
      q.x = static_cast<float>(P.x());
      q.y = static_cast<float>(P.y());
      q.z = static_cast<float>(P.z());
      const Eigen::Vector3d n = -T_reference_camera.linear().transpose().col(2);
      q.normal_x = static_cast<float>(n.x());
      q.normal_y = static_cast<float>(n.y());
      q.normal_z = static_cast<float>(n.z());
    }
  }
  return view;
}

}  // namespace synthetic
}  // namespace quadric_slam
