// record_trajectory: a ROS node that records nav_msgs/Odometry poses into a TUM trajectory file
// when it shuts down (for evaluating a live run with scripts/evaluate).
//
//   rosrun quadric_slam record_trajectory _topic:=odom _file:=trajectory.txt
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include <mutex>

#include "quadric_slam/io/trajectory_io.h"

namespace qs = quadric_slam;

int main(int argc, char** argv) {
  ros::init(argc, argv, "record_trajectory");
  ros::NodeHandle nh, private_nh("~");
  std::string topic = "odom", file = "trajectory.txt";
  private_nh.param("topic", topic, topic);
  private_nh.param("file", file, file);

  std::mutex mutex;
  qs::Trajectory trajectory;
  ros::Subscriber sub =
      nh.subscribe<nav_msgs::Odometry>(topic, 100, [&](const nav_msgs::OdometryConstPtr& odom) {
        const auto& p = odom->pose.pose;
        qs::StampedPose pose;
        pose.stamp = odom->header.stamp.toSec();
        pose.T_world_sensor.translation() =
            Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
        pose.T_world_sensor.linear() =
            Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
                .normalized()
                .toRotationMatrix();
        std::lock_guard<std::mutex> lock(mutex);
        trajectory.push_back(pose);
      });
  ROS_INFO("record_trajectory: recording %s into %s", sub.getTopic().c_str(), file.c_str());
  ros::spin();
  std::lock_guard<std::mutex> lock(mutex);
  try {
    qs::writeTumTrajectory(trajectory, file, "recorded from " + sub.getTopic());
    std::printf("record_trajectory: %zu poses written to %s\n", trajectory.size(), file.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "record_trajectory: %s\n", e.what());
    return 1;
  }
  return 0;
}
