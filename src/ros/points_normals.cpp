#include "quadric_slam/ros/points_normals.h"

#include <cstring>

#include "quadric_slam/ros/message_validation.h"

#include "quadric_slam/ros/frame_ids.h"

namespace quadric_slam {
namespace {

std::uint32_t fieldOffset(const sensor_msgs::PointCloud2& msg, const std::string& name) {
  for (const auto& field : msg.fields) {
    if (field.name == name)
      return field.offset;
  }
  return 0;  // not reached: pointCloudProblem() found every field
}

}  // namespace

std::string pointsNormalsFromMsg(const sensor_msgs::PointCloud2& msg,
                                 pcl::PointCloud<pcl::PointNormal>& cloud) {
  const std::string problem = pointCloudProblem(msg, pointsNormalsLayout());
  if (!problem.empty())
    return problem;
  const std::vector<std::string>& names = pointsNormalsLayout().float32_fields;
  std::uint32_t offsets[6];
  for (int i = 0; i < 6; ++i)
    offsets[i] = fieldOffset(msg, names[i]);
  cloud.header.frame_id = withoutLeadingSlash(msg.header.frame_id);
  cloud.width = msg.width;
  cloud.height = msg.height;
  cloud.is_dense = false;
  cloud.points.resize(static_cast<std::size_t>(msg.width) * msg.height);
  for (std::uint32_t row = 0; row < msg.height; ++row) {
    const std::uint8_t* line = msg.data.data() + static_cast<std::size_t>(row) * msg.row_step;
    for (std::uint32_t col = 0; col < msg.width; ++col) {
      const std::uint8_t* in = line + static_cast<std::size_t>(col) * msg.point_step;
      float v[6];
      for (int i = 0; i < 6; ++i)
        std::memcpy(&v[i], in + offsets[i], sizeof(float));
      pcl::PointNormal& p = cloud.points[static_cast<std::size_t>(row) * msg.width + col];
      p.x = v[0];
      p.y = v[1];
      p.z = v[2];
      p.normal_x = v[3];
      p.normal_y = v[4];
      p.normal_z = v[5];
      p.curvature = 0.f;
    }
  }
  return "";
}

}  // namespace quadric_slam
