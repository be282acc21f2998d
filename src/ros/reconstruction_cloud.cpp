#include "quadric_slam/ros/reconstruction_cloud.h"

#include <sensor_msgs/point_cloud2_iterator.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>

#include "quadric_slam/ros/markers.h"

namespace quadric_slam {

sensor_msgs::PointCloud2 reconstructionCloudMsg(const pcl::PointCloud<pcl::PointXYZRGBL>& points,
                                                const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 msg;
  msg.header = header;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2Fields(
      5, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
      sensor_msgs::PointField::FLOAT32, "rgb", 1, sensor_msgs::PointField::FLOAT32, "label", 1,
      sensor_msgs::PointField::UINT32);
  modifier.resize(points.size());
  msg.height = 1;
  msg.width = static_cast<std::uint32_t>(points.size());
  msg.is_dense = true;
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), rgb(msg, "rgb");
  sensor_msgs::PointCloud2Iterator<std::uint32_t> label(msg, "label");
  std::map<std::uint32_t, float> packed_colours;  // one colour computation per landmark
  for (const pcl::PointXYZRGBL& p : points) {
    x[0] = p.x;
    x[1] = p.y;
    x[2] = p.z;
    *label = p.label;
    if ((p.rgba >> 24) != 0) {  // a colour from the RGB image
      const std::uint32_t rgba_bits = p.rgba | 0xFF000000u;
      std::memcpy(&*rgb, &rgba_bits, sizeof(float));
      ++x;
      ++rgb;
      ++label;
      continue;
    }
    auto colour = packed_colours.find(p.label);
    if (colour == packed_colours.end()) {
      const std_msgs::ColorRGBA c = landmarkColour(static_cast<int>(p.label), 1.0);
      auto byte = [](float v) {
        return static_cast<std::uint32_t>(std::lround(std::min(1.0f, std::max(0.0f, v)) * 255.0f));
      };
      const std::uint32_t rgb_bits = (byte(c.r) << 16) | (byte(c.g) << 8) | byte(c.b);
      float packed;
      std::memcpy(&packed, &rgb_bits, sizeof(packed));
      colour = packed_colours.emplace(p.label, packed).first;
    }
    *rgb = colour->second;
    ++x;
    ++rgb;
    ++label;
  }
  return msg;
}

}  // namespace quadric_slam
