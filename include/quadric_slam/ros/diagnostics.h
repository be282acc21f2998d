// Health of a front-end nodelet on /diagnostics, through diagnostic_updater. Statuses (one
// DiagnosticArray every ~diagnostic_period wall seconds, default 1, also while a bag's clock is
// paused):
//   "quadric_slam: <nodelet name>"              frames received, processed and dropped (per
//       reason), processing time median / p95 / max over the last frames (a bounded window);
//       OK, WARN when some frames of the period were dropped, ERROR when every one was
//   "quadric_slam: <nodelet name> output rate"  diagnostic_updater::FrequencyStatus of the
//       processed (published) frames, in ROS time (the bag's clock under use_sim_time)
// plus any task a nodelet adds (e.g. the odometry's tracking state).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <ros/ros.h>

#include <limits>
#include <mutex>
#include <string>

#include "quadric_slam/eval/frame_statistics.h"

namespace quadric_slam {

// Adds the processing-time figures of a summary (shared by every nodelet's status).
void addTimingValues(diagnostic_updater::DiagnosticStatusWrapper& status,
                     const TimingSummary& timing);

class NodeletDiagnostics {
 public:
  struct Options {
    // Bounds of the output rate (Hz) below / above which "output rate" warns; the defaults
    // accept any rate and only report it (a frame source's rate is not known in advance).
    double min_output_rate_hz = 0.0;
    double max_output_rate_hz = std::numeric_limits<double>::infinity();
    std::size_t timing_window = 300;  // frames the processing-time figures cover
  };

  // nodelet_name: the nodelet's getName() (e.g. "/normal_estimation"); private_nh: where
  // ~diagnostic_period is read.
  NodeletDiagnostics(ros::NodeHandle& nh, ros::NodeHandle& private_nh,
                     const std::string& nodelet_name, const Options& options);
  NodeletDiagnostics(ros::NodeHandle& nh, ros::NodeHandle& private_nh,
                     const std::string& nodelet_name)
      : NodeletDiagnostics(nh, private_nh, nodelet_name, Options()) {}

  // One of the two per frame the nodelet receives. Thread-safe.
  void frameProcessed(double processing_ms);
  void frameDropped(const std::string& reason);

  // Another status "quadric_slam: <nodelet name> <task>", reported with the others; fn runs on
  // the reporting thread (it must lock what it reads).
  template <class T>
  void addTask(const std::string& task, T* object,
               void (T::*fn)(diagnostic_updater::DiagnosticStatusWrapper&)) {
    updater_.add(name_ + " " + task, object, fn);
  }

 private:
  void report(diagnostic_updater::DiagnosticStatusWrapper& status);
  void onTimer(const ros::WallTimerEvent&);

  std::string name_;
  double min_rate_hz_, max_rate_hz_;  // FrequencyStatusParam points at these
  diagnostic_updater::Updater updater_;
  diagnostic_updater::FrequencyStatus output_rate_;
  std::mutex mutex_;
  FrameStatistics frames_;
  ros::WallTimer timer_;
};

}  // namespace quadric_slam
