#include "quadric_slam/sim/kinect_depth_model.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

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
  require(projector_side >= -1 && projector_side <= 1, "projector_side", "-1, 0 or 1");
  require(sigma_scale >= 0.0 && sigma_scale <= 10.0, "sigma_scale", "in [0, 10]");
  require(std::abs(distortion_r2) <= 2.0, "distortion_r2", "in [-2, 2] px");
  require(std::abs(distortion_r4) <= 2.0, "distortion_r4", "in [-2, 2] px");
  require(pattern_amplitude >= 0.0 && pattern_amplitude <= 1.0, "pattern_amplitude",
          "in [0, 1] px");
  require(pattern_wavelength_px > 0.0, "pattern_wavelength_px", "> 0 px");
  require(pattern_seed >= 0, "pattern_seed", ">= 0");
  require(correlated_fraction >= 0.0 && correlated_fraction <= 1.0, "correlated_fraction",
          "in [0, 1]");
  require(correlation_px > 0.0 && correlation_px <= 20.0, "correlation_px", "in (0, 20] px");
}

void KinectDepthModel::applyModel(const std::string& name, Params* params) {
  const Params harsh;
  if (name == "harsh") {
    params->sigma_scale = harsh.sigma_scale;
    params->distortion_r2 = harsh.distortion_r2;
    params->distortion_r4 = harsh.distortion_r4;
    params->pattern_amplitude = harsh.pattern_amplitude;
    params->pattern_wavelength_px = harsh.pattern_wavelength_px;
    params->pattern_seed = harsh.pattern_seed;
    params->correlated_fraction = harsh.correlated_fraction;
    params->correlation_px = harsh.correlation_px;
    params->projector_side = harsh.projector_side;
  } else if (name == "nguyen") {
    params->sigma_scale = 1.0;
    params->distortion_r2 = 0.0;
    params->distortion_r4 = 0.0;
    params->pattern_amplitude = 0.0;
    params->correlated_fraction = 0.0;
    params->projector_side = 0;
  } else {
    throw std::invalid_argument("unknown depth model '" + name + "' (harsh or nguyen)");
  }
}

KinectDepthModel::Params KinectDepthModel::nguyenParams() {
  Params p;
  applyModel("nguyen", &p);
  return p;
}

KinectDepthModel::Params KinectDepthModel::harshParams() {
  return Params();
}

KinectDepthModel::Params KinectDepthModel::paramsForModel(const std::string& name) {
  Params p;
  applyModel(name, &p);
  return p;
}

KinectDepthModel::KinectDepthModel(const Params& params) : params_(params) {
  params_.validate();
  cos_max_incidence_ = std::cos(params_.max_incidence);
}

double KinectDepthModel::sigma(double z) const {
  // Nguyen et al. 2012, axial noise: sigma_z = 0.0012 + 0.0019 (z - 0.4)^2.
  const double dz = z - params_.sigma_reference_depth;
  return params_.sigma_scale * (params_.sigma_constant + params_.sigma_quadratic * dz * dz);
}

double KinectDepthModel::distortion(double z, double r) const {
  // A fixed disparity pattern D(r) (px) seen as depth: z' = f b / (f b / z - D) ~ z + z^2 D / (f
  // b).
  const double r2 = r * r;
  const double d = params_.distortion_r2 * r2 + params_.distortion_r4 * r2 * r2;
  return z * z * d / (params_.focal_px * params_.baseline);
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
  return measure(z_true, cos_incidence, 0.0, random.normal(), random);
}

float KinectDepthModel::measure(double z_true, double cos_incidence, double r, double unit_noise,
                                SimRandom& random) const {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (!std::isfinite(z_true) || z_true < params_.min_range || z_true > params_.max_range)
    return nan;
  if (std::abs(cos_incidence) < cos_max_incidence_)
    return nan;
  if (params_.dropout_probability > 0.0 && random.uniform() < params_.dropout_probability)
    return nan;
  const double z = z_true + distortion(z_true, r) + sigma(z_true) * unit_noise;
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
  const cv::Mat noise = unitNoise(depth_true.size(), seed);
  const cv::Mat pattern = disparityPattern(depth_true.size());
  const double inv_fb = 1.0 / (params_.focal_px * params_.baseline);
  const double cu = 0.5 * (depth_true.cols - 1), cv0 = 0.5 * (depth_true.rows - 1);
  const double inv_corner = 1.0 / std::hypot(cu, cv0);
  for (int v = 0; v < depth_true.rows; ++v) {
    SimRandom random(seed, 0x5eed, static_cast<std::uint64_t>(v));
    const float* z_row = depth_true.ptr<float>(v);
    const float* c_row = cos_incidence.ptr<float>(v);
    const float* n_row = noise.ptr<float>(v);
    const float* p_row = pattern.ptr<float>(v);
    float* o_row = out.ptr<float>(v);
    for (int u = 0; u < depth_true.cols; ++u) {
      const double r = std::hypot(u - cu, v - cv0) * inv_corner;
      // The fixed pattern, like the radial term, is a disparity offset: z^2 / (f b) in depth.
      const double zt = z_row[u] + z_row[u] * z_row[u] * inv_fb * p_row[u];
      float z = measure(zt, c_row[u], r, n_row[u], random);
      if (!std::isnan(z) && params_.edge_dropout_px > 0 && nearEdge(depth_true, u, v))
        z = std::numeric_limits<float>::quiet_NaN();
      o_row[u] = z;
    }
    if (params_.projector_side != 0)
      castProjectorShadow(z_row, o_row, depth_true.cols);
  }
  return out;
}

