// Checker for quadric_segmentation.test: publishes organized clouds with normals (a rendered scene
// with a floor, a wall, a sphere and a cylinder; an all-NaN cloud; a cloud without normal fields)
// to the nodelet and checks the observations, the lazy debug image and the handling of bad input.
#include <gtest/gtest.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "../unit/kinect_vga.h"
#include "quadric_slam/QuadricObservationArray.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/sim/primitive_scene_renderer.h"

namespace qs = quadric_slam;

namespace {

// Floor 0.8 m below the camera, wall at 2.5 m, a sphere (r 0.15 m) and an upright cylinder (r 0.09
// m).
pcl::PointCloud<pcl::PointNormal> sceneCloud() {
  std::vector<qs::ScenePrimitive> scene(4);
  scene[0].shape = qs::PrimitiveShape::plane(Eigen::Vector3d(0, -1, 0), -0.8);
  scene[1].shape = qs::PrimitiveShape::plane(Eigen::Vector3d(0, 0, -1), -2.5);
  scene[2].shape = qs::PrimitiveShape::sphere(Eigen::Vector3d(-0.45, 0.25, 1.6), 0.15);
  scene[3].shape =
      qs::PrimitiveShape::cylinder(Eigen::Vector3d(0.3, 0.8, 1.8), Eigen::Vector3d(0, -1, 0), 0.09);
  scene[3].axis_max = 0.55;
  const qs::PrimitiveRendering frame =
      qs::renderPrimitives(scene, qs::test::kinectVga(), qs::RenderParams());
  const qs::DepthImageView<float> view = qs::depthViewOf(frame.depth);
  return qs::NormalEstimator(qs::NormalEstimator::Params())
      .compute(qs::backProject(view, qs::test::kinectVga(), qs::BackProjectionParams()));
}

class QuadricSegmentationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::NodeHandle nh("test_camera");
    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("points_normals", 5);
    observations_sub_ =
        nh.subscribe("observations", 10, &QuadricSegmentationTest::onObservations, this);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    while ((cloud_pub_.getNumSubscribers() == 0 || observations_sub_.getNumPublishers() == 0) &&
           ros::WallTime::now() < deadline) {
      ros::WallDuration(0.05).sleep();
      ros::spinOnce();
    }
    ASSERT_GT(cloud_pub_.getNumSubscribers(), 0u) << "nodelet did not subscribe";
  }

  void onObservations(const qs::QuadricObservationArrayConstPtr& msg) { received_.push_back(msg); }

  qs::QuadricObservationArrayConstPtr publishAndWait(sensor_msgs::PointCloud2 cloud, double stamp,
                                                     double timeout_s) {
    cloud.header.stamp = ros::Time(stamp);
    cloud.header.frame_id = "test_optical_frame";
    cloud_pub_.publish(cloud);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::WallTime::now() < deadline) {
      ros::spinOnce();
      for (const auto& msg : received_)
        if (msg->header.stamp == cloud.header.stamp)
          return msg;
      ros::WallDuration(0.01).sleep();
    }
    return nullptr;
  }

  ros::Publisher cloud_pub_;
  ros::Subscriber observations_sub_;
  std::vector<qs::QuadricObservationArrayConstPtr> received_;
};

