// The organized points_normals cloud (PointCloud2 with float32 x y z normal_x normal_y normal_z,
// as published by quadric_slam/NormalEstimation) into the core's point type, for every consumer.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/PointCloud2.h>

#include <string>

namespace quadric_slam {

// Copies x y z normal_x normal_y normal_z by field offset (curvature need not be present; it is
// set to 0). Returns the problem that prevents it (pointCloudProblem() with pointsNormalsLayout(),
// message_validation.h); cloud is left untouched then. Reuses cloud's storage. The cloud's frame id
// is the message's without a leading '/'.
std::string pointsNormalsFromMsg(const sensor_msgs::PointCloud2& msg,
                                 pcl::PointCloud<pcl::PointNormal>& cloud);

}  // namespace quadric_slam
