#include "quadric_slam/sim/kinect_depth_model.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace quadric_slam {
namespace {

void require(bool ok, const std::string& field, const std::string& range) {
  if (!ok)
    throw std::invalid_argument("KinectDepthModel::Params::" + field + " must be " + range);
}

}  // namespace

void KinectDepthModel::Params::validate() const {
  require(min_range > 0.0, "min_range", "> 0 m");
  require(max_range > min_range, "max_range", "> min_range");
  require(sigma_constant >= 0.0, "sigma_constant", ">= 0 m");
  require(sigma_quadratic >= 0.0, "sigma_quadratic", ">= 0 1/m");
  require(sigma_reference_depth >= 0.0, "sigma_reference_depth", ">= 0 m");
  require(focal_px > 0.0, "focal_px", "> 0 px");
  require(baseline > 0.0, "baseline", "> 0 m");
  require(disparity_resolution >= 0.0 && disparity_resolution <= 1.0, "disparity_resolution",
          "in [0, 1] px");
  require(max_incidence > 0.0 && max_incidence <= M_PI / 2, "max_incidence", "in (0, pi/2] rad");
  require(edge_dropout_px >= 0 && edge_dropout_px <= 10, "edge_dropout_px", "in [0, 10] px");
  require(edge_jump_ratio > 0.0, "edge_jump_ratio", "> 0");
  require(dropout_probability >= 0.0 && dropout_probability < 1.0, "dropout_probability",
          "in [0, 1)");
}

KinectDepthModel::KinectDepthModel(const Params& params) : params_(params) {
  params_.validate();
  cos_max_incidence_ = std::cos(params_.max_incidence);
}

double KinectDepthModel::sigma(double z) const {
  // Nguyen et al. 2012, axial noise: sigma_z = 0.0012 + 0.0019 (z - 0.4)^2.
  const double dz = z - params_.sigma_reference_depth;
  return params_.sigma_constant + params_.sigma_quadratic * dz * dz;
}

double KinectDepthModel::depthStep(double z) const {
  // d = f b / z  =>  |dz/dd| = z^2 / (f b); one disparity step of `resolution` pixels.
  return z * z * params_.disparity_resolution / (params_.focal_px * params_.baseline);
}

double KinectDepthModel::expectedStd(double z) const {
  const double s = sigma(z), q = depthStep(z);
  return std::sqrt(s * s + q * q / 12.0);
}

double KinectDepthModel::quantise(double z) const {
  if (params_.disparity_resolution <= 0.0 || !(z > 0.0))
    return z;
  const double fb = params_.focal_px * params_.baseline;
  const double steps = std::round(fb / z / params_.disparity_resolution);
  if (steps < 1.0)
    return fb / params_.disparity_resolution;
  return fb / (steps * params_.disparity_resolution);
}

float KinectDepthModel::measure(double z_true, double cos_incidence, SimRandom& random) const {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (!std::isfinite(z_true) || z_true < params_.min_range || z_true > params_.max_range)
    return nan;
  if (std::abs(cos_incidence) < cos_max_incidence_)
    return nan;
  if (params_.dropout_probability > 0.0 && random.uniform() < params_.dropout_probability)
    return nan;
  const double z = z_true + sigma(z_true) * random.normal();
  return static_cast<float>(quantise(z));
}

bool KinectDepthModel::nearEdge(const cv::Mat& depth_true, int u, int v) const {
  const int r = params_.edge_dropout_px;
  const float z = depth_true.at<float>(v, u);
  const float jump = static_cast<float>(params_.edge_jump_ratio) * z;
  const int v0 = std::max(0, v - r), v1 = std::min(depth_true.rows - 1, v + r);
  const int u0 = std::max(0, u - r), u1 = std::min(depth_true.cols - 1, u + r);
  for (int vv = v0; vv <= v1; ++vv) {
    const float* row = depth_true.ptr<float>(vv);
    for (int uu = u0; uu <= u1; ++uu) {
      if (row[uu] < z - jump)  // NaN (no surface) compares false: treated as far away
        return true;
    }
  }
  return false;
}

cv::Mat KinectDepthModel::apply(const cv::Mat& depth_true, const cv::Mat& cos_incidence,
                                std::uint64_t seed) const {
  if (depth_true.type() != CV_32FC1 || cos_incidence.type() != CV_32FC1 ||
      depth_true.size() != cos_incidence.size()) {
    throw std::invalid_argument("KinectDepthModel::apply: need two CV_32FC1 images of one size");
  }
  cv::Mat out(depth_true.size(), CV_32FC1);
  for (int v = 0; v < depth_true.rows; ++v) {
    SimRandom random(seed, 0x5eed, static_cast<std::uint64_t>(v));
    const float* z_row = depth_true.ptr<float>(v);
    const float* c_row = cos_incidence.ptr<float>(v);
    float* o_row = out.ptr<float>(v);
    for (int u = 0; u < depth_true.cols; ++u) {
      float z = measure(z_row[u], c_row[u], random);
      if (!std::isnan(z) && params_.edge_dropout_px > 0 && nearEdge(depth_true, u, v))
        z = std::numeric_limits<float>::quiet_NaN();
      o_row[u] = z;
    }
  }
  return out;
}

}  // namespace quadric_slam
