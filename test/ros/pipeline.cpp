// Checker for pipeline.test: renders a short synthetic TUM bag of config/scenes/desk.yaml with the
// project's generator, publishes its depth frames one at a time on TUM's topics, and checks what
// the pipeline publishes: points_normals and odom per frame, frame ids, tf, and the odometry's
// error against the ground truth.
#include <gtest/gtest.h>
#include <unistd.h>
#include <nav_msgs/Odometry.h>
#include <quadric_slam/QuadricObservationArray.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/transform_listener.h>

#include <filesystem>
#include <map>
#include <set>

#include "quadric_slam/eval/trajectory_metrics.h"
#include "synthetic_bag.h"

namespace qs = quadric_slam;

namespace {

constexpr double kSeconds = 1.5;  // 45 frames at 30 Hz
constexpr double kRate = 30.0;    // the desk scene's camera rate

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    bag_path_ = testing::TempDir() + "/pipeline_test_" + std::to_string(::getpid()) + ".bag";
    truth_ = qs::test::writeDeskBag(bag_path_, kRate, kSeconds, 7).truth;
  }
  void TearDown() override { std::filesystem::remove(bag_path_); }

  std::string bag_path_;
  qs::Trajectory truth_;
};

TEST_F(PipelineTest, EveryFrameGivesNormalsObservationsAndOdometryThatFollowsTheTruth) {
  ros::NodeHandle nh;
  ros::Publisher depth_pub = nh.advertise<sensor_msgs::Image>("/camera/depth/image", 2);
  ros::Publisher info_pub =
      nh.advertise<sensor_msgs::CameraInfo>("/camera/depth/camera_info", 2, true);
  std::map<double, nav_msgs::OdometryConstPtr> odoms;
  std::map<double, sensor_msgs::PointCloud2ConstPtr> clouds;
  ros::Subscriber odom_sub = nh.subscribe<nav_msgs::Odometry>(
      "odom", 100,
      [&](const nav_msgs::OdometryConstPtr& m) { odoms[m->header.stamp.toSec()] = m; });
  ros::Subscriber cloud_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      "points_normals", 100,
      [&](const sensor_msgs::PointCloud2ConstPtr& m) { clouds[m->header.stamp.toSec()] = m; });
  std::map<double, quadric_slam::QuadricObservationArrayConstPtr> observations;
  ros::Subscriber observations_sub = nh.subscribe<quadric_slam::QuadricObservationArray>(
      "observations", 100, [&](const quadric_slam::QuadricObservationArrayConstPtr& m) {
        observations[m->header.stamp.toSec()] = m;
      });
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);

  const ros::WallTime connect_deadline = ros::WallTime::now() + ros::WallDuration(60.0);
  // One connection per subscribing process: both nodelets share the manager's.
  while ((depth_pub.getNumSubscribers() == 0 || info_pub.getNumSubscribers() == 0 ||
          odom_sub.getNumPublishers() == 0 || cloud_sub.getNumPublishers() == 0 ||
          observations_sub.getNumPublishers() == 0) &&
         ros::WallTime::now() < connect_deadline) {
    ros::WallDuration(0.05).sleep();
    ros::spinOnce();
  }
  ASSERT_GT(depth_pub.getNumSubscribers(), 0u) << "the pipeline did not subscribe";

  // Publish each depth frame (with its camera_info) and wait for its odometry before the next:
  // the test checks the computation, not the machine's speed.
  rosbag::Bag bag(bag_path_, rosbag::bagmode::Read);
  const std::vector<std::string> topics = {"/camera/depth/image", "/camera/depth/camera_info"};
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  // camera_info first (latched): in the bag a frame's image may precede its camera_info.
  for (const rosbag::MessageInstance& m : view) {
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      info_pub.publish(info);
      break;
    }
  }
  std::size_t published = 0;
  for (const rosbag::MessageInstance& m : view) {
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      info_pub.publish(info);
      continue;
    }
    auto depth = m.instantiate<sensor_msgs::Image>();
    ASSERT_TRUE(depth);
    const double stamp = depth->header.stamp.toSec();
    // The very first frame may beat the first camera_info to the nodelets (separate
    // connections): the nodelet drops it, by design, and the frame is sent again.
    for (int attempt = 0; attempt < 3 && !odoms.count(stamp); ++attempt) {
      depth_pub.publish(depth);
      const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(20.0);
      while ((!odoms.count(stamp) || !observations.count(stamp)) &&
             ros::WallTime::now() < deadline &&
             (published > 0 || ros::WallTime::now() < deadline - ros::WallDuration(17.0))) {
        ros::WallDuration(0.005).sleep();
        ros::spinOnce();
      }
    }
    ++published;
    ASSERT_TRUE(observations.count(stamp)) << "no observations for frame " << published;
    ASSERT_TRUE(odoms.count(stamp)) << "no odom for frame " << published << " at " << stamp;
  }
  ros::WallDuration(0.2).sleep();
  ros::spinOnce();

  EXPECT_EQ(published, truth_.size());
  EXPECT_EQ(odoms.size(), truth_.size());
  EXPECT_EQ(clouds.size(), truth_.size());
  const nav_msgs::Odometry& last = *odoms.rbegin()->second;
  EXPECT_EQ(last.header.frame_id, "odom");
  EXPECT_EQ(last.child_frame_id, "camera");
  const sensor_msgs::PointCloud2& cloud = *clouds.rbegin()->second;
  EXPECT_EQ(cloud.width, 640u);
  EXPECT_EQ(cloud.height, 480u);
  EXPECT_TRUE(tf_buffer.canTransform("odom", "camera", ros::Time(0), ros::Duration(2.0)));

  // The bag stamps its images "/openni_rgb_optical_frame", a frame of the bag's own tf tree (here
  // without one). quadric_slam.launch names the clouds and observations with the odometry's
  // camera frame instead, without a '/' (tf2 refuses it), so rviz (fixed frame map) can place
  // them: tf2 must give their frame in the map (mapping's map -> odom, odometry's odom ->
  // camera) at every stamp. A wait bounds each lookup in case the mapper's tf is still on its way.
  auto expectPlaceableInMap = [&](const std_msgs::Header& header, const char* what) {
    EXPECT_EQ(header.frame_id, "camera") << what << " at " << header.stamp;
    std::string error;
    EXPECT_TRUE(tf_buffer.canTransform("map", header.frame_id, header.stamp, ros::Duration(5.0),
                                       &error))
        << what << " in '" << header.frame_id << "' at " << header.stamp << ": " << error;
  };
  for (const auto& [stamp, points_normals] : clouds)
    expectPlaceableInMap(points_normals->header, "points_normals");
  for (const auto& [stamp, array] : observations)
    expectPlaceableInMap(array->header, "observations");

  // The desk scene seen from the hand-held path holds planes (walls, desk), the globe (sphere),
  // the poster tube (cylinder) and the lamp shade (cone): each class must be observed in most
  // frames, in the camera frame, with a covariance of its class's minimal dimension.
  EXPECT_EQ(observations.size(), truth_.size());
  std::map<int, int> frames_with_class;
  for (const auto& [stamp, array] : observations) {
    std::set<int> classes;
    for (const auto& o : array->observations) {
      classes.insert(o.surface.quadric_class);
      EXPECT_EQ(o.covariance.size(),
                static_cast<std::size_t>(o.minimal_dimension) * o.minimal_dimension);
      EXPECT_GT(o.num_points, 0u);
    }
    for (int c : classes)
      ++frames_with_class[c];
  }
  const int frames = static_cast<int>(truth_.size());
  EXPECT_GE(frames_with_class[quadric_slam::QuadricSurface::CLASS_PLANE], frames);
  EXPECT_GE(frames_with_class[quadric_slam::QuadricSurface::CLASS_SPHERE], 0.9 * frames);
  EXPECT_GE(frames_with_class[quadric_slam::QuadricSurface::CLASS_CYLINDER], 0.9 * frames);
  EXPECT_GE(frames_with_class[quadric_slam::QuadricSurface::CLASS_CONE], 0.5 * frames);
  std::printf("pipeline: frames with plane %d, sphere %d, cylinder %d, cone %d of %d\n",
              frames_with_class[0], frames_with_class[1], frames_with_class[2],
              frames_with_class[3], frames);

  // The odometry against the ground truth (TUM conventions: rigid alignment, ATE RMSE).
  qs::Trajectory estimate;
  for (const auto& [stamp, odom] : odoms) {
    const auto& p = odom->pose.pose;
    qs::StampedPose pose;
    pose.stamp = stamp;
    pose.T_world_sensor.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
    pose.T_world_sensor.linear() =
        Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
            .toRotationMatrix();
    estimate.push_back(pose);
  }
  const qs::AteResult ate =
      qs::AbsoluteTrajectoryError(qs::AbsoluteTrajectoryError::Params{}).evaluate(truth_, estimate);
  EXPECT_EQ(ate.pairs(), truth_.size());
  EXPECT_LT(ate.rmse(), 0.005) << "odometry ATE over " << kSeconds << " s of hand-held motion";
  std::printf("pipeline: %zu frames, odometry ATE %.5f m\n", ate.pairs(), ate.rmse());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "pipeline_checker");
  return RUN_ALL_TESTS();
}
