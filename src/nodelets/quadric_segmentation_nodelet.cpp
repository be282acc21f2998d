// quadric_segmentation: organized cloud with normals -> quadric observations (planes, spheres,
// cylinders, cones) in the camera frame, with the core QuadricSegmenter.
//
// Subscribes  points_normals (sensor_msgs/PointCloud2, organized, fields x y z normal_x normal_y
//             normal_z [curvature], NaN where unknown; e.g. from quadric_slam/NormalEstimation)
// Parameters  config/segmentation.yaml (every key documented there)
// Publishes   observations (quadric_slam/QuadricObservationArray, the cloud's stamp and frame
//             (without a leading '/', as on every output: tf2 and rviz refuse it); an
//             empty array when the frame holds no quadric, e.g. an empty or all-NaN cloud)
//             (each with at most ~max_support_points supporting points for the reconstruction)
//             ~segmentation_image (sensor_msgs/Image rgb8, a colour per segment; only computed
//             while subscribed)
//             ~segmented_cloud (sensor_msgs/PointCloud2 x y z label, organized, label 0 =
//             unassigned; only computed while subscribed)
//             /diagnostics (frames processed and dropped per reason, processing time, output
//             rate: ros/diagnostics.h)
// Clouds are segmented by ~workers threads at once (ros/ordered_worker_pool.h): one frame takes
// longer than a 30 Hz frame period on a small machine, and the nodelet's callbacks run one at a
// time; observations are still published in the clouds' order. At most ~queue_size clouds wait
// for a worker; a newer one pushes out the oldest (counted as dropped on /diagnostics).
// A cloud the segmenter cannot read (see ros/message_validation.h: missing or non-float32 normal
// fields, not organized, inconsistent sizes) or that makes the core throw gets an error, throttled
// per reason, and is dropped and counted on /diagnostics.
#include <nodelet/nodelet.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <pluginlib/class_list_macros.hpp>
#include <string>
#include <vector>

#include "quadric_slam/QuadricObservationArray.h"
#include "quadric_slam/frontend/detection_measurement.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/pipeline/segmenter_params.h"
#include "quadric_slam/ros/conversions.h"
#include "quadric_slam/ros/diagnostics.h"
#include "quadric_slam/ros/drop_reporter.h"
#include "quadric_slam/ros/frame_ids.h"
#include "quadric_slam/ros/ordered_worker_pool.h"
#include "quadric_slam/ros/params.h"
#include "quadric_slam/ros/points_normals.h"

namespace quadric_slam {

class QuadricSegmentationNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& private_nh = getPrivateNodeHandle();

    ParamLog log;
    QuadricSegmenter::Params params;
    int queue_size = 2;
    int workers = 1;
    try {
      const RosParamReader reader(private_nh);
      readSegmentationParams(reader, params, log);
      readParam(reader, "queue_size", queue_size, log);
      readParam(reader, "workers", workers, log);
      if (queue_size < 1)
        throw std::invalid_argument("queue_size must be >= 1");
      if (workers < 1 || workers > 8)
        throw std::invalid_argument("workers must be in [1, 8]");
      readParam(reader, "max_support_points", max_support_points_, log);
      if (max_support_points_ < 0)
        throw std::invalid_argument("max_support_points must be >= 0");
      segmenter_ = std::make_unique<QuadricSegmenter>(params);
    } catch (const std::invalid_argument& e) {
      NODELET_FATAL("quadric_segmentation: invalid parameter: %s", e.what());
      throw;
    }
    NODELET_INFO("quadric_segmentation parameters:%s", log.str().c_str());

