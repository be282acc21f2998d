// odometry: organized cloud with normals -> frame-to-keyframe point-to-plane ICP odometry.
//
// Subscribes  points_normals (sensor_msgs/PointCloud2, organized, fields x y z normal_x normal_y
//             normal_z, NaN where there is no data, camera optical frame; the output of
//             quadric_slam/NormalEstimation)
//             depth/camera_info (sensor_msgs/CameraInfo, the latest one is used; the cloud may be
//             a decimation of that image: the factor is cloud width vs camera_info width)
// Publishes   odom (nav_msgs/Odometry: pose of ~camera_frame in ~odom_frame with covariance)
//             tf ~odom_frame -> ~camera_frame (when ~publish_tf)
//             /diagnostics (diagnostic_msgs/DiagnosticArray, at most once a second)
// All parameters are documented in config/odometry.yaml.
// A cloud or camera_info it cannot use (see ros/message_validation.h), or a cloud that makes the
// core throw, gets an error, throttled per reason; dropped clouds are counted on /diagnostics.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/transform_broadcaster.h>
#include <pluginlib/class_list_macros.hpp>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>

#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/pipeline/pipeline_params.h"
#include "quadric_slam/ros/depth_image.h"
#include "quadric_slam/ros/diagnostics.h"
#include "quadric_slam/ros/drop_reporter.h"
#include "quadric_slam/ros/message_validation.h"
#include "quadric_slam/ros/params.h"
#include "quadric_slam/ros/points_normals.h"

namespace quadric_slam {

class OdometryNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& private_nh = getPrivateNodeHandle();

    ParamLog log;
    OdometryTracker::Params params;
    int queue_size = 5;
    try {
      const RosParamReader reader(private_nh);
      readParam(reader, "odom_frame", odom_frame_, log);
      readParam(reader, "camera_frame", camera_frame_, log);
      readParam(reader, "publish_tf", publish_tf_, log);
      readOdometryParams(reader, params, log);
      readParam(reader, "queue_size", queue_size, log);
      if (odom_frame_.empty() || camera_frame_.empty() || odom_frame_ == camera_frame_)
        throw std::invalid_argument("odom_frame and camera_frame must be non-empty and differ");
      if (queue_size < 1)
        throw std::invalid_argument("queue_size must be >= 1");
      tracker_ = std::make_unique<OdometryTracker>(params);
    } catch (const std::invalid_argument& e) {
      NODELET_FATAL("odometry: invalid parameter: %s", e.what());
      throw;
    }
    NODELET_INFO("odometry parameters:%s", log.str().c_str());

    tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    odom_pub_ = nh.advertise<nav_msgs::Odometry>("odom", queue_size);
    diagnostics_pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 1);
    input_diagnostics_ = std::make_unique<NodeletDiagnostics>(nh, "quadric_slam: odometry");
    cloud_drops_ =
        std::make_unique<DropReporter>("odometry: dropping cloud", input_diagnostics_.get());
    info_drops_ = std::make_unique<DropReporter>("odometry: ignoring camera_info", nullptr);
    info_sub_ = nh.subscribe("depth/camera_info", queue_size, &OdometryNodelet::onCameraInfo, this);
    cloud_sub_ = nh.subscribe("points_normals", queue_size, &OdometryNodelet::onCloud, this);
  }

  void onCameraInfo(const sensor_msgs::CameraInfoConstPtr& info) {
    info_drops_->guard([&] { processCameraInfo(info); });
  }

  void processCameraInfo(const sensor_msgs::CameraInfoConstPtr& info) {
    const std::string problem = cameraInfoProblem(*info);
    if (!problem.empty()) {
      info_drops_->report(problem);
      return;
    }
    std::lock_guard<std::mutex> lock(intrinsics_mutex_);
    intrinsics_ = intrinsicsFromCameraInfo(*info);
    have_intrinsics_ = true;
  }

  void onCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
    cloud_drops_->guard([&] { processCloud(msg); });
  }

  void processCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
    const auto start = std::chrono::steady_clock::now();
    CameraIntrinsics intrinsics;
    {
      std::lock_guard<std::mutex> lock(intrinsics_mutex_);
      if (!have_intrinsics_) {
        cloud_drops_->drop("no valid camera_info received on " + info_sub_.getTopic() + " yet");
        return;
      }
      intrinsics = intrinsics_;
    }
    std::string problem = pointsNormalsFromMsg(*msg, cloud_);
    if (!problem.empty()) {
      cloud_drops_->drop(problem);
      return;
    }
    if (organizedCloudDecimation(intrinsics, static_cast<int>(msg->width),
                                 static_cast<int>(msg->height), &problem) == 0) {
      cloud_drops_->drop(problem);
      return;
    }

    const double stamp = msg->header.stamp.toSec();
    if (have_stamp_ && stamp < last_stamp_) {
      NODELET_WARN(
          "odometry: time went backwards (%.3f s after %.3f s; a looping bag?): "
          "resetting odometry, %s restarts at the identity",
          stamp, last_stamp_, odom_frame_.c_str());
      tracker_->reset();
      last_pose_valid_ = false;
    }
    have_stamp_ = true;
    last_stamp_ = stamp;

    const OdometryTracker::Result result = tracker_->track(cloud_, intrinsics, stamp);
    input_diagnostics_->frameProcessed(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    ++frames_;
    counts_[static_cast<int>(result.status)]++;
    if (result.status != TrackingStatus::kOk) {
      NODELET_WARN_THROTTLE(5.0, "odometry: tracking %s: %s", toString(result.status),
                            result.icp.message.c_str());
    }
    publishDiagnostics(result, msg->header.stamp);
    if (!tracker_->initialized())
      return;  // no odom frame yet (no usable first frame)
    publishOdometry(result, msg->header.stamp);
  }

  void publishOdometry(const OdometryTracker::Result& result, const ros::Time& stamp) {
    auto odom = boost::make_shared<nav_msgs::Odometry>();
    odom->header.stamp = stamp;
    odom->header.frame_id = odom_frame_;
    odom->child_frame_id = camera_frame_;
    const Eigen::Isometry3d& T = result.T_odom_camera;
    const Eigen::Quaterniond q(T.linear());
    odom->pose.pose.position.x = T.translation().x();
    odom->pose.pose.position.y = T.translation().y();
    odom->pose.pose.position.z = T.translation().z();
    odom->pose.pose.orientation.x = q.x();
    odom->pose.pose.orientation.y = q.y();
    odom->pose.pose.orientation.z = q.z();
    odom->pose.pose.orientation.w = q.w();
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c)
        odom->pose.covariance[6 * r + c] = result.covariance(r, c);
    }
    // Twist: finite difference of the last two poses, in the camera (child) frame. Its
    // covariance is not estimated: a large diagonal says so.
    const double dt = (stamp - last_pose_stamp_).toSec();
    if (last_pose_valid_ && dt > 0) {
      const Eigen::Isometry3d delta = last_pose_.inverse() * T;
      const Eigen::AngleAxisd aa(delta.linear());
      const Eigen::Vector3d v = delta.translation() / dt, w = aa.axis() * aa.angle() / dt;
      odom->twist.twist.linear.x = v.x();
      odom->twist.twist.linear.y = v.y();
      odom->twist.twist.linear.z = v.z();
      odom->twist.twist.angular.x = w.x();
      odom->twist.twist.angular.y = w.y();
      odom->twist.twist.angular.z = w.z();
    }
    for (int i = 0; i < 6; ++i)
      odom->twist.covariance[7 * i] = 1e6;
    last_pose_ = T;
    last_pose_stamp_ = stamp;
    last_pose_valid_ = true;
    odom_pub_.publish(odom);

    if (publish_tf_) {
      geometry_msgs::TransformStamped tf;
      tf.header = odom->header;
      tf.child_frame_id = camera_frame_;
      tf.transform.translation.x = T.translation().x();
      tf.transform.translation.y = T.translation().y();
      tf.transform.translation.z = T.translation().z();
      tf.transform.rotation = odom->pose.pose.orientation;
      tf_broadcaster_->sendTransform(tf);
    }
  }

  void publishDiagnostics(const OdometryTracker::Result& result, const ros::Time& stamp) {
    const ros::WallTime now = ros::WallTime::now();
    if (diagnostics_pub_.getNumSubscribers() == 0 || (now - last_diagnostics_).toSec() < 1.0)
      return;
    last_diagnostics_ = now;
    diagnostic_msgs::DiagnosticArray array;
    array.header.stamp = stamp;
    diagnostic_msgs::DiagnosticStatus status;
    status.name = getName() + ": tracking";
    status.hardware_id = camera_frame_;
    switch (result.status) {
      case TrackingStatus::kOk:
        status.level = diagnostic_msgs::DiagnosticStatus::OK;
        status.message = "tracking";
        break;
      case TrackingStatus::kDegenerate:
        status.level = diagnostic_msgs::DiagnosticStatus::WARN;
        status.message = "degenerate geometry: " + result.icp.message;
        break;
      case TrackingStatus::kLost:
        status.level = diagnostic_msgs::DiagnosticStatus::ERROR;
        status.message = "lost: " + result.icp.message;
        break;
    }
    const auto add = [&status](const std::string& key, const auto& value) {
      diagnostic_msgs::KeyValue kv;
      kv.key = key;
      std::ostringstream text;
      text << value;
      kv.value = text.str();
      status.values.push_back(kv);
    };
    add("frames", frames_);
    add("ok", counts_[0]);
    add("degenerate", counts_[1]);
    add("lost", counts_[2]);
    add("consecutive lost", result.consecutive_lost);
    add("correspondences", result.icp.correspondences);
    add("inlier fraction", result.icp.inlier_fraction);
    add("rms residual (m at 1 m)", result.icp.rms_residual);
    add("iterations", result.icp.iterations);
    array.status.push_back(status);
    diagnostics_pub_.publish(array);
  }

  std::string odom_frame_ = "odom";
  std::string camera_frame_ = "camera";
  bool publish_tf_ = true;
  std::unique_ptr<OdometryTracker> tracker_;
  // Input health (frames processed and dropped, with the reason) beside the tracking status.
  std::unique_ptr<NodeletDiagnostics> input_diagnostics_;
  std::unique_ptr<DropReporter> cloud_drops_, info_drops_;
  pcl::PointCloud<pcl::PointNormal> cloud_;  // reused conversion buffer
  std::mutex intrinsics_mutex_;
  CameraIntrinsics intrinsics_;
  bool have_intrinsics_ = false;
  bool have_stamp_ = false;
  double last_stamp_ = 0;
  bool last_pose_valid_ = false;
  Eigen::Isometry3d last_pose_ = Eigen::Isometry3d::Identity();
  ros::Time last_pose_stamp_;
  long frames_ = 0;
  long counts_[3] = {0, 0, 0};
  ros::WallTime last_diagnostics_;
  ros::Subscriber cloud_sub_, info_sub_;
  ros::Publisher odom_pub_, diagnostics_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
};

}  // namespace quadric_slam

PLUGINLIB_EXPORT_CLASS(quadric_slam::OdometryNodelet, nodelet::Nodelet)
