// Checker for odometry.test: publishes camera_info and synthetic organized clouds with normals
// (ray-cast room corner, Kinect-like noise, project normals) along a known path and checks the
// odometry nodelet's odom messages and tf against the truth.
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <Eigen/Geometry>
#include <vector>

#include "../unit/odometry/synthetic_scene.h"
#include "odom_recorder.h"

namespace quadric_slam {
namespace {

constexpr int kDecimation = 2;

Eigen::Isometry3d pathPose(int i) {
  // 5 mm and about 0.15 degrees per frame in front of the room corner.
  const double s = i / 59.0;
  const Eigen::Vector3d eye(-0.3 + 0.25 * s, -0.3 + 0.1 * std::sin(2 * M_PI * s),
                            1.5 + 0.05 * std::sin(M_PI * s));
  const Eigen::Vector3d target(2.0 + 0.3 * std::sin(2 * M_PI * s), 2.0 - 0.2 * s,
                               0.7 + 0.1 * std::cos(2 * M_PI * s));
  return synthetic::lookAt(eye, target);
}

Eigen::Isometry3d fromMsg(const geometry_msgs::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
          .normalized()
          .toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return T;
}

class OdometryNodeletTest : public ::testing::Test {
 protected:
  void SetUp() override {
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("depth/camera_info", 1, true);
    cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("points_normals", 5);
    spinner_.start();
    const CameraIntrinsics k = synthetic::vgaIntrinsics();
    sensor_msgs::CameraInfo info;
    info.header.frame_id = "openni_rgb_optical_frame";
    info.width = k.width;
    info.height = k.height;
    info.K = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
    info_pub_.publish(info);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    while ((cloud_pub_.getNumSubscribers() == 0 || !odom_.hasPublisher()) &&
           ros::WallTime::now() < deadline)
      ros::WallDuration(0.05).sleep();
    ASSERT_GT(cloud_pub_.getNumSubscribers(), 0u) << "the odometry nodelet did not subscribe";
    ros::WallDuration(0.5).sleep();  // let the latched camera_info arrive
  }

  // Publishes and waits up to 10 s for the answer; false if none came.
  bool publishAndWait(const sensor_msgs::PointCloud2& cloud, double timeout = 10.0) {
    return odom_.publishAndWait([&] { cloud_pub_.publish(cloud); }, timeout);
  }

  static sensor_msgs::PointCloud2 frame(int i, double stamp) {
    auto cloud = synthetic::renderCloud(synthetic::roomScene(), pathPose(i),
                                        synthetic::vgaIntrinsics(), kDecimation, 0.0015, 40 + i);
    sensor_msgs::PointCloud2 msg;
    pcl::toROSMsg(*cloud, msg);
    msg.header.stamp = ros::Time(stamp);
    msg.header.frame_id = "openni_rgb_optical_frame";
    return msg;
  }

  ros::NodeHandle nh_;
  ros::AsyncSpinner spinner_{1};
  ros::Publisher info_pub_, cloud_pub_;
  OdomRecorder odom_{nh_};
};

TEST_F(OdometryNodeletTest, TracksSequenceDropsBadCloudsAndResetsOnTimeJump) {
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);
  const int frames = 25;
  const double t0 = 1000.0;
  const Eigen::Isometry3d T_world_first = pathPose(0);
  for (int i = 0; i < frames; ++i)
    ASSERT_TRUE(publishAndWait(frame(i, t0 + i / 30.0))) << "no odom for frame " << i;

  nav_msgs::Odometry last;
  {
    const std::vector<nav_msgs::Odometry> odom = odom_.messages();
    ASSERT_EQ(odom.size(), static_cast<std::size_t>(frames));
    last = odom.back();
    EXPECT_TRUE(fromMsg(odom.front().pose.pose).isApprox(Eigen::Isometry3d::Identity(), 1e-9));
  }
  EXPECT_EQ(last.header.frame_id, "odom");
  EXPECT_EQ(last.child_frame_id, "camera");
  EXPECT_NEAR(last.header.stamp.toSec(), t0 + (frames - 1) / 30.0, 1e-6);
  const Eigen::Isometry3d truth = T_world_first.inverse() * pathPose(frames - 1);
  const Eigen::Isometry3d estimate = fromMsg(last.pose.pose);
  EXPECT_GT(truth.translation().norm(), 0.08);  // the camera did move
  EXPECT_LT((estimate.translation() - truth.translation()).norm(), 5e-3);
  EXPECT_LT(Eigen::AngleAxisd((estimate.inverse() * truth).linear()).angle(), 0.3 * M_PI / 180);
  // Covariance: positive variances, sub-centimetre position standard deviation.
  for (int i = 0; i < 6; ++i)
    EXPECT_GT(last.pose.covariance[7 * i], 0.0);
  EXPECT_LT(std::sqrt(last.pose.covariance[0]), 0.01);

  // The same pose on tf.
  geometry_msgs::TransformStamped tf;
  ASSERT_NO_THROW(
      tf = tf_buffer.lookupTransform("odom", "camera", last.header.stamp, ros::Duration(5.0)));
  EXPECT_NEAR(tf.transform.translation.x, last.pose.pose.position.x, 1e-9);
  EXPECT_NEAR(tf.transform.translation.z, last.pose.pose.position.z, 1e-9);
  EXPECT_NEAR(tf.transform.rotation.w, last.pose.pose.orientation.w, 1e-9);

  // A cloud without normal fields is dropped (no odom).
  {
    pcl::PointCloud<pcl::PointXYZ> xyz = synthetic::renderDepth(
        synthetic::roomScene(), pathPose(frames), synthetic::vgaIntrinsics(), kDecimation, 0, 1);
    sensor_msgs::PointCloud2 msg;
    pcl::toROSMsg(xyz, msg);
    msg.header.stamp = ros::Time(t0 + frames / 30.0);
    EXPECT_FALSE(publishAndWait(msg, 1.5)) << "a cloud without normals was tracked";
  }
  // A cloud whose size fits no decimation of camera_info is dropped.
  {
    pcl::PointCloud<pcl::PointNormal> odd(300, 200);
    sensor_msgs::PointCloud2 msg;
    pcl::toROSMsg(odd, msg);
    msg.header.stamp = ros::Time(t0 + frames / 30.0);
    EXPECT_FALSE(publishAndWait(msg, 1.5)) << "a cloud of the wrong size was tracked";
  }

  // Time going backwards (a looping bag): reset, the odom frame restarts at this frame.
  ASSERT_TRUE(publishAndWait(frame(10, t0 - 5.0)));
  { EXPECT_TRUE(fromMsg(odom_.last().pose.pose).isApprox(Eigen::Isometry3d::Identity(), 1e-9)); }
  // ... and tracking continues from there.
  ASSERT_TRUE(publishAndWait(frame(11, t0 - 5.0 + 1 / 30.0)));
  {
    const Eigen::Isometry3d step = pathPose(10).inverse() * pathPose(11);
    EXPECT_LT((fromMsg(odom_.last().pose.pose).translation() - step.translation()).norm(), 2e-3);
  }
}

}  // namespace
}  // namespace quadric_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "odometry_checker");
  const int result = RUN_ALL_TESTS();
  ros::shutdown();
  return result;
}
