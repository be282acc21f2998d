// Checker for odometry_photometric.test: the odometry nodelet with photometric_refinement, fed a
// camera sliding along a textured wall (depth alone leaves the slide free) as clouds with normals
// and registered grey images with their camera_info; checks that odom follows the slide, and that
// a cloud whose image never comes is still tracked, on depth alone.
#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>

#include <Eigen/Geometry>
#include <vector>

#include "../unit/odometry/textured_wall.h"
#include "odom_recorder.h"

namespace quadric_slam {
namespace {

constexpr char kFrame[] = "openni_rgb_optical_frame";

// 1 cm and 4 mm a frame along the wall, facing it.
Eigen::Isometry3d slide(int i) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.01 * i, 0.004 * i, 0.0);
  return T;
}

sensor_msgs::CameraInfo cameraInfo(double stamp) {
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  sensor_msgs::CameraInfo info;
  info.header.frame_id = kFrame;
  info.header.stamp = ros::Time(stamp);
  info.width = k.width;
  info.height = k.height;
  info.K = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
  info.P = {k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0};
  return info;
}

class OdometryPhotometricTest : public ::testing::Test {
 protected:
  void SetUp() override {
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("depth/camera_info", 1, true);
    cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("points_normals", 5);
    image_pub_ = nh_.advertise<sensor_msgs::Image>("rgb/image", 5);
    image_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("rgb/camera_info", 5);
    spinner_.start();
    info_pub_.publish(cameraInfo(0.0));
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    while ((cloud_pub_.getNumSubscribers() == 0 || image_pub_.getNumSubscribers() == 0 ||
            image_info_pub_.getNumSubscribers() == 0 || !odom_.hasPublisher()) &&
           ros::WallTime::now() < deadline)
      ros::WallDuration(0.05).sleep();
    ASSERT_GT(image_pub_.getNumSubscribers(), 0u) << "the odometry nodelet took no images";
    ros::WallDuration(0.5).sleep();  // let the latched camera_info arrive
  }

  // Publishes frame i at stamp (its image first, unless with_image is false) and waits for odom.
  bool publishAndWait(int i, double stamp, bool with_image) {
    const synthetic::View view = synthetic::render(slide(i));
    if (with_image) {
      cv_bridge::CvImage image;
      image.header.stamp = ros::Time(stamp);
      image.header.frame_id = kFrame;
      image.encoding = sensor_msgs::image_encodings::MONO8;
      image.image = view.image;
      image_info_pub_.publish(cameraInfo(stamp));
      image_pub_.publish(image.toImageMsg());
      ros::WallDuration(0.05).sleep();  // the image is in the buffer before its cloud
    }
    sensor_msgs::PointCloud2 msg;
    pcl::toROSMsg(view.cloud, msg);
    msg.header.stamp = ros::Time(stamp);
    msg.header.frame_id = kFrame;
    return odom_.publishAndWait([&] { cloud_pub_.publish(msg); }, 10.0);
  }

  Eigen::Vector3d lastPosition() {
    const geometry_msgs::Point p = odom_.last().pose.pose.position;
    return Eigen::Vector3d(p.x, p.y, p.z);
  }

  ros::NodeHandle nh_;
  ros::AsyncSpinner spinner_{1};
  ros::Publisher info_pub_, cloud_pub_, image_pub_, image_info_pub_;
  OdomRecorder odom_{nh_};
};

TEST_F(OdometryPhotometricTest, FollowsASlideAlongATexturedWallFromItsImages) {
  const double t0 = 100.0;
  const int frames = 20;
  for (int i = 0; i < frames; ++i)
    ASSERT_TRUE(publishAndWait(i, t0 + i / 30.0, true)) << "no odom for frame " << i;
  const Eigen::Vector3d truth = slide(frames - 1).translation();
  EXPECT_GT(truth.norm(), 0.15);  // the camera did slide
  EXPECT_LT((lastPosition() - truth).norm(), 0.005) << lastPosition().transpose();

  // A cloud whose image never comes is tracked all the same (depth alone: the slide since the
  // last frame is not measured, the pose stays near the last one).
  const Eigen::Vector3d before = lastPosition();
  ASSERT_TRUE(publishAndWait(frames, t0 + frames / 30.0, false));
  EXPECT_LT((lastPosition() - before).norm(), 0.012);
}

}  // namespace
}  // namespace quadric_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "odometry_photometric_checker");
  const int result = RUN_ALL_TESTS();
  ros::shutdown();
  return result;
}
