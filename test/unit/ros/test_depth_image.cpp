// sensor_msgs depth images and camera_info into the core types, without a master.
#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <cstring>

#include "quadric_slam/ros/depth_image.h"

namespace qs = quadric_slam;
namespace enc = sensor_msgs::image_encodings;

namespace {

sensor_msgs::CameraInfo info(int width, int height) {
  sensor_msgs::CameraInfo msg;
  msg.width = width;
  msg.height = height;
  msg.K = {500.0, 0, 3.5, 0, 400.0, 2.5, 0, 0, 1};
  return msg;
}

sensor_msgs::Image image(const std::string& encoding, int width, int height, int pad_bytes) {
  sensor_msgs::Image msg;
  msg.encoding = encoding;
  msg.width = width;
  msg.height = height;
  const int bytes = encoding == enc::TYPE_32FC1 ? 4 : 2;
  msg.step = width * bytes + pad_bytes;
  msg.data.assign(msg.step * height, 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double z = 1.0 + 0.1 * u + 0.01 * v;  // metres
      std::uint8_t* pixel = &msg.data[v * msg.step + u * bytes];
      if (bytes == 4) {
        const float f = static_cast<float>(z);
        std::memcpy(pixel, &f, 4);
      } else {
        const std::uint16_t mm = static_cast<std::uint16_t>(std::lround(z * 1000));
        std::memcpy(pixel, &mm, 2);
      }
    }
  }
  return msg;
}

}  // namespace

TEST(DepthImage, IntrinsicsFromCameraInfo) {
  const qs::CameraIntrinsics k = qs::intrinsicsFromCameraInfo(info(8, 6));
  EXPECT_DOUBLE_EQ(k.fx, 500.0);
  EXPECT_DOUBLE_EQ(k.fy, 400.0);
  EXPECT_DOUBLE_EQ(k.cx, 3.5);
  EXPECT_DOUBLE_EQ(k.cy, 2.5);
  EXPECT_EQ(k.width, 8);
  EXPECT_EQ(k.height, 6);
  EXPECT_FALSE(qs::intrinsicsFromCameraInfo(sensor_msgs::CameraInfo()).valid());
}

TEST(DepthImage, BothEncodingsWithPaddedRowsGiveTheSameCloud) {
  const qs::CameraIntrinsics k = qs::intrinsicsFromCameraInfo(info(8, 6));
  pcl::PointCloud<pcl::PointXYZ> metres, millimetres;
  ASSERT_EQ(qs::depthImageToCloud(image(enc::TYPE_32FC1, 8, 6, 4), k, {}, metres), "");
  ASSERT_EQ(qs::depthImageToCloud(image(enc::TYPE_16UC1, 8, 6, 2), k, {}, millimetres), "");
  ASSERT_EQ(metres.width, 8u);
  ASSERT_EQ(metres.height, 6u);
  for (int v = 0; v < 6; ++v) {
    for (int u = 0; u < 8; ++u) {
      const double z = 1.0 + 0.1 * u + 0.01 * v;
      EXPECT_NEAR(metres(u, v).z, z, 1e-6);
      EXPECT_NEAR(metres(u, v).x, (u - 3.5) * z / 500.0, 1e-6);
      EXPECT_NEAR(metres(u, v).y, (v - 2.5) * z / 400.0, 1e-6);
      EXPECT_NEAR(millimetres(u, v).z, z, 0.5e-3);
    }
  }
}

TEST(DepthImage, BadInputIsRefusedWithAReason) {
  const qs::CameraIntrinsics k = qs::intrinsicsFromCameraInfo(info(8, 6));
  pcl::PointCloud<pcl::PointXYZ> cloud;
  EXPECT_NE(qs::depthImageToCloud(image(enc::RGB8, 8, 6, 0), k, {}, cloud).find("encoding"),
            std::string::npos);
  EXPECT_NE(qs::depthImageToCloud(image(enc::TYPE_32FC1, 4, 3, 0), k, {}, cloud).find("4 x 3"),
            std::string::npos);
  sensor_msgs::Image short_buffer = image(enc::TYPE_32FC1, 8, 6, 0);
  short_buffer.data.resize(10);
  EXPECT_NE(qs::depthImageToCloud(short_buffer, k, {}, cloud).find("data has"), std::string::npos);
  sensor_msgs::Image big_endian = image(enc::TYPE_16UC1, 8, 6, 0);
  big_endian.is_bigendian = 1;
  EXPECT_NE(qs::depthImageToCloud(big_endian, k, {}, cloud).find("big-endian"), std::string::npos);
  EXPECT_TRUE(cloud.empty()) << "a refused image must leave the cloud untouched";
}
