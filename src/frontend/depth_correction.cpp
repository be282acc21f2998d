#include "quadric_slam/frontend/depth_correction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace quadric_slam {
namespace {

// z = f b / (f b / z' + D): the measured depth z' moved by the disparity offset D. A corrected
// disparity at or below zero is beyond infinity: no depth (NaN).
double depthFromCorrectedDisparity(double focal_baseline, double offset, double z_measured) {
  const double disparity = focal_baseline / z_measured + offset;
  return disparity > 0.0 ? focal_baseline / disparity : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

GridWeights gridWeights(double u, double v, int width, int height, int cols, int rows) {
  const double x = std::clamp(u, 0.0, width - 1.0) * (cols - 1) / (width - 1.0);
  const double y = std::clamp(v, 0.0, height - 1.0) * (rows - 1) / (height - 1.0);
  const int i = std::min(static_cast<int>(x), cols - 2),
            j = std::min(static_cast<int>(y), rows - 2);
  const double fx = x - i, fy = y - j;
  GridWeights g;
  g.nodes[0] = j * cols + i;
  g.nodes[1] = j * cols + i + 1;
  g.nodes[2] = (j + 1) * cols + i;
  g.nodes[3] = (j + 1) * cols + i + 1;
  g.weights[0] = (1 - fx) * (1 - fy);
  g.weights[1] = fx * (1 - fy);
  g.weights[2] = (1 - fx) * fy;
  g.weights[3] = fx * fy;
  return g;
}

DepthCorrection::DepthCorrection(int width, int height, int cols, int rows,
                                 std::vector<double> offsets, double focal_baseline)
    : width_(width),
      height_(height),
      cols_(cols),
      rows_(rows),
      offsets_(std::move(offsets)),
      focal_baseline_(focal_baseline) {
  if (width < 2 || height < 2)
    throw std::invalid_argument("DepthCorrection: image size must be at least 2 x 2 pixels");
  if (cols < 2 || rows < 2 || cols > width || rows > height)
    throw std::invalid_argument("DepthCorrection: grid must have 2..width x 2..height nodes");
  if (offsets_.size() != static_cast<std::size_t>(cols) * rows)
    throw std::invalid_argument("DepthCorrection: " + std::to_string(offsets_.size()) +
                                " offsets for a grid of " + std::to_string(cols * rows) + " nodes");
  for (double d : offsets_)
    if (!std::isfinite(d) || std::abs(d) > 10.0)
      throw std::invalid_argument("DepthCorrection: offsets must be finite, within 10 px");
  if (!(focal_baseline > 0.0) || !std::isfinite(focal_baseline))
    throw std::invalid_argument("DepthCorrection: focal_baseline must be > 0 (px m)");
  pixel_offsets_.resize(static_cast<std::size_t>(width) * height);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u)
      pixel_offsets_[static_cast<std::size_t>(v) * width + u] = static_cast<float>(offsetAt(u, v));
}

double DepthCorrection::offsetAt(double u, double v) const {
  if (empty())
    return 0.0;
  const GridWeights g = gridWeights(u, v, width_, height_, cols_, rows_);
  double d = 0.0;
  for (int k = 0; k < 4; ++k)
    d += g.weights[k] * offsets_[g.nodes[k]];
  return d;
}

double DepthCorrection::correctedDepth(double u, double v, double z_measured) const {
  if (empty() || !std::isfinite(z_measured) || z_measured <= 0.0)
    return z_measured;
  return depthFromCorrectedDisparity(focal_baseline_, offsetAt(u, v), z_measured);
}

void DepthCorrection::apply(pcl::PointCloud<pcl::PointXYZ>* cloud, int decimation) const {
  if (empty())
    return;
  const int step = std::max(1, decimation);
  if (static_cast<int>(cloud->width) != width_ / step ||
      static_cast<int>(cloud->height) != height_ / step)
    throw std::invalid_argument("DepthCorrection::apply: a " + std::to_string(cloud->width) +
                                " x " + std::to_string(cloud->height) + " cloud (decimation " +
                                std::to_string(step) + ") is not of the correction's " +
                                std::to_string(width_) + " x " + std::to_string(height_) +
                                " image");
  for (int row = 0; row < static_cast<int>(cloud->height); ++row) {
    for (int col = 0; col < static_cast<int>(cloud->width); ++col) {
      pcl::PointXYZ& p = (*cloud)(col, row);
      if (!std::isfinite(p.z) || p.z <= 0.0f)
        continue;
      const double offset =
          pixel_offsets_[static_cast<std::size_t>(row * step) * width_ + col * step];
      const double z = depthFromCorrectedDisparity(focal_baseline_, offset, p.z);
      if (!std::isfinite(z)) {
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const float scale = static_cast<float>(z / p.z);
      p.x *= scale;
      p.y *= scale;
      p.z *= scale;
    }
  }
}

}  // namespace quadric_slam
