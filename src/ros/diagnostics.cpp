#include "quadric_slam/ros/diagnostics.h"

namespace quadric_slam {

void addTimingValues(diagnostic_updater::DiagnosticStatusWrapper& status,
                     const TimingSummary& timing) {
  status.add("processing time median (ms)", timing.median_ms);
  status.add("processing time p95 (ms)", timing.p95_ms);
  status.add("processing time max (ms)", timing.max_ms);
  status.add("processing time window (frames)", timing.count);
}

namespace {

std::string withoutLeadingSlash(const std::string& name) {
  return !name.empty() && name[0] == '/' ? name.substr(1) : name;
}

}  // namespace

// The updater's "node name" is the prefix of every status: "quadric_slam: <nodelet name> ...",
// one group in rqt_robot_monitor for all of the package's nodelets.
NodeletDiagnostics::NodeletDiagnostics(ros::NodeHandle& nh, ros::NodeHandle& private_nh,
                                       const std::string& nodelet_name, const Options& options)
    : name_(withoutLeadingSlash(nodelet_name)),
      min_rate_hz_(options.min_output_rate_hz),
      max_rate_hz_(options.max_output_rate_hz),
      updater_(nh, private_nh, "/quadric_slam"),
      output_rate_(diagnostic_updater::FrequencyStatusParam(&min_rate_hz_, &max_rate_hz_),
                   name_ + " output rate"),
      frames_(options.timing_window) {
  updater_.setHardwareID("quadric_slam");
  updater_.add(name_, this, &NodeletDiagnostics::report);
  updater_.add(output_rate_);
  // A wall timer: on a bag's clock the reports go on while it is paused or has ended.
  timer_ = nh.createWallTimer(ros::WallDuration(updater_.getPeriod()), &NodeletDiagnostics::onTimer,
                              this);
}

void NodeletDiagnostics::frameProcessed(double processing_ms) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    frames_.processed(processing_ms);
  }
  output_rate_.tick();
}

void NodeletDiagnostics::frameDropped(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  frames_.dropped(reason);
}

void NodeletDiagnostics::onTimer(const ros::WallTimerEvent&) {
  try {
    updater_.force_update();
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(30.0, "%s: diagnostics failed: %s", name_.c_str(), e.what());
  }
}

void NodeletDiagnostics::report(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  const FrameStatistics::Period period = frames_.takePeriod();
  using diagnostic_msgs::DiagnosticStatus;
  if (period.dropped > 0 && period.processed == 0)
    status.summary(DiagnosticStatus::ERROR, "dropping every frame: " + frames_.lastDropReason());
  else if (period.dropped > 0)
    status.summary(DiagnosticStatus::WARN, "dropping some frames: " + frames_.lastDropReason());
  else if (period.processed == 0)
    status.summary(DiagnosticStatus::OK, "waiting for input");
  else
    status.summary(DiagnosticStatus::OK, "ok");
  status.add("frames received", frames_.received());
  status.add("frames processed", frames_.processedCount());
  status.add("frames dropped", frames_.droppedCount());
  addTimingValues(status, frames_.timing());
  status.add("last drop reason", frames_.lastDropReason());
  for (const auto& [reason, count] : frames_.dropsPerReason())
    status.add("dropped: " + reason, count);
}

}  // namespace quadric_slam
