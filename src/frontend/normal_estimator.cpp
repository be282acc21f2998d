#include "quadric_slam/frontend/normal_estimator.h"

#include <pcl/features/integral_image_normal.h>

#include "quadric_slam/frontend/box_gradient_normals.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace quadric_slam {
namespace {

using Estimator = pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal>;

constexpr const char* kOwnMethod = "box_gradient";

Estimator::NormalEstimationMethod methodFromName(const std::string& name) {
  if (name == "average_3d_gradient")
    return Estimator::AVERAGE_3D_GRADIENT;
  if (name == "covariance_matrix")
    return Estimator::COVARIANCE_MATRIX;
  if (name == "average_depth_change")
    return Estimator::AVERAGE_DEPTH_CHANGE;
  if (name == "simple_3d_gradient")
    return Estimator::SIMPLE_3D_GRADIENT;
  throw std::invalid_argument(
      "method must be one of box_gradient, average_3d_gradient, covariance_matrix, "
      "average_depth_change, simple_3d_gradient; got '" +
      name + "'");
}

}  // namespace

void NormalEstimator::Params::validate() const {
  if (method != kOwnMethod)
    methodFromName(method);
  if (!(max_depth_change_factor > 0.0 && max_depth_change_factor <= 1.0)) {
    throw std::invalid_argument("max_depth_change_factor must be in (0, 1], got " +
                                std::to_string(max_depth_change_factor));
  }
  if (!(normal_smoothing_size >= 1.0 && normal_smoothing_size <= 100.0)) {
    throw std::invalid_argument("normal_smoothing_size must be in [1, 100] pixels, got " +
                                std::to_string(normal_smoothing_size));
  }
  if (normal_stride < 1 || normal_stride > 4) {
    throw std::invalid_argument("normal_stride must be in [1, 4], got " +
                                std::to_string(normal_stride));
  }
  if (threads < 1 || threads > 64) {
    throw std::invalid_argument("threads must be in [1, 64], got " + std::to_string(threads));
  }
}

NormalEstimator::NormalEstimator(const Params& params) : params_(params) {
  params_.validate();
}

pcl::PointCloud<pcl::PointNormal> NormalEstimator::compute(
    const pcl::PointCloud<pcl::PointXYZ>& cloud) const {
  pcl::PointCloud<pcl::PointNormal> out;
  compute(cloud, out);
  return out;
}

void NormalEstimator::compute(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                              pcl::PointCloud<pcl::PointNormal>& out) const {
  if (!cloud.isOrganized()) {
    throw std::invalid_argument("NormalEstimator::compute needs an organized cloud");
  }
  if (params_.method == kOwnMethod) {
    BoxGradientSettings settings;
    settings.max_half_window = static_cast<int>(params_.normal_smoothing_size);
    settings.max_depth_change_factor = params_.max_depth_change_factor;
    settings.depth_dependent_smoothing = params_.depth_dependent_smoothing;
    settings.threads = params_.threads;
    settings.stride = params_.normal_stride;
    computeBoxGradientNormals(cloud, settings, out);
    return;
  }
  shapeNormalsOutput(cloud, out);
  if (cloud.empty())
    return;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out[i].x = cloud[i].x;
    out[i].y = cloud[i].y;
    out[i].z = cloud[i].z;
  }

  pcl::PointCloud<pcl::Normal> normals;
  // PCL's estimator leaves a border of normal_smoothing_size pixels on every side and reads out of
  // bounds when the two borders overlap (its loops run to height - border, unsigned): smaller
  // clouds keep NaN normals.
  const auto border = static_cast<std::uint32_t>(params_.normal_smoothing_size);
  if (cloud.width > 2 && cloud.height > 2 && cloud.width > 2 * border &&
      cloud.height > 2 * border) {
    Estimator estimator;
    estimator.setNormalEstimationMethod(methodFromName(params_.method));
    estimator.setMaxDepthChangeFactor(static_cast<float>(params_.max_depth_change_factor));
    estimator.setNormalSmoothingSize(static_cast<float>(params_.normal_smoothing_size));
    estimator.setDepthDependentSmoothing(params_.depth_dependent_smoothing);
    estimator.setViewPoint(0.f, 0.f, 0.f);
    // The estimator keeps a shared pointer; wrap without copying (the cloud outlives the call).
    estimator.setInputCloud(pcl::PointCloud<pcl::PointXYZ>::ConstPtr(
        &cloud, [](const pcl::PointCloud<pcl::PointXYZ>*) {}));
    estimator.compute(normals);
  }

  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    pcl::PointNormal& p = out[i];
    const bool has_normal = normals.size() == cloud.size() && std::isfinite(cloud[i].z) &&
                            std::isfinite(normals[i].normal_x);
    if (has_normal) {
      p.normal_x = normals[i].normal_x;
      p.normal_y = normals[i].normal_y;
      p.normal_z = normals[i].normal_z;
      p.curvature = normals[i].curvature;
    } else {
      p.normal_x = p.normal_y = p.normal_z = p.curvature = nan;
    }
  }
}

}  // namespace quadric_slam
