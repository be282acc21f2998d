// The odom messages a checker receives from the odometry nodelet, and a wait for the answer to
// one input.
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include <mutex>
#include <vector>

namespace quadric_slam {

class OdomRecorder {
 public:
  explicit OdomRecorder(ros::NodeHandle& nh)
      : subscriber_(nh.subscribe("odom", 100, &OdomRecorder::onOdom, this)) {}

  bool hasPublisher() const { return subscriber_.getNumPublishers() > 0; }
  std::size_t count() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return odom_.size();
  }
  std::vector<nav_msgs::Odometry> messages() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return odom_;
  }
  nav_msgs::Odometry last() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return odom_.empty() ? nav_msgs::Odometry() : odom_.back();
  }
  // Runs publish() and waits up to timeout (s) for a new odom message; false if none came.
  template <typename Publish>
  bool publishAndWait(Publish publish, double timeout) {
    const std::size_t before = count();
    publish();
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
    while (count() == before && ros::WallTime::now() < deadline)
      ros::WallDuration(0.005).sleep();
    return count() > before;
  }

 private:
  void onOdom(const nav_msgs::OdometryConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    odom_.push_back(*msg);
  }

  mutable std::mutex mutex_;
  std::vector<nav_msgs::Odometry> odom_;
  ros::Subscriber subscriber_;
};

}  // namespace quadric_slam
