// static_transform: publishes one static transform on /tf_static (latched), like tf2_ros's
// static_transform_publisher, which Debian does not package. The launch files use it for an
// identity map -> odom while the mapping nodelet is not running (mapping:=false): the map is then
// the odometry's frame, the first camera pose, as the mapper's would be before any correction.
//
//   rosrun quadric_slam static_transform x y z qx qy qz qw parent child
//   rosrun quadric_slam static_transform parent child           (identity)
// Frame ids are published without a leading '/' (tf2 and rviz refuse it).
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "quadric_slam/ros/frame_ids.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "static_transform", ros::init_options::AnonymousName);
  std::vector<std::string> args;
  ros::removeROSArgs(argc, argv, args);
  args.erase(args.begin());
  geometry_msgs::TransformStamped tf;
  tf.transform.rotation.w = 1.0;
  try {
    if (args.size() == 9) {
      tf.transform.translation.x = std::stod(args[0]);
      tf.transform.translation.y = std::stod(args[1]);
      tf.transform.translation.z = std::stod(args[2]);
      tf.transform.rotation.x = std::stod(args[3]);
      tf.transform.rotation.y = std::stod(args[4]);
      tf.transform.rotation.z = std::stod(args[5]);
      tf.transform.rotation.w = std::stod(args[6]);
      args.erase(args.begin(), args.begin() + 7);
    }
  } catch (const std::exception&) {
    args.clear();
  }
  for (std::string& frame : args)
    frame = quadric_slam::withoutLeadingSlash(frame);
  const auto& q = tf.transform.rotation;
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (args.size() != 2 || args[0].empty() || args[1].empty() || args[0] == args[1] ||
      std::abs(norm - 1.0) > 1e-3) {
    std::fprintf(stderr,
                 "usage: static_transform [x y z qx qy qz qw] parent child\n"
                 "  (m; a unit quaternion; distinct, non-empty frame ids)\n");
    return 2;
  }
  ros::NodeHandle nh;  // before ros::Time::now()
  tf.header.frame_id = args[0];
  tf.child_frame_id = args[1];
  tf.header.stamp = ros::Time::now();  // 0 on simulated time before the clock: static anyway
  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(tf);
  ROS_INFO("static_transform: %s -> %s (%.3f %.3f %.3f m; %.4f %.4f %.4f %.4f)",
           tf.header.frame_id.c_str(), tf.child_frame_id.c_str(), tf.transform.translation.x,
           tf.transform.translation.y, tf.transform.translation.z, q.x, q.y, q.z, q.w);
  ros::spin();
  return 0;
}