void KinectDepthModel::castProjectorShadow(const float* z_true, float* out, int width) const {
  // With the projector at x = s b, a surface point at column u and depth z is lit from projector
  // column p(u) = u - s f b / z. Scanning away from the projector (s = +1: right to left), a
  // point is in shadow when a point already passed (nearer the projector side) has a projector
  // column at or beyond its own: the ray from the projector is blocked.
  const double fb = params_.focal_px * params_.baseline;
  const int s = params_.projector_side;
  double extreme =
      s > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
  for (int k = 0; k < width; ++k) {
    const int u = s > 0 ? width - 1 - k : k;
    const double z = z_true[u];
    if (!(z > 0.0))
      continue;  // no surface: nothing casts or receives a shadow
    const double p = u - s * fb / z;
    if (s > 0 ? p >= extreme + 0.5 : p <= extreme - 0.5)
      out[u] = std::numeric_limits<float>::quiet_NaN();
    extreme = s > 0 ? std::min(extreme, p) : std::max(extreme, p);
  }
}

cv::Mat KinectDepthModel::disparityPattern(cv::Size size) const {
  cv::Mat pattern(size, CV_32FC1, cv::Scalar(0.0f));
  if (params_.pattern_amplitude <= 0.0)
    return pattern;
  constexpr int kWaves = 12;
  SimRandom random(static_cast<std::uint64_t>(params_.pattern_seed), 0xd157, 0);
  // Each wave sin(k . (u, v) + phase) has mean square 1/2, so the sum has about kWaves / 2.
  const double amplitude = params_.pattern_amplitude * std::sqrt(2.0 / kWaves);
  std::vector<double> ku(kWaves), kv(kWaves), phase(kWaves);
  for (int w = 0; w < kWaves; ++w) {
    const double angle = 2.0 * M_PI * random.uniform();
    const double wavelength = params_.pattern_wavelength_px * (1.0 + random.uniform());
    ku[w] = 2.0 * M_PI / wavelength * std::cos(angle);
    kv[w] = 2.0 * M_PI / wavelength * std::sin(angle);
    phase[w] = 2.0 * M_PI * random.uniform();
  }
  // Evaluated on a grid of kStep pixels and interpolated: the waves are much longer than kStep.
  constexpr int kStep = 8;
  cv::Mat coarse(size.height / kStep + 2, size.width / kStep + 2, CV_32FC1);
  for (int j = 0; j < coarse.rows; ++j) {
    for (int i = 0; i < coarse.cols; ++i) {
      double sum = 0.0;
      for (int w = 0; w < kWaves; ++w)
        sum += std::sin(ku[w] * i * kStep + kv[w] * j * kStep + phase[w]);
      coarse.at<float>(j, i) = static_cast<float>(amplitude * sum);
    }
  }
  for (int v = 0; v < size.height; ++v) {
    float* row = pattern.ptr<float>(v);
    const int j = v / kStep;
    const float b = static_cast<float>(v % kStep) / kStep;
    for (int u = 0; u < size.width; ++u) {
      const int i = u / kStep;
      const float a = static_cast<float>(u % kStep) / kStep;
      row[u] = (1 - b) * ((1 - a) * coarse.at<float>(j, i) + a * coarse.at<float>(j, i + 1)) +
               b * ((1 - a) * coarse.at<float>(j + 1, i) + a * coarse.at<float>(j + 1, i + 1));
    }
  }
  return pattern;
}

cv::Mat KinectDepthModel::unitNoise(cv::Size size, std::uint64_t seed) const {
  const double f = params_.correlated_fraction;
  cv::Mat white(size, CV_32FC1), coloured(size, CV_32FC1, cv::Scalar(0.0f));
  for (int v = 0; v < size.height; ++v) {
    SimRandom random(seed, 0x0b5e, static_cast<std::uint64_t>(v));
    float* w = white.ptr<float>(v);
    float* c = coloured.ptr<float>(v);
    for (int u = 0; u < size.width; ++u) {
      w[u] = static_cast<float>(random.normal());
      if (f > 0.0)
        c[u] = static_cast<float>(random.normal());
    }
  }
  if (f <= 0.0)
    return white;
  // Low-pass the second field; a Gaussian of sigma s scales white noise's variance by
  // sum(w_i w_j)^2 = (sum_i w_i^2)^2 over the separable kernel, undone here.
  const double s = params_.correlation_px;
  const int half = static_cast<int>(std::ceil(4.0 * s));
  const cv::Mat kernel = cv::getGaussianKernel(2 * half + 1, s, CV_32F);
  cv::sepFilter2D(coloured, coloured, CV_32F, kernel, kernel, cv::Point(-1, -1), 0.0,
                  cv::BORDER_REFLECT_101);
  const double k2 = kernel.dot(kernel);
  coloured *= 1.0 / k2;  // 1 / sqrt(k2^2): k2 per axis
  cv::Mat out;
  cv::addWeighted(white, std::sqrt(1.0 - f), coloured, std::sqrt(f), 0.0, out);
  return out;
}

}  // namespace quadric_slam
