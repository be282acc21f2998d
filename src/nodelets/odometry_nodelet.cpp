// odometry: organized cloud with normals -> frame-to-keyframe point-to-plane ICP odometry.
//
// Subscribes  points_normals (sensor_msgs/PointCloud2, organized, fields x y z normal_x normal_y
//             normal_z, NaN where there is no data, camera optical frame; the output of
//             quadric_slam/NormalEstimation)
//             depth/camera_info (sensor_msgs/CameraInfo, the latest one is used; the cloud may be
//             a decimation of that image: the factor is cloud width vs camera_info width)
//             observations (quadric_slam/QuadricObservationArray from quadric_slam/
//             QuadricSegmentation, only when ~use_observations: paired with points_normals by
//             exact stamp, they give the tracker its motion guess for large steps, as in the
//             offline runner)
//             rgb/image and rgb/camera_info (sensor_msgs/Image rgb8, bgr8 or mono8 registered to
//             the depth, through image_transport; only with ~photometric_refinement or
//             ~feature_motion_guess): each cloud takes the image nearest its stamp within
//             ~rgb_max_stamp_difference from a buffer of ~rgb_buffer_size; a degenerate alignment
//             is refined by its intensities (odometry/photometric_refinement.h) and a large step
//             guessed from its corners (odometry/feature_motion_guess.h); a cloud whose image has
//             not arrived yet is
//             tracked on depth alone (counted on /diagnostics), never held back
// Publishes   odom (nav_msgs/Odometry: pose of ~camera_frame in ~odom_frame with covariance;
//             while tracking is lost, the last pose with every pose variance 9999: ros/
//             odometry_status.h; twist: the step from the previous message over dt, with the
//             tracker's increment covariance / dt^2, 1e6 on the diagonal for the first message)
//             tf ~odom_frame -> ~camera_frame (when ~publish_tf)
//             /diagnostics (frames processed and dropped per reason, processing time, output
//             rate: ros/diagnostics.h; and "<name> tracking": ok / degenerate / lost with the ICP
//             figures of the last frame)
// All parameters are documented in config/odometry.yaml. The cloud's own frame id is not used: the
// pose is that of ~camera_frame, our name for the tracked optical frame (normal_estimation's
// ~output_frame gives the clouds the same name in quadric_slam.launch).
// A cloud or camera_info it cannot use (see ros/message_validation.h), or a cloud that makes the
// core throw, gets an error, throttled per reason; dropped clouds are counted on /diagnostics.
#include <geometry_msgs/TransformStamped.h>
#include <image_transport/image_transport.h>
#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
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
#include <string>