TEST_F(QuadricSegmentationTest, ObservationsOfARenderedSceneAndBadInput) {
  sensor_msgs::PointCloud2 scene;
  pcl::toROSMsg(sceneCloud(), scene);

  // Lazy debug image: subscribe before publishing the scene.
  ros::NodeHandle nh;
  std::vector<sensor_msgs::ImageConstPtr> images;
  ros::Subscriber image_sub = nh.subscribe<sensor_msgs::Image>(
      "/quadric_segmentation/segmentation_image", 2,
      [&images](const sensor_msgs::ImageConstPtr& image) { images.push_back(image); });
  std::vector<sensor_msgs::PointCloud2ConstPtr> labelled;
  ros::Subscriber labelled_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      "/quadric_segmentation/segmented_cloud", 2,
      [&labelled](const sensor_msgs::PointCloud2ConstPtr& cloud) { labelled.push_back(cloud); });
  const ros::WallTime wait = ros::WallTime::now() + ros::WallDuration(10.0);
  while ((image_sub.getNumPublishers() == 0 || labelled_sub.getNumPublishers() == 0) &&
         ros::WallTime::now() < wait) {
    ros::WallDuration(0.05).sleep();
    ros::spinOnce();
  }

  const auto first = publishAndWait(scene, 1.0, 30.0);
  ASSERT_TRUE(first) << "no observations for the scene";
  EXPECT_EQ(first->header.frame_id, "test_optical_frame");
  int planes = 0, spheres = 0, cylinders = 0;
  for (const qs::QuadricObservation& o : first->observations) {
    EXPECT_EQ(o.minimal_dimension, o.covariance.size() == 0 ? 0 : std::sqrt(o.covariance.size()));
    EXPECT_GT(o.num_points, 0u);
    EXPECT_GT(o.label, 0u);
    EXPECT_LT(o.fit_rms, 0.015f);
    const Eigen::Quaterniond q(o.surface.pose.orientation.w, o.surface.pose.orientation.x,
                               o.surface.pose.orientation.y, o.surface.pose.orientation.z);
    EXPECT_NEAR(q.norm(), 1.0, 1e-6);
    if (o.surface.quadric_class == qs::QuadricSurface::CLASS_PLANE) {
      ++planes;
      ASSERT_EQ(o.surface.shape.size(), 4u);
      // Plane normal = quadric x axis.
      const Eigen::Vector3d x = q.toRotationMatrix().col(0);
      EXPECT_NEAR(std::abs(x.dot(
                      Eigen::Vector3d(o.surface.shape[0], o.surface.shape[1], o.surface.shape[2]))),
                  1.0, 1e-6);
      EXPECT_EQ(o.minimal_dimension, 3);
    } else if (o.surface.quadric_class == qs::QuadricSurface::CLASS_SPHERE) {
      ++spheres;
      ASSERT_EQ(o.surface.shape.size(), 4u);
      EXPECT_NEAR(o.surface.shape[3], 0.15, 0.005);
      EXPECT_NEAR(o.surface.scale[0], 1.0 / o.surface.shape[3], 1e-6);
      EXPECT_NEAR(o.surface.pose.position.x, -0.45, 0.01);
      EXPECT_EQ(o.surface.signature[3], -1);
      EXPECT_EQ(o.minimal_dimension, 4);
    } else if (o.surface.quadric_class == qs::QuadricSurface::CLASS_CYLINDER) {
      ++cylinders;
      ASSERT_EQ(o.surface.shape.size(), 7u);
      EXPECT_NEAR(o.surface.shape[6], 0.09, 0.005);
      // Axis = quadric z, vertical.
      const Eigen::Vector3d z = q.toRotationMatrix().col(2);
      EXPECT_GT(std::abs(z.y()), std::cos(2 * M_PI / 180));
      EXPECT_EQ(o.minimal_dimension, 5);
    }
  }
  EXPECT_EQ(planes, 2);
  EXPECT_EQ(spheres, 1);
  EXPECT_EQ(cylinders, 1);
  const ros::WallTime image_deadline = ros::WallTime::now() + ros::WallDuration(5.0);
  while (images.empty() && ros::WallTime::now() < image_deadline) {
    ros::WallDuration(0.02).sleep();
    ros::spinOnce();
  }
  ASSERT_FALSE(images.empty()) << "no ~segmentation_image while subscribed";
  EXPECT_EQ(images.back()->encoding, "rgb8");
  EXPECT_EQ(images.back()->width, 640u);
  EXPECT_EQ(images.back()->height, 480u);
  while (labelled.empty() && ros::WallTime::now() < image_deadline) {
    ros::WallDuration(0.02).sleep();
    ros::spinOnce();
  }
  ASSERT_FALSE(labelled.empty()) << "no ~segmented_cloud while subscribed";
  pcl::PointCloud<pcl::PointXYZL> labels;
  pcl::fromROSMsg(*labelled.back(), labels);
  ASSERT_EQ(labels.width, 640u);
  ASSERT_EQ(labels.height, 480u);
  std::map<std::uint32_t, std::uint32_t> counts;
  for (const auto& p : labels.points)
    ++counts[p.label];
  // Every observation's label holds exactly its supporting points.
  for (const qs::QuadricObservation& o : first->observations)
    EXPECT_EQ(counts[o.label], o.num_points) << "label " << o.label;

  // An all-NaN cloud: an empty array with the same stamp.
  pcl::PointCloud<pcl::PointNormal> nan_cloud(640, 480);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (auto& p : nan_cloud.points)
    p.x = p.y = p.z = p.normal_x = p.normal_y = p.normal_z = p.curvature = nan;
  sensor_msgs::PointCloud2 nan_msg;
  pcl::toROSMsg(nan_cloud, nan_msg);
  const auto empty = publishAndWait(nan_msg, 2.0, 20.0);
  ASSERT_TRUE(empty) << "no observations for an all-NaN cloud";
  EXPECT_TRUE(empty->observations.empty());

  // An empty cloud: an empty array too.
  sensor_msgs::PointCloud2 empty_msg;
  pcl::toROSMsg(pcl::PointCloud<pcl::PointNormal>(), empty_msg);
  const auto none = publishAndWait(empty_msg, 3.0, 20.0);
  ASSERT_TRUE(none) << "no observations for an empty cloud";
  EXPECT_TRUE(none->observations.empty());

  // A cloud without normals is dropped (no output), and the nodelet keeps working.
  pcl::PointCloud<pcl::PointXYZ> xyz(64, 48);
  for (auto& p : xyz.points) {
    p.x = p.y = 0;
    p.z = 1;
  }
  sensor_msgs::PointCloud2 xyz_msg;
  pcl::toROSMsg(xyz, xyz_msg);
  EXPECT_FALSE(publishAndWait(xyz_msg, 4.0, 2.0)) << "a cloud without normals was processed";
  const auto again = publishAndWait(scene, 5.0, 30.0);
  ASSERT_TRUE(again) << "the nodelet stopped after bad input";
  EXPECT_EQ(again->observations.size(), first->observations.size());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "quadric_segmentation_checker");
  return RUN_ALL_TESTS();
}
