#include "quadric_slam/sim/depth_warp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace quadric_slam {

void DepthWarpParams::validate() const {
  if (!(depth_jump_fraction > 0.0 && depth_jump_fraction <= 1.0))
    throw std::invalid_argument("depth_jump_fraction must be in (0, 1], got " +
                                std::to_string(depth_jump_fraction));
  if (!(min_depth_jump > 0.0))
    throw std::invalid_argument("min_depth_jump must be > 0, got " +
                                std::to_string(min_depth_jump));
  if (!(min_depth > 0.0))
    throw std::invalid_argument("min_depth must be > 0, got " + std::to_string(min_depth));
}

namespace {

// A triangle vertex in the moved camera: pixel position and inverse depth.
struct Vertex {
  double x, y, inverse_depth;
};

// A triangle larger than this (pixels, either side of its bounding box) is a surface seen edge-on
// or very close: left as a hole rather than smeared over the image.
constexpr double kMaxTriangleExtent = 32.0;

// Rasterises one triangle into the z-buffer: pixel centres inside it (edges included; a pixel
// on an edge shared by two triangles gets the same depth from both) take the perspective-correct
// interpolated depth when nearer than what is there.
void rasterise(const std::array<Vertex, 3>& t, cv::Mat& depth) {
  const double min_x = std::min({t[0].x, t[1].x, t[2].x});
  const double max_x = std::max({t[0].x, t[1].x, t[2].x});
  const double min_y = std::min({t[0].y, t[1].y, t[2].y});
  const double max_y = std::max({t[0].y, t[1].y, t[2].y});
  if (max_x - min_x > kMaxTriangleExtent || max_y - min_y > kMaxTriangleExtent)
    return;
  if (max_x < -1.0 || max_y < -1.0 || min_x > depth.cols || min_y > depth.rows)
    return;  // outside the image
  // (A corner that lands on a pixel centre up to rounding still covers it.)
  constexpr double kSlack = 1e-6;
  const int u0 = std::max(0, static_cast<int>(std::ceil(min_x - kSlack)));
  const int u1 = std::min(depth.cols - 1, static_cast<int>(std::floor(max_x + kSlack)));
  const int v0 = std::max(0, static_cast<int>(std::ceil(min_y - kSlack)));
  const int v1 = std::min(depth.rows - 1, static_cast<int>(std::floor(max_y + kSlack)));
  if (u0 > u1 || v0 > v1)
    return;
  const double area =
      (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
  if (std::abs(area) < 1e-12)
    return;
  constexpr double kEdgeTolerance = 1e-7;
  for (int v = v0; v <= v1; ++v) {
    float* row = depth.ptr<float>(v);
    for (int u = u0; u <= u1; ++u) {
      const double l0 =
          ((t[1].x - u) * (t[2].y - v) - (t[2].x - u) * (t[1].y - v)) / area;
      const double l1 =
          ((t[2].x - u) * (t[0].y - v) - (t[0].x - u) * (t[2].y - v)) / area;
      const double l2 = 1.0 - l0 - l1;
      if (l0 < -kEdgeTolerance || l1 < -kEdgeTolerance || l2 < -kEdgeTolerance)
        continue;
      const double w = l0 * t[0].inverse_depth + l1 * t[1].inverse_depth + l2 * t[2].inverse_depth;
      if (!(w > 0.0))
        continue;
      const float z = static_cast<float>(1.0 / w);
      if (std::isnan(row[u]) || z < row[u])
        row[u] = z;
    }
  }
}

}  // namespace

cv::Mat warpDepthImage(const cv::Mat& depth_m, const CameraIntrinsics& k,
                       const Eigen::Isometry3d& T_reference_moved, const DepthWarpParams& params) {
  params.validate();
  if (depth_m.type() != CV_32FC1)
    throw std::invalid_argument("warpDepthImage: depth must be CV_32FC1 metres");
  const std::string size_problem = imageSizeProblem(k, depth_m.cols, depth_m.rows);
  if (!size_problem.empty())
    throw std::invalid_argument("warpDepthImage: " + size_problem);

  const int width = depth_m.cols, height = depth_m.rows;
  // Every valid pixel once: its point in the moved camera, projected (NaN inverse depth: none).
  cv::Mat projected(height, width, CV_64FC3);
  const Eigen::Isometry3d T_moved_reference = T_reference_moved.inverse();
  for (int v = 0; v < height; ++v) {
    const float* z_row = depth_m.ptr<float>(v);
    cv::Vec3d* out = projected.ptr<cv::Vec3d>(v);
    for (int u = 0; u < width; ++u) {
      const double z = z_row[u];
      out[u] = cv::Vec3d(0, 0, std::numeric_limits<double>::quiet_NaN());
      if (!(z > 0.0) || !std::isfinite(z))
        continue;
      const Eigen::Vector3d p_reference((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
      const Eigen::Vector3d p = T_moved_reference * p_reference;
      if (p.z() < params.min_depth)
        continue;
      out[u] = cv::Vec3d(k.fx * p.x() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy, 1.0 / p.z());
    }
  }

  cv::Mat warped(height, width, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  // One continuous surface: the depths (in the reference image) of a triangle's corners agree.
  auto continuous = [&](float a, float b, float c) {
    const float lo = std::min({a, b, c}), hi = std::max({a, b, c});
    return hi - lo <= std::max(params.min_depth_jump, params.depth_jump_fraction * lo);
  };
  auto vertex = [&](int u, int v, Vertex& out) {
    const cv::Vec3d& p = projected.at<cv::Vec3d>(v, u);
    if (std::isnan(p[2]))
      return false;
    out = {p[0], p[1], p[2]};
    return true;
  };
  for (int v = 0; v + 1 < height; ++v) {
    for (int u = 0; u + 1 < width; ++u) {
      // Corners a (u, v), b (u+1, v), c (u, v+1), d (u+1, v+1): triangles a b c and b d c.
      Vertex a, b, c, d;
      const bool has_a = vertex(u, v, a), has_b = vertex(u + 1, v, b);
      const bool has_c = vertex(u, v + 1, c), has_d = vertex(u + 1, v + 1, d);
      const float za = depth_m.at<float>(v, u), zb = depth_m.at<float>(v, u + 1);
      const float zc = depth_m.at<float>(v + 1, u), zd = depth_m.at<float>(v + 1, u + 1);
      if (has_a && has_b && has_c && continuous(za, zb, zc))
        rasterise({a, b, c}, warped);
      if (has_b && has_d && has_c && continuous(zb, zd, zc))
        rasterise({b, d, c}, warped);
    }
  }
  return warped;
}

}  // namespace quadric_slam
