// normal_estimation: depth image + camera_info -> organized PointCloud2 with xyz and normals.
//
// Subscribes  depth/image (sensor_msgs/Image, 32FC1 metres or 16UC1 millimetres)
//             depth/camera_info (sensor_msgs/CameraInfo, the latest one is used)
// Parameters  config/normal_estimation.yaml (every key documented there)
// Publishes   points_normals (sensor_msgs/PointCloud2, organized, fields x y z normal_x normal_y
//             normal_z curvature, NaN where there is no data, the depth image's stamp and frame)
#include <nodelet/nodelet.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>
#include <mutex>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/ros/params.h"

namespace quadric_slam {

class NormalEstimationNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& private_nh = getPrivateNodeHandle();

    ros_params::ParamLog log;
    NormalEstimator::Params normal_params;
    ros_params::read(private_nh, "decimation", back_projection_.decimation, log);
    ros_params::read(private_nh, "min_range", back_projection_.min_range, log);
    ros_params::read(private_nh, "max_range", back_projection_.max_range, log);
    ros_params::read(private_nh, "normal_method", normal_params.method, log);
    ros_params::read(private_nh, "max_depth_change_factor", normal_params.max_depth_change_factor,
                     log);
    ros_params::read(private_nh, "normal_smoothing_size", normal_params.normal_smoothing_size, log);
    ros_params::read(private_nh, "depth_dependent_smoothing",
                     normal_params.depth_dependent_smoothing, log);
    ros_params::read(private_nh, "threads", normal_params.threads, log);
    int queue_size = 5;
    ros_params::read(private_nh, "queue_size", queue_size, log);
    try {
      back_projection_.validate();
      estimator_ = std::make_unique<NormalEstimator>(normal_params);
    } catch (const std::invalid_argument& e) {
      NODELET_FATAL("normal_estimation: invalid parameter: %s", e.what());
      throw;
    }
    NODELET_INFO("normal_estimation parameters:%s", log.str().c_str());

    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("points_normals", queue_size);
    info_sub_ =
        nh.subscribe("depth/camera_info", queue_size, &NormalEstimationNodelet::onCameraInfo, this);
    depth_sub_ = nh.subscribe("depth/image", queue_size, &NormalEstimationNodelet::onDepth, this);
  }

  void onCameraInfo(const sensor_msgs::CameraInfoConstPtr& info) {
    CameraIntrinsics intrinsics;
    intrinsics.fx = info->K[0];
    intrinsics.fy = info->K[4];
    intrinsics.cx = info->K[2];
    intrinsics.cy = info->K[5];
    intrinsics.width = static_cast<int>(info->width);
    intrinsics.height = static_cast<int>(info->height);
    const std::string problem = intrinsics.problem();
    if (!problem.empty()) {
      NODELET_ERROR_THROTTLE(5.0, "normal_estimation: ignoring camera_info: %s", problem.c_str());
      return;
    }
    std::lock_guard<std::mutex> lock(intrinsics_mutex_);
    intrinsics_ = intrinsics;
    have_intrinsics_ = true;
  }

  void onDepth(const sensor_msgs::ImageConstPtr& image) {
    CameraIntrinsics intrinsics;
    {
      std::lock_guard<std::mutex> lock(intrinsics_mutex_);
      if (!have_intrinsics_) {
        NODELET_ERROR_THROTTLE(5.0,
                               "normal_estimation: no valid camera_info received on %s yet; "
                               "dropping depth frames",
                               info_sub_.getTopic().c_str());
        return;
      }
      intrinsics = intrinsics_;
    }
    const std::string size_problem = imageSizeProblem(intrinsics, static_cast<int>(image->width),
                                                      static_cast<int>(image->height));
    if (!size_problem.empty()) {
      NODELET_ERROR_THROTTLE(5.0, "normal_estimation: dropping frame: %s", size_problem.c_str());
      return;
    }

    pcl::PointCloud<pcl::PointXYZ> cloud;
    namespace enc = sensor_msgs::image_encodings;
    if (image->encoding == enc::TYPE_32FC1) {
      if (!checkBuffer<float>(*image))
        return;
      cloud = backProject(view<float>(*image, 1.0), intrinsics, back_projection_);
    } else if (image->encoding == enc::TYPE_16UC1 || image->encoding == enc::MONO16) {
      if (!checkBuffer<std::uint16_t>(*image))
        return;
      cloud = backProject(view<std::uint16_t>(*image, 0.001), intrinsics, back_projection_);
    } else {
      NODELET_ERROR_THROTTLE(5.0,
                             "normal_estimation: unsupported depth encoding '%s' (expected 32FC1 "
                             "metres or 16UC1 millimetres); dropping frame",
                             image->encoding.c_str());
      return;
    }

    const pcl::PointCloud<pcl::PointNormal> with_normals = estimator_->compute(cloud);
    auto msg = boost::make_shared<sensor_msgs::PointCloud2>();
    pcl::toROSMsg(with_normals, *msg);
    msg->header = image->header;
    cloud_pub_.publish(msg);
  }

  // The buffer must hold height rows of row_step bytes, each at least width pixels wide.
  template <typename T>
  bool checkBuffer(const sensor_msgs::Image& image) {
    const std::size_t min_step = static_cast<std::size_t>(image.width) * sizeof(T);
    if (image.step < min_step ||
        image.data.size() < static_cast<std::size_t>(image.step) * image.height) {
      NODELET_ERROR_THROTTLE(5.0,
                             "normal_estimation: malformed %s image (%u x %u, step %u, %zu bytes); "
                             "dropping frame",
                             image.encoding.c_str(), image.width, image.height, image.step,
                             image.data.size());
      return false;
    }
    if (image.is_bigendian) {
      NODELET_ERROR_THROTTLE(5.0,
                             "normal_estimation: big-endian depth images are not supported; "
                             "dropping frame");
      return false;
    }
    return true;
  }

  template <typename T>
  static DepthImageView<T> view(const sensor_msgs::Image& image, double metres_per_unit) {
    DepthImageView<T> v;
    v.data = image.data.data();
    v.width = static_cast<int>(image.width);
    v.height = static_cast<int>(image.height);
    v.row_step_bytes = image.step;
    v.metres_per_unit = metres_per_unit;
    return v;
  }

  BackProjectionParams back_projection_;
  std::unique_ptr<NormalEstimator> estimator_;
  std::mutex intrinsics_mutex_;
  CameraIntrinsics intrinsics_;
  bool have_intrinsics_ = false;
  ros::Subscriber depth_sub_, info_sub_;
  ros::Publisher cloud_pub_;
};

}  // namespace quadric_slam

PLUGINLIB_EXPORT_CLASS(quadric_slam::NormalEstimationNodelet, nodelet::Nodelet)
