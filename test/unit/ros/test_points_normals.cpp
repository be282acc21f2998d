// points_normals PointCloud2 -> core cloud, without a master.
#include <gtest/gtest.h>
#include <pcl_conversions/pcl_conversions.h>

#include "quadric_slam/ros/points_normals.h"

namespace qs = quadric_slam;

TEST(PointsNormals, RoundTripOfAnOrganizedCloud) {
  pcl::PointCloud<pcl::PointNormal> in(4, 3);
  for (std::size_t i = 0; i < in.size(); ++i) {
    in[i].x = 0.1f * i;
    in[i].y = -0.2f * i;
    in[i].z = 1.0f + i;
    in[i].normal_x = 0.f;
    in[i].normal_y = 0.6f;
    in[i].normal_z = -0.8f;
  }
  in[5].normal_x = std::nanf("");
  sensor_msgs::PointCloud2 msg;
  pcl::toROSMsg(in, msg);
  msg.header.frame_id = "optical";
  pcl::PointCloud<pcl::PointNormal> out;
  ASSERT_EQ(qs::pointsNormalsFromMsg(msg, out), "");
  ASSERT_EQ(out.width, 4u);
  ASSERT_EQ(out.height, 3u);
  EXPECT_EQ(out.header.frame_id, "optical");
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_FLOAT_EQ(out[i].x, in[i].x);
    EXPECT_FLOAT_EQ(out[i].z, in[i].z);
    if (i == 5) {
      EXPECT_TRUE(std::isnan(out[i].normal_x));
    } else {
      EXPECT_FLOAT_EQ(out[i].normal_z, -0.8f);
    }
  }
}

TEST(PointsNormals, CloudsWithoutNormalsOrMalformedAreRefused) {
  pcl::PointCloud<pcl::PointXYZ> xyz(4, 3);
  sensor_msgs::PointCloud2 msg;
  pcl::toROSMsg(xyz, msg);
  pcl::PointCloud<pcl::PointNormal> out;
  EXPECT_NE(qs::pointsNormalsFromMsg(msg, out).find("normal_x"), std::string::npos);
  EXPECT_TRUE(out.empty());

  pcl::PointCloud<pcl::PointNormal> with_normals(4, 3);
  pcl::toROSMsg(with_normals, msg);
  msg.data.resize(msg.data.size() / 2);
  EXPECT_NE(qs::pointsNormalsFromMsg(msg, out).find("data has"), std::string::npos);
  pcl::toROSMsg(with_normals, msg);
  msg.is_bigendian = true;
  EXPECT_NE(qs::pointsNormalsFromMsg(msg, out).find("big-endian"), std::string::npos);
}