#include "quadric_slam/QuadricObservationArray.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/pipeline/pipeline_params.h"
#include "quadric_slam/ros/colour_image_buffer.h"
#include "quadric_slam/ros/conversions.h"
#include "quadric_slam/ros/depth_image.h"
#include "quadric_slam/ros/diagnostics.h"
#include "quadric_slam/ros/drop_reporter.h"
#include "quadric_slam/ros/frame_ids.h"
#include "quadric_slam/ros/message_validation.h"
#include "quadric_slam/ros/odometry_status.h"
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
      readFrameParam(reader, "odom_frame", odom_frame_, log);
      readFrameParam(reader, "camera_frame", camera_frame_, log);
      readParam(reader, "publish_tf", publish_tf_, log);
      readOdometryParams(reader, params, log);
      readParam(reader, "queue_size", queue_size, log);
      readParam(reader, "use_observations", use_observations_, log);
      int rgb_buffer_size = 10;
      readParam(reader, "rgb_buffer_size", rgb_buffer_size, log);
      readParam(reader, "rgb_max_stamp_difference", rgb_max_stamp_difference_, log);
      if (params.photometric_refinement || params.feature_motion_guess) {
        if (rgb_buffer_size < 1)
          throw std::invalid_argument("rgb_buffer_size must be >= 1");
        colour_images_ = std::make_unique<ColourImageBuffer>(
            static_cast<std::size_t>(rgb_buffer_size), rgb_max_stamp_difference_);
      }
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
    diagnostics_ = std::make_unique<NodeletDiagnostics>(nh, private_nh, getName());
    diagnostics_->addTask("tracking", this, &OdometryNodelet::diagnoseTracking);
    cloud_drops_ = std::make_unique<DropReporter>("odometry: dropping cloud", diagnostics_.get());
    info_drops_ = std::make_unique<DropReporter>("odometry: ignoring camera_info", nullptr);
    info_sub_ = nh.subscribe("depth/camera_info", queue_size, &OdometryNodelet::onCameraInfo, this);
    if (colour_images_) {
      rgb_drops_ = std::make_unique<DropReporter>("odometry: ignoring colour image", nullptr);
      image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
      rgb_sub_ = image_transport_->subscribeCamera(
          "rgb/image", static_cast<std::uint32_t>(queue_size), &OdometryNodelet::onRgb, this,
          image_transport::TransportHints("raw", ros::TransportHints(), private_nh));
    }
    if (use_observations_) {
      cloud_filter_.subscribe(nh, "points_normals", queue_size);
      // A cloud the segmentation refuses never gets observations, so the pair never forms:
      // report a bad cloud when it arrives, not only when it is paired.
      cloud_filter_.registerCallback(&OdometryNodelet::onCloudArrived, this);
      observations_filter_.subscribe(nh, "observations", queue_size);
      sync_ = std::make_unique<Synchronizer>(cloud_filter_, observations_filter_, queue_size);
      sync_->registerCallback(&OdometryNodelet::onCloudAndObservations, this);
    } else {
      cloud_sub_ = nh.subscribe("points_normals", queue_size, &OdometryNodelet::onCloud, this);
    }
  }

  void onCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
    cloud_drops_->guard([&] { track(msg, nullptr); });
  }

  void onCloudArrived(const sensor_msgs::PointCloud2ConstPtr& msg) {
    cloud_drops_->guard([&] {
      const std::string problem = pointCloudProblem(*msg, pointsNormalsLayout());
      if (!problem.empty())
        cloud_drops_->drop(problem);
    });
  }

  void onCloudAndObservations(const sensor_msgs::PointCloud2ConstPtr& msg,
                              const QuadricObservationArrayConstPtr& observations) {
    cloud_drops_->guard([&] { trackWithObservations(msg, observations); });
  }

  void trackWithObservations(const sensor_msgs::PointCloud2ConstPtr& msg,
                             const QuadricObservationArrayConstPtr& observations) {
    int rejected = 0;
    const FrameMeasurements frame = fromObservationArrayMsg(*observations, &rejected);
    if (rejected > 0) {
      NODELET_WARN_THROTTLE(5.0,
                            "odometry: %d of %zu observations at %.3f s did not convert; the "
                            "motion guess uses the rest",
                            rejected, observations->observations.size(),
                            observations->header.stamp.toSec());
    }
    track(msg, &frame.observations);
  }

  // A colour image and its camera_info into the buffer the clouds look their images up in.
  void onRgb(const sensor_msgs::ImageConstPtr& image, const sensor_msgs::CameraInfoConstPtr& info) {
    rgb_drops_->guard([&] {
      ColourImageBuffer::Entry entry;
      const std::string problem = colourEntryFromMessages(image, info, &entry);
      if (!problem.empty()) {
        rgb_drops_->report(problem);
        return;
      }
      colour_images_->add(std::move(entry));
    });
  }

  // The colour image of the cloud's stamp, registered to the depth, or nullptr (depth alone).
  const cv::Mat* imageFor(double stamp, const CameraIntrinsics& depth_intrinsics,
                          ColourImageBuffer::Entry* entry) {
    if (!colour_images_)
      return nullptr;
    const bool found = colour_images_->nearest(stamp, entry);
    colour_images_->dropBefore(stamp - rgb_max_stamp_difference_);
    std::lock_guard<std::mutex> lock(tracking_mutex_);
    if (!found) {
      ++frames_without_image_;
      return nullptr;
    }
    if (entry->rgb->image.cols != depth_intrinsics.width ||
        entry->rgb->image.rows != depth_intrinsics.height) {
      ++frames_without_image_;
      NODELET_WARN_THROTTLE(5.0,
                            "odometry: the colour image is %dx%d, the depth %dx%d: not registered "
                            "to the depth, tracking on depth alone",
                            entry->rgb->image.cols, entry->rgb->image.rows, depth_intrinsics.width,
                            depth_intrinsics.height);
      return nullptr;
    }
    return &entry->rgb->image;
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

  void track(const sensor_msgs::PointCloud2ConstPtr& msg,
             const std::vector<QuadricMeasurement>* observations) {
    const auto start = std::chrono::steady_clock::now();
    CameraIntrinsics intrinsics;
    {
      std::lock_guard<std::mutex> lock(intrinsics_mutex_);
      if (!have_intrinsics_) {
        drop("no valid camera_info received on " + info_sub_.getTopic() + " yet");
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

    // (What the tracker throws is caught by the guard around this callback and counted as a drop.)
    if (observations != nullptr)
      tracker_->adoptSurfaceNormals(*observations, cloud_);
    ColourImageBuffer::Entry image;
    const OdometryTracker::Result result = tracker_->track(cloud_, intrinsics, stamp, observations,
                                                           imageFor(stamp, intrinsics, &image));
    if (result.status != TrackingStatus::kOk) {
      NODELET_WARN_THROTTLE(5.0, "odometry: tracking %s: %s", toString(result.status),
                            result.icp.message.c_str());
    }
    {
      std::lock_guard<std::mutex> lock(tracking_mutex_);
      ++frames_;
      counts_[static_cast<int>(result.status)]++;
      photometric_refined_ += result.photometric.refined ? 1 : 0;
      last_result_ = result;
    }
    if (!tracker_->initialized()) {
      drop("no odometry yet: the first frame was not usable");
      return;
    }
    publishOdometry(result, msg->header.stamp);
    diagnostics_->frameProcessed(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }

  void drop(const std::string& reason) { cloud_drops_->drop(reason); }

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
    if (result.status == TrackingStatus::kLost)
      markLost(*odom);  // the last pose, flagged (ros/odometry_status.h)
    // Twist: finite difference of the last two poses, in the camera (child) frame. Its
    // covariance carries the tracker's increment covariance from the previous message
    // (OdometryTracker::Result::increment_covariance, [rho; phi] in this frame's body tangent) as
    // that of a velocity held over dt: Cov(twist) = Cov(increment) / dt^2; the mapping nodelet
    // multiplies by dt^2 again. Without a previous pose (the first message), and for a lost frame
    // (the tracker knows nothing of the motion; the mapper then uses its own model, as offline),
    // it is not estimated: a large diagonal (1e6) says so.
    const double dt = (stamp - last_pose_stamp_).toSec();
    const bool twist_known = last_pose_valid_ && dt > 0 && result.status != TrackingStatus::kLost;
    if (twist_known) {
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
    if (twist_known) {
      for (int r = 0; r < 6; ++r) {
        for (int c = 0; c < 6; ++c)
          odom->twist.covariance[6 * r + c] = result.increment_covariance(r, c) / (dt * dt);
      }
    } else {
      for (int i = 0; i < 6; ++i)
        odom->twist.covariance[7 * i] = 1e6;
    }
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

  // The tracking state of the last frame, with the counts per state since the start.
  void diagnoseTracking(diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(tracking_mutex_);
    const OdometryTracker::Result& result = last_result_;
    using diagnostic_msgs::DiagnosticStatus;
    if (frames_ == 0)
      status.summary(DiagnosticStatus::OK, "waiting for input");
    else if (result.status == TrackingStatus::kOk)
      status.summary(DiagnosticStatus::OK, "tracking");
    else if (result.status == TrackingStatus::kDegenerate)
      status.summary(DiagnosticStatus::WARN, "degenerate geometry: " + result.icp.message);
    else
      status.summary(DiagnosticStatus::ERROR, "lost: " + result.icp.message);
    status.add("frames", frames_);
    status.add("ok", counts_[0]);
    status.add("degenerate", counts_[1]);
    status.add("lost", counts_[2]);
    status.add("consecutive lost", result.consecutive_lost);
    status.add("correspondences", result.icp.correspondences);
    status.add("inlier fraction", result.icp.inlier_fraction);
    status.add("rms residual (m at 1 m)", result.icp.rms_residual);
    status.add("iterations", result.icp.iterations);
    if (colour_images_) {
      status.add("refined by intensities", photometric_refined_);
      status.add("frames without colour image", frames_without_image_);
    }
  }

  std::string odom_frame_ = "odom";
  std::string camera_frame_ = "camera";
  bool publish_tf_ = true;
  std::unique_ptr<OdometryTracker> tracker_;
  pcl::PointCloud<pcl::PointNormal> cloud_;  // reused conversion buffer
  std::mutex intrinsics_mutex_;
  CameraIntrinsics intrinsics_;
  bool have_intrinsics_ = false;
  bool have_stamp_ = false;
  double last_stamp_ = 0;
  bool last_pose_valid_ = false;
  Eigen::Isometry3d last_pose_ = Eigen::Isometry3d::Identity();
  ros::Time last_pose_stamp_;
  std::mutex tracking_mutex_;  // the tracking figures, read by the diagnostics thread
  long frames_ = 0;
  long counts_[3] = {0, 0, 0};
  OdometryTracker::Result last_result_;
  std::unique_ptr<NodeletDiagnostics> diagnostics_;
  // Input health (frames processed and dropped, with the reason) beside the tracking status.
  std::unique_ptr<DropReporter> cloud_drops_, info_drops_;
  bool use_observations_ = false;
  // The colour images for the photometric refinement (only with ~photometric_refinement).
  std::unique_ptr<ColourImageBuffer> colour_images_;
  double rgb_max_stamp_difference_ = 0.02;
  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  image_transport::CameraSubscriber rgb_sub_;
  std::unique_ptr<DropReporter> rgb_drops_;
  long photometric_refined_ = 0, frames_without_image_ = 0;
  ros::Subscriber cloud_sub_, info_sub_;
  using Synchronizer =
      message_filters::TimeSynchronizer<sensor_msgs::PointCloud2, QuadricObservationArray>;
  message_filters::Subscriber<sensor_msgs::PointCloud2> cloud_filter_;
  message_filters::Subscriber<QuadricObservationArray> observations_filter_;
  std::unique_ptr<Synchronizer> sync_;
  ros::Publisher odom_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
};

}  // namespace quadric_slam

PLUGINLIB_EXPORT_CLASS(quadric_slam::OdometryNodelet, nodelet::Nodelet)