    diagnostics_ = std::make_unique<NodeletDiagnostics>(nh, private_nh, getName());
    drops_ =
        std::make_unique<DropReporter>("quadric_segmentation: dropping cloud", diagnostics_.get());
    observations_pub_ = nh.advertise<QuadricObservationArray>("observations", queue_size);
    image_pub_ = private_nh.advertise<sensor_msgs::Image>("segmentation_image", 1);
    cloud_pub_ = private_nh.advertise<sensor_msgs::PointCloud2>("segmented_cloud", 1);
    clouds_.resize(workers);
    pool_ = std::make_unique<OrderedWorkerPool>(workers, queue_size);
    cloud_sub_ =
        nh.subscribe("points_normals", queue_size, &QuadricSegmentationNodelet::onCloud, this);
  }

  ~QuadricSegmentationNodelet() override {
    cloud_sub_.shutdown();
    pool_.reset();  // running segmentations finish and publish before the members they use go
  }

  void onCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
    drops_->guard([&] {
      const int pushed_out = pool_->submit([this, msg](int worker) {
        const auto start = std::chrono::steady_clock::now();
        // What the worker computed is published (or reported) in the clouds' order.
        std::function<void()> deliver;
        drops_->guard([&] { deliver = processCloud(msg, worker, start); });
        return deliver;
      });
      if (pushed_out > 0)
        diagnostics_->frameDropped("not keeping up: the oldest waiting cloud was dropped");
    });
  }

  // Segments msg on worker `worker` (its own cloud storage) and returns what publishes the result.
  std::function<void()> processCloud(const sensor_msgs::PointCloud2ConstPtr& msg, int worker,
                                     std::chrono::steady_clock::time_point start) {
    {
      pcl::PointCloud<pcl::PointNormal>& cloud = clouds_[worker];  // kept from frame to frame
      const std::string problem = pointsNormalsFromMsg(*msg, cloud);
      if (!problem.empty())
        return [this, problem] { drops_->drop(problem); };
      const Segmentation segmentation = segmenter_->segment(cloud);

      // Every output carries the cloud's header, its frame id without a leading '/'.
      std_msgs::Header header = msg->header;
      header.frame_id = withoutLeadingSlash(header.frame_id);
      // Core measurements (detection_measurement.h) -> messages (ros/conversions.h); the header is
      // copied exactly (the conversion goes through a double stamp).
      FrameMeasurements measurements =
          toFrameMeasurements(segmentation, header.stamp.toSec(), header.frame_id);
      attachSupportPoints(measurements, segmentation, cloud, max_support_points_);
      auto out = boost::make_shared<QuadricObservationArray>(toObservationArrayMsg(measurements));
      out->header = header;
      const sensor_msgs::ImagePtr image =
          image_pub_.getNumSubscribers() > 0 ? segmentationImage(segmentation, header) : nullptr;
      const sensor_msgs::PointCloud2Ptr labelled =
          cloud_pub_.getNumSubscribers() > 0 ? segmentedCloud(cloud, segmentation, header)
                                             : nullptr;
      // The processing time is the worker's, without the wait for the clouds before it.
      const double processing_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      return [this, out, image, labelled, processing_ms] {
        observations_pub_.publish(out);
        if (image)
          image_pub_.publish(image);
        if (labelled)
          cloud_pub_.publish(labelled);
        diagnostics_->frameProcessed(processing_ms);
      };
    }
  }

  static sensor_msgs::ImagePtr segmentationImage(const Segmentation& segmentation,
                                                 const std_msgs::Header& header) {
    const cv::Mat rgb = colouriseLabels(segmentation.labels);
    auto image = boost::make_shared<sensor_msgs::Image>();
    image->header = header;
    image->height = static_cast<std::uint32_t>(rgb.rows);
    image->width = static_cast<std::uint32_t>(rgb.cols);
    image->encoding = sensor_msgs::image_encodings::RGB8;
    image->step = static_cast<std::uint32_t>(rgb.cols * 3);
    image->data.resize(static_cast<std::size_t>(image->step) * rgb.rows);
    for (int r = 0; r < rgb.rows; ++r)
      std::memcpy(&image->data[static_cast<std::size_t>(r) * image->step], rgb.ptr(r), image->step);
    return image;
  }

  static sensor_msgs::PointCloud2Ptr segmentedCloud(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                                    const Segmentation& segmentation,
                                                    const std_msgs::Header& header) {
    pcl::PointCloud<pcl::PointXYZL> labelled(cloud.width, cloud.height);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      labelled.points[i].x = cloud.points[i].x;
      labelled.points[i].y = cloud.points[i].y;
      labelled.points[i].z = cloud.points[i].z;
      labelled.points[i].label = segmentation.labels.at<std::uint16_t>(
          static_cast<int>(i / cloud.width), static_cast<int>(i % cloud.width));
    }
    labelled.is_dense = false;
    auto out = boost::make_shared<sensor_msgs::PointCloud2>();
    pcl::toROSMsg(labelled, *out);
    out->header = header;
    return out;
  }

  std::unique_ptr<QuadricSegmenter> segmenter_;
  int max_support_points_ = 1000;
  std::unique_ptr<NodeletDiagnostics> diagnostics_;
  std::unique_ptr<DropReporter> drops_;
  ros::Publisher observations_pub_, image_pub_, cloud_pub_;
  // The incoming cloud as PCL points, one per worker: kept, so that a frame of the same size
  // allocates and zero-fills nothing (15 MB at 640 x 480).
  std::vector<pcl::PointCloud<pcl::PointNormal>> clouds_;
  // Declared after everything its jobs use, so it is destroyed (its jobs finished) first.
  std::unique_ptr<OrderedWorkerPool> pool_;
  ros::Subscriber cloud_sub_;
};

}  // namespace quadric_slam

PLUGINLIB_EXPORT_CLASS(quadric_slam::QuadricSegmentationNodelet, nodelet::Nodelet)
