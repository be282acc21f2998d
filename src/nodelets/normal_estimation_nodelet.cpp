// normal_estimation: depth image + camera_info -> organized PointCloud2 with xyz and normals.
//
// Subscribes  depth/image (sensor_msgs/Image, 32FC1 metres or 16UC1 millimetres) through
//             image_transport: ~image_transport picks the transport (default raw; e.g.
//             compressedDepth when its plugin is installed)
//             depth/camera_info (sensor_msgs/CameraInfo, the latest one is used; not paired with
//             the image by stamp, so a camera_info that is bad, late or missing for some frames
//             does not hold back the depth stream — the image is dropped only until a valid one
//             has been received)
// Parameters  config/normal_estimation.yaml (every key documented there)
//             ~depth_correction (string, default ""): a file of scripts/calibrate_depth; the
//             sensor's fixed depth distortion is undone before the normals (a depth image of
//             another size than the file's is dropped with the reason)
// Publishes   points_normals (sensor_msgs/PointCloud2, organized, fields x y z normal_x normal_y
//             normal_z curvature, NaN where there is no data, the depth image's stamp; frame
//             ~output_frame, or the image's frame id when that is empty, without a leading '/')
//             /diagnostics (frames processed and dropped per reason, processing time, output
//             rate: ros/diagnostics.h)
// Bad input (no camera_info yet, unsupported encoding, size mismatch, malformed buffer: see
// ros/message_validation.h) and anything the core throws get an error, throttled per reason, and
// the frame is dropped and counted on /diagnostics.
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <pluginlib/class_list_macros.hpp>

#include <chrono>
#include <memory>
#include <mutex>

#include "quadric_slam/frontend/depth_correction.h"
#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/io/depth_correction_yaml.h"
#include "quadric_slam/pipeline/pipeline_params.h"
#include "quadric_slam/ros/depth_image.h"
#include "quadric_slam/ros/diagnostics.h"
#include "quadric_slam/ros/drop_reporter.h"
#include "quadric_slam/ros/frame_ids.h"
#include "quadric_slam/ros/message_validation.h"
#include "quadric_slam/ros/params.h"

namespace quadric_slam {

class NormalEstimationNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& private_nh = getPrivateNodeHandle();

    ParamLog log;
    NormalEstimator::Params normal_params;
    int queue_size = 5;
    try {
      const RosParamReader params(private_nh);
      readNormalEstimationParams(params, back_projection_, normal_params, log);
      readFrameParam(params, "output_frame", output_frame_, log);
      readParam(params, "queue_size", queue_size, log);
      std::string correction_file;
      readParam(params, "depth_correction", correction_file, log);
      if (!correction_file.empty())
        depth_correction_ = readDepthCorrectionYaml(correction_file);
      estimator_ = std::make_unique<NormalEstimator>(normal_params);
    } catch (const std::invalid_argument& e) {
      NODELET_FATAL("normal_estimation: invalid parameter: %s", e.what());
      throw;
    } catch (const std::runtime_error& e) {
      NODELET_FATAL("normal_estimation: depth_correction: %s", e.what());
      throw;
    }
    NODELET_INFO("normal_estimation parameters:%s", log.str().c_str());

    diagnostics_ = std::make_unique<NodeletDiagnostics>(nh, private_nh, getName());
    depth_drops_ = std::make_unique<DropReporter>("normal_estimation: dropping depth frame",
                                                  diagnostics_.get());
    info_drops_ =
        std::make_unique<DropReporter>("normal_estimation: ignoring camera_info", nullptr);
    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("points_normals", queue_size);
    info_sub_ =
        nh.subscribe("depth/camera_info", queue_size, &NormalEstimationNodelet::onCameraInfo, this);
    image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
    depth_sub_ = image_transport_->subscribe(
        "depth/image", queue_size, &NormalEstimationNodelet::onDepth, this,
        image_transport::TransportHints("raw", ros::TransportHints(), private_nh));
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

  void onDepth(const sensor_msgs::ImageConstPtr& image) {
    depth_drops_->guard([&] { processDepth(image); });
  }

  void processDepth(const sensor_msgs::ImageConstPtr& image) {
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
    pcl::PointCloud<pcl::PointXYZ> cloud;
    const std::string problem = depthImageToCloud(*image, intrinsics, back_projection_, cloud);
    if (!problem.empty()) {
      drop(problem);
      return;
    }
    if (!depth_correction_.empty()) {
      if (depth_correction_.width() != static_cast<int>(image->width) ||
          depth_correction_.height() != static_cast<int>(image->height)) {
        drop("depth image " + std::to_string(image->width) + " x " + std::to_string(image->height) +
             " is not the depth correction's " + std::to_string(depth_correction_.width()) + " x " +
             std::to_string(depth_correction_.height()));
        return;
      }
      depth_correction_.apply(&cloud, back_projection_.decimation);
    }
    estimator_->compute(cloud, with_normals_);
    auto msg = boost::make_shared<sensor_msgs::PointCloud2>();
    pcl::toROSMsg(with_normals_, *msg);
    msg->header = image->header;
    msg->header.frame_id = outputFrameId(output_frame_, image->header.frame_id);
    cloud_pub_.publish(msg);
    diagnostics_->frameProcessed(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }

  void drop(const std::string& reason) { depth_drops_->drop(reason); }

  BackProjectionParams back_projection_;
  DepthCorrection depth_correction_;  // empty: none
  std::string output_frame_;          // "" = the image's frame
  std::unique_ptr<NormalEstimator> estimator_;
  // Output storage reused from frame to frame (a subscription's callbacks never run concurrently).
  pcl::PointCloud<pcl::PointNormal> with_normals_;
  std::unique_ptr<NodeletDiagnostics> diagnostics_;
  std::unique_ptr<DropReporter> depth_drops_, info_drops_;
  std::mutex intrinsics_mutex_;
  CameraIntrinsics intrinsics_;
  bool have_intrinsics_ = false;
  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  image_transport::Subscriber depth_sub_;
  ros::Subscriber info_sub_;
  ros::Publisher cloud_pub_;
};

}  // namespace quadric_slam

PLUGINLIB_EXPORT_CLASS(quadric_slam::NormalEstimationNodelet, nodelet::Nodelet)
