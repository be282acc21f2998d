// Shared by the rostest checkers: feeds a pipeline one depth frame at a time and waits for the
// output that frame causes before sending the next, so that a test checks the computation and not
// the machine's speed (a loaded machine would otherwise drop frames).
#pragma once

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <functional>
#include <string>

namespace quadric_slam::test {

// Spins the global callback queue until done() or timeout_s wall seconds; returns done().
inline bool spinUntil(const std::function<bool()>& done, double timeout_s) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (!done() && ros::WallTime::now() < deadline) {
    ros::WallDuration(0.005).sleep();
    ros::spinOnce();
  }
  return done();
}

class FramePlayer {
 public:
  FramePlayer(ros::NodeHandle& nh, const std::string& depth_topic = "/camera/depth/image",
              const std::string& info_topic = "/camera/depth/camera_info")
      : depth_pub_(nh.advertise<sensor_msgs::Image>(depth_topic, 2)),
        info_pub_(nh.advertise<sensor_msgs::CameraInfo>(info_topic, 2, true)) {}

  // True once the pipeline subscribes to both topics.
  bool waitForSubscribers(double timeout_s) const {
    return spinUntil(
        [&] { return depth_pub_.getNumSubscribers() > 0 && info_pub_.getNumSubscribers() > 0; },
        timeout_s);
  }

  // Publishes the camera_info and the depth frame, then spins until arrived() (the frame's output
  // came). The first frame may beat its camera_info to a nodelet on another connection, which
  // drops it by design: `attempts` > 1 sends the frame again after each timeout_s.
  bool play(const sensor_msgs::ImageConstPtr& depth, const sensor_msgs::CameraInfoConstPtr& info,
            const std::function<bool()>& arrived, int attempts = 1, double timeout_s = 20.0) {
    for (int attempt = 0; attempt < attempts; ++attempt) {
      info_pub_.publish(info);
      depth_pub_.publish(depth);
      if (spinUntil(arrived, timeout_s))
        return true;
    }
    return false;
  }

 private:
  ros::Publisher depth_pub_;
  ros::Publisher info_pub_;
};

}  // namespace quadric_slam::test
