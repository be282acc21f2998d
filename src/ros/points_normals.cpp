#include "quadric_slam/ros/points_normals.h"

#include <cstring>
#include <sstream>

#include "quadric_slam/ros/frame_ids.h"

namespace quadric_slam {
namespace {

// Byte offset of a float32 field with one element that fits in a point, or -1.
int floatField(const sensor_msgs::PointCloud2& msg, const std::string& name) {
  for (const auto& field : msg.fields) {
    if (field.name == name) {
      const bool ok = field.datatype == sensor_msgs::PointField::FLOAT32 && field.count == 1 &&
                      field.offset + sizeof(float) <= msg.point_step;
      return ok ? static_cast<int>(field.offset) : -1;
    }
  }
  return -1;
}

}  // namespace

std::string pointsNormalsFromMsg(const sensor_msgs::PointCloud2& msg,
                                 pcl::PointCloud<pcl::PointNormal>& cloud) {
  const char* const names[6] = {"x", "y", "z", "normal_x", "normal_y", "normal_z"};
  int offsets[6];
  for (int i = 0; i < 6; ++i) {
    offsets[i] = floatField(msg, names[i]);
    if (offsets[i] < 0) {
      return std::string("cloud has no float32 field '") + names[i] +
             "' (needs x y z normal_x normal_y normal_z, e.g. from quadric_slam/NormalEstimation)";
    }
  }
  if (msg.is_bigendian)
    return "big-endian clouds are not supported";
  if (msg.data.size() < static_cast<std::size_t>(msg.row_step) * msg.height ||
      msg.row_step < msg.point_step * msg.width) {
    std::ostringstream why;
    why << "malformed cloud (" << msg.width << " x " << msg.height << ", point_step "
        << msg.point_step << ", row_step " << msg.row_step << ", " << msg.data.size() << " bytes)";
    return why.str();
  }
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
