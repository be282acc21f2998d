// Health of a nodelet on /diagnostics (diagnostic_msgs/DiagnosticArray, published directly:
// diagnostic_updater is not packaged in Debian). Counts processed and dropped frames, remembers the
// last reason for a drop and the processing time, and publishes once per period.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>

#include <mutex>
#include <string>

namespace quadric_slam {

class NodeletDiagnostics {
 public:
  // name: the status name shown by rqt_robot_monitor, e.g. "quadric_slam: normal_estimation".
  NodeletDiagnostics(ros::NodeHandle& nh, const std::string& name, double period_s = 1.0);

  void frameProcessed(double processing_ms);
  void frameDropped(const std::string& reason);

 private:
  void publish(const ros::WallTimerEvent&);

  std::string name_;
  ros::Publisher publisher_;
  ros::WallTimer timer_;
  std::mutex mutex_;
  unsigned long processed_ = 0, dropped_ = 0;
  unsigned long processed_at_last_report_ = 0, dropped_at_last_report_ = 0;
  double last_processing_ms_ = 0.0;
  std::string last_drop_reason_;
};

}  // namespace quadric_slam
