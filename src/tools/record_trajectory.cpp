// record_trajectory: a ROS node that records a camera trajectory from a nav_msgs/Odometry topic
// into a TUM trajectory file when it shuts down (for evaluating a live run with scripts/evaluate).
//
//   rosrun quadric_slam record_trajectory _topic:=odom _file:=odometry.txt
//       the odometry as published: the message's pose (child frame in the message's frame)
//   rosrun quadric_slam record_trajectory _topic:=odom _frame:=map _file:=trajectory.txt
//       the SLAM trajectory: at every odometry stamp, the tf lookup frame -> child frame (e.g.
//       map -> camera = the mapper's map -> odom composed with the odometry), so the file holds
//       the estimate as it was at that time, like scripts/run_bag's trajectory.txt
//
// Private parameters:
//   ~topic        nav_msgs/Odometry topic whose stamps (and, without ~frame, poses) are recorded;
//                 default "odom"
//   ~file         output TUM file (timestamp tx ty tz qx qy qz qw); default "trajectory.txt"
//   ~frame        "" (default): record the message poses; else the parent frame of a tf lookup
//   ~child_frame  child frame of the tf lookup; default "" = the message's child_frame_id
//   ~max_delay    s (message time): a stamp whose transform has not arrived when the newest
//                 message is this much younger is given up; default 2.0
// Frame ids are used without a leading '/' (ros/frame_ids.h: tf2 stores "/world" as "world" and
// rejects lookups of "/world").
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/transform_listener.h>

#include <memory>
#include <mutex>

#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/ros/frame_ids.h"
#include "quadric_slam/ros/tf_lookup.h"

namespace qs = quadric_slam;

namespace {

Eigen::Isometry3d toIsometry(const geometry_msgs::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  T.linear() =
      Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
          .normalized()
          .toRotationMatrix();
  return T;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "record_trajectory");
  ros::NodeHandle nh, private_nh("~");
  std::string topic = "odom", file = "trajectory.txt", frame, child_frame;
  double max_delay = 2.0;
  private_nh.param("topic", topic, topic);
  private_nh.param("file", file, file);
  private_nh.param("frame", frame, frame);
  private_nh.param("child_frame", child_frame, child_frame);
  private_nh.param("max_delay", max_delay, max_delay);
  frame = qs::withoutLeadingSlash(frame);
  child_frame = qs::withoutLeadingSlash(child_frame);

  std::unique_ptr<tf2_ros::Buffer> buffer;
  std::unique_ptr<tf2_ros::TransformListener> listener;
  if (!frame.empty()) {
    buffer = std::make_unique<tf2_ros::Buffer>(ros::Duration(30.0));
    listener = std::make_unique<tf2_ros::TransformListener>(*buffer);
  }

  std::mutex mutex;
  qs::Trajectory trajectory;
  qs::PendingTfLookups pending(max_delay);  // stamps waiting for their transform (tf mode)
  std::string recorded_child = child_frame;

  // Resolves the pending stamps in order; with `final`, gives up on whatever cannot be resolved.
  auto resolve = [&](bool final) {
    for (const qs::PendingTfLookups::Resolved& resolved : pending.resolve(*buffer, final))
      trajectory.push_back({resolved.stamp.toSec(), resolved.transforms.front()});
  };

  ros::Subscriber sub =
      nh.subscribe<nav_msgs::Odometry>(topic, 100, [&](const nav_msgs::OdometryConstPtr& odom) {
        std::lock_guard<std::mutex> lock(mutex);
        if (frame.empty()) {
          trajectory.push_back({odom->header.stamp.toSec(), toIsometry(odom->pose.pose)});
          return;
        }
        if (child_frame.empty())
          recorded_child = qs::withoutLeadingSlash(odom->child_frame_id);
        pending.add(odom->header.stamp, {{frame, recorded_child}});
        resolve(false);
      });
  ros::WallTimer timer =
      nh.createWallTimer(ros::WallDuration(0.1), [&](const ros::WallTimerEvent&) {
        std::lock_guard<std::mutex> lock(mutex);
        if (buffer)
          resolve(false);
      });
  if (frame.empty()) {
    ROS_INFO("record_trajectory: recording the poses of %s into %s", sub.getTopic().c_str(),
             file.c_str());
  } else {
    ROS_INFO("record_trajectory: recording tf %s -> %s at the stamps of %s into %s", frame.c_str(),
             child_frame.empty() ? "(the odometry's child frame)" : child_frame.c_str(),
             sub.getTopic().c_str(), file.c_str());
  }
  ros::spin();

  std::lock_guard<std::mutex> lock(mutex);
  if (buffer)
    resolve(true);
  const std::string what = frame.empty() ? "recorded from " + sub.getTopic()
                                         : "tf " + frame + " -> " + recorded_child +
                                               " at the stamps of " + sub.getTopic();
  try {
    qs::writeTumTrajectory(trajectory, file, what);
    std::printf("record_trajectory: %zu poses written to %s (%s)\n", trajectory.size(),
                file.c_str(), what.c_str());
    if (pending.givenUp() > 0) {
      std::printf("record_trajectory: %zu stamps without a transform (last: %s)\n",
                  pending.givenUp(), pending.lastError().c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "record_trajectory: %s\n", e.what());
    return 1;
  }
  return 0;
}
