#include "quadric_slam/io/depth_png.h"

#include <cmath>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace quadric_slam {

cv::Mat depthUnitsToMetres(const cv::Mat& raw, double units_per_metre) {
  if (raw.type() != CV_16UC1) {
    throw std::invalid_argument("depth must be CV_16UC1 (16-bit, one channel)");
  }
  if (!(units_per_metre > 0.0) || !std::isfinite(units_per_metre)) {
    throw std::invalid_argument("units_per_metre must be in (0, inf), got " +
                                std::to_string(units_per_metre));
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double metres_per_unit = 1.0 / units_per_metre;
  cv::Mat metres(raw.rows, raw.cols, CV_32FC1);
  for (int v = 0; v < raw.rows; ++v) {
    const auto* in = raw.ptr<std::uint16_t>(v);
    auto* out = metres.ptr<float>(v);
    for (int u = 0; u < raw.cols; ++u) {
      out[u] = in[u] == 0 ? nan : static_cast<float>(in[u] * metres_per_unit);
    }
  }
  return metres;
}

cv::Mat readTumDepthPng(const std::string& path, double units_per_metre) {
  const cv::Mat raw = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
  if (raw.empty())
    throw std::runtime_error(path + ": cannot read depth image");
  if (raw.type() != CV_16UC1) {
    throw std::runtime_error(path + ": depth PNG must be 16-bit single channel (TUM format)");
  }
  return depthUnitsToMetres(raw, units_per_metre);
}

cv::Mat readRgbPng(const std::string& path) {
  const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty())
    throw std::runtime_error(path + ": cannot read colour image");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

}  // namespace quadric_slam
