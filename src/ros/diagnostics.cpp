#include "quadric_slam/ros/diagnostics.h"

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <diagnostic_msgs/KeyValue.h>

namespace quadric_slam {
namespace {

diagnostic_msgs::KeyValue keyValue(const std::string& key, const std::string& value) {
  diagnostic_msgs::KeyValue kv;
  kv.key = key;
  kv.value = value;
  return kv;
}

}  // namespace

NodeletDiagnostics::NodeletDiagnostics(ros::NodeHandle& nh, const std::string& name,
                                       double period_s)
    : name_(name) {
  publisher_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 1);
  timer_ = nh.createWallTimer(ros::WallDuration(period_s), &NodeletDiagnostics::publish, this);
}

void NodeletDiagnostics::frameProcessed(double processing_ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++processed_;
  last_processing_ms_ = processing_ms;
}

void NodeletDiagnostics::frameDropped(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++dropped_;
  last_drop_reason_ = reason;
}

void NodeletDiagnostics::publish(const ros::WallTimerEvent&) {
  diagnostic_msgs::DiagnosticStatus status;
  status.name = name_;
  status.hardware_id = "quadric_slam";
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const unsigned long new_processed = processed_ - processed_at_last_report_;
    const unsigned long new_dropped = dropped_ - dropped_at_last_report_;
    processed_at_last_report_ = processed_;
    dropped_at_last_report_ = dropped_;
    if (new_dropped > 0 && new_processed == 0) {
      status.level = diagnostic_msgs::DiagnosticStatus::ERROR;
      status.message = "dropping every frame: " + last_drop_reason_;
    } else if (new_dropped > 0) {
      status.level = diagnostic_msgs::DiagnosticStatus::WARN;
      status.message = "dropping some frames: " + last_drop_reason_;
    } else if (new_processed == 0) {
      status.level = diagnostic_msgs::DiagnosticStatus::OK;
      status.message = "waiting for input";
    } else {
      status.level = diagnostic_msgs::DiagnosticStatus::OK;
      status.message = "ok";
    }
    status.values.push_back(keyValue("frames processed", std::to_string(processed_)));
    status.values.push_back(keyValue("frames dropped", std::to_string(dropped_)));
    status.values.push_back(
        keyValue("last processing time (ms)", std::to_string(last_processing_ms_)));
    status.values.push_back(keyValue("last drop reason", last_drop_reason_));
  }
  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = ros::Time::now();
  array.status.push_back(status);
  publisher_.publish(array);
}

}  // namespace quadric_slam
