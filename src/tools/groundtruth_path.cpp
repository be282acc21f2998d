// groundtruth_path: a ROS node that shows a bag's ground truth beside our estimate. A TUM rosbag's
// /tf carries the motion-capture truth (/world -> /kinect -> ... -> /openni_rgb_optical_frame), a
// tree of its own that our map -> odom -> camera tree never joins. At every stamp of the odometry
// this node looks up the bag's world -> optical frame and publishes the poses as a nav_msgs/Path
// in our map frame, anchored so that its first pose coincides with our camera pose at that stamp
// (the map frame is the first camera pose):
//   T_map_truth(t) = T_map_camera(t0) * T_world_optical(t0)^-1 * T_world_optical(t)
//
//   rosrun quadric_slam groundtruth_path [_file:=groundtruth.txt]
//
// Subscribes  ~topic (nav_msgs/Odometry, default "odom"): only its stamps are used
// Publishes   groundtruth_path (nav_msgs/Path in ~map_frame, latched)
// Private parameters:
//   ~world_frame   the bag's world frame; default "/world"
//   ~frame         the bag's camera frame (the depth image's optical frame); default
//                  "/openni_rgb_optical_frame"
//   ~map_frame     our map frame; default "map"
//   ~camera_frame  our camera frame (the odometry's child frame); default "camera"
//   ~file          when set, the truth (world -> frame at the odometry stamps, in the bag's world
//                  frame) is written there as a TUM trajectory at shutdown; default ""
//   ~max_delay     s (message time): a stamp whose transforms have not arrived when the newest
//                  odometry is this much younger is skipped; default 2.0
//   ~publish_period  s (message time) between path messages; default 0.5
// TUM bags name their frames with a leading '/', which tf2 strips when it stores a transform and
// rejects in a lookup: every frame id is used without it (ros/frame_ids.h).
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/transform_listener.h>

#include <mutex>
#include <optional>

#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/ros/frame_ids.h"
#include "quadric_slam/ros/tf_lookup.h"

namespace qs = quadric_slam;

namespace {

geometry_msgs::PoseStamped toPoseStamped(const Eigen::Isometry3d& T, const ros::Time& stamp,
                                         const std::string& frame) {
  geometry_msgs::PoseStamped pose;
  pose.header.stamp = stamp;
  pose.header.frame_id = frame;
  pose.pose = tf2::toMsg(T);
  return pose;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "groundtruth_path");
  ros::NodeHandle nh, private_nh("~");
  std::string topic = "odom", world_frame = "/world", frame = "/openni_rgb_optical_frame",
              map_frame = "map", camera_frame = "camera", file;
  double max_delay = 2.0, publish_period = 0.5;
  private_nh.param("topic", topic, topic);
  private_nh.param("world_frame", world_frame, world_frame);
  private_nh.param("frame", frame, frame);
  private_nh.param("map_frame", map_frame, map_frame);
  private_nh.param("camera_frame", camera_frame, camera_frame);
  private_nh.param("file", file, file);
  private_nh.param("max_delay", max_delay, max_delay);
  private_nh.param("publish_period", publish_period, publish_period);
  world_frame = qs::withoutLeadingSlash(world_frame);
  frame = qs::withoutLeadingSlash(frame);
  map_frame = qs::withoutLeadingSlash(map_frame);
  camera_frame = qs::withoutLeadingSlash(camera_frame);

  tf2_ros::Buffer buffer(ros::Duration(30.0));
  tf2_ros::TransformListener listener(buffer);
  ros::Publisher path_pub = nh.advertise<nav_msgs::Path>("groundtruth_path", 1, true);

  std::mutex mutex;
  // Each odometry stamp waits for the bag's world -> frame and, until the anchor is set, our
  // map -> camera.
  qs::PendingTfLookups pending(max_delay);
  const qs::TfLookup truth_lookup{world_frame, frame}, our_lookup{map_frame, camera_frame};
  ros::Time last_published;
  std::optional<Eigen::Isometry3d> T_map_world;  // the anchor
  nav_msgs::Path path;
  path.header.frame_id = map_frame;
  qs::Trajectory truth;  // world -> frame, for ~file

  // Resolves the pending stamps in order; with `final`, skips whatever cannot be resolved.
  auto resolve = [&](bool final) {
    const std::size_t skipped_before = pending.givenUp();
    const std::vector<qs::PendingTfLookups::Resolved> resolved = pending.resolve(buffer, final);
    if (pending.givenUp() > skipped_before) {
      ROS_WARN_THROTTLE(10.0, "groundtruth_path: %zu stamps without a pose (last: %s)",
                        pending.givenUp(), pending.lastError().c_str());
    }
    for (const qs::PendingTfLookups::Resolved& pose : resolved) {
      const Eigen::Isometry3d& T_world_optical = pose.transforms[0];
      if (!T_map_world) {
        // Stamps added before the anchor was set wait for map -> camera too (transforms[1]).
        const Eigen::Isometry3d& T_map_camera = pose.transforms.at(1);
        T_map_world = T_map_camera * T_world_optical.inverse();
        ROS_INFO("groundtruth_path: %s -> %s anchored to %s -> %s at t = %.3f s",
                 world_frame.c_str(), frame.c_str(), map_frame.c_str(), camera_frame.c_str(),
                 pose.stamp.toSec());
      }
      path.poses.push_back(toPoseStamped(*T_map_world * T_world_optical, pose.stamp, map_frame));
      truth.push_back({pose.stamp.toSec(), T_world_optical});
    }
    if (!resolved.empty() &&
        (final || (pending.newest() - last_published).toSec() >= publish_period)) {
      path.header.stamp = path.poses.back().header.stamp;
      path_pub.publish(path);
      last_published = pending.newest();
    }
  };

  ros::Subscriber sub =
      nh.subscribe<nav_msgs::Odometry>(topic, 100, [&](const nav_msgs::OdometryConstPtr& odom) {
        std::lock_guard<std::mutex> lock(mutex);
        if (T_map_world)
          pending.add(odom->header.stamp, {truth_lookup});
        else
          pending.add(odom->header.stamp, {truth_lookup, our_lookup});
        resolve(false);
      });
  ros::WallTimer timer =
      nh.createWallTimer(ros::WallDuration(0.1), [&](const ros::WallTimerEvent&) {
        std::lock_guard<std::mutex> lock(mutex);
        resolve(false);
      });
  ROS_INFO("groundtruth_path: the bag's %s -> %s at the stamps of %s, as %s in %s",
           world_frame.c_str(), frame.c_str(), sub.getTopic().c_str(), path_pub.getTopic().c_str(),
           map_frame.c_str());
  ros::spin();

  std::lock_guard<std::mutex> lock(mutex);
  resolve(true);
  std::printf("groundtruth_path: %zu poses", path.poses.size());
  if (pending.givenUp() > 0)
    std::printf(", %zu stamps without a pose (last: %s)", pending.givenUp(),
                pending.lastError().c_str());
  std::printf("\n");
  if (!file.empty()) {
    try {
      qs::writeTumTrajectory(truth, file, "tf " + world_frame + " -> " + frame + " from the bag");
      std::printf("groundtruth_path: %zu poses written to %s\n", truth.size(), file.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "groundtruth_path: %s\n", e.what());
      return 1;
    }
  }
  return 0;
}
