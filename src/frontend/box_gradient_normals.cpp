#include "quadric_slam/frontend/box_gradient_normals.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

namespace quadric_slam {
namespace {

// Runs fn(begin, end) over [0, count) split into `threads` contiguous chunks, one thread each.
template <typename Fn>
void forEachChunk(int count, int threads, Fn fn) {
  threads = std::max(1, std::min(threads, count));
  if (threads == 1) {
    fn(0, count);
    return;
  }
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t) {
    workers.emplace_back(fn, count * t / threads, count * (t + 1) / threads);
  }
  fn(0, count / threads);
  for (auto& worker : workers)
    worker.join();
}

// Summed-area table of (x, y, z, valid count) over an organized cloud, (W+1) x (H+1), interleaved
// so that each box corner is one cache line, in double: float sums over a whole frame lose the
// millimetres the differences need.
struct IntegralImages {
  struct Cell {
    double x, y, z, n;
  };
  int stride = 0;
  std::vector<Cell> cells;

  // Built in two passes that each split over threads: prefix sums along every row, then
  // accumulation down the columns.
  IntegralImages(const pcl::PointCloud<pcl::PointXYZ>& cloud, int threads)
      : stride(static_cast<int>(cloud.width) + 1),
        cells(static_cast<std::size_t>(stride) * (cloud.height + 1), Cell{0, 0, 0, 0}) {
    const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
    forEachChunk(height, threads, [&](int v_begin, int v_end) {
      for (int v = v_begin; v < v_end; ++v) {
        Cell sum{0, 0, 0, 0};
        Cell* here = &cells[static_cast<std::size_t>(v + 1) * stride + 1];
        const pcl::PointXYZ* point = &cloud.points[static_cast<std::size_t>(v) * width];
        for (int u = 0; u < width; ++u) {
          if (std::isfinite(point[u].z)) {
            sum.x += point[u].x;
            sum.y += point[u].y;
            sum.z += point[u].z;
            sum.n += 1.0;
          }
          here[u] = sum;
        }
      }
    });
    forEachChunk(width, threads, [&](int u_begin, int u_end) {
      for (int v = 1; v < height; ++v) {
        const Cell* above = &cells[static_cast<std::size_t>(v) * stride + 1];
        Cell* here = &cells[static_cast<std::size_t>(v + 1) * stride + 1];
        for (int u = u_begin; u < u_end; ++u) {
          here[u].x += above[u].x;
          here[u].y += above[u].y;
          here[u].z += above[u].z;
          here[u].n += above[u].n;
        }
      }
    });
  }

  // Mean point over the inclusive pixel box [u0, u1] x [v0, v1]; false when less than min_fraction
  // of its pixels hold data.
  bool mean(int u0, int v0, int u1, int v1, double min_fraction, Eigen::Vector3d& out) const {
    const Cell& a = cells[static_cast<std::size_t>(v0) * stride + u0];
    const Cell& b = cells[static_cast<std::size_t>(v0) * stride + u1 + 1];
    const Cell& c = cells[static_cast<std::size_t>(v1 + 1) * stride + u0];
    const Cell& d = cells[static_cast<std::size_t>(v1 + 1) * stride + u1 + 1];
    const double count = d.n - b.n - c.n + a.n;
    if (count < min_fraction * (u1 - u0 + 1) * (v1 - v0 + 1) || count < 1.0)
      return false;
    const double inverse_count = 1.0 / count;  // one division, not three
    out = Eigen::Vector3d(d.x - b.x - c.x + a.x, d.y - b.y - c.y + a.y, d.z - b.z - c.z + a.z) *
          inverse_count;
    return true;
  }
};

// Distance (pixels, L1) of every pixel to the nearest edge: a pixel without data or whose right or
// lower neighbour jumps in depth by more than factor * depth.
cv::Mat distanceToEdges(const pcl::PointCloud<pcl::PointXYZ>& cloud, double factor, int threads) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  cv::Mat not_edge(height, width, CV_8UC1, cv::Scalar(255));
  forEachChunk(height, threads, [&](int v_begin, int v_end) {
    for (int v = v_begin; v < v_end; ++v) {
      auto* row = not_edge.ptr<std::uint8_t>(v);
      for (int u = 0; u < width; ++u) {
        const float z = cloud(u, v).z;
        if (!std::isfinite(z)) {
          row[u] = 0;
          continue;
        }
        const float limit = static_cast<float>(factor) * z;
        if (u + 1 < width) {
          const float right = cloud(u + 1, v).z;
          if (std::isfinite(right) && std::abs(right - z) > limit)
            row[u] = 0;
        }
        if (v + 1 < height) {
          const float below = cloud(u, v + 1).z;
          if (std::isfinite(below) && std::abs(below - z) > limit)
            row[u] = 0;
        }
      }
    }
  });
  cv::Mat distance;
  cv::distanceTransform(not_edge, distance, cv::DIST_L1, 3, CV_32F);
  return distance;
}

}  // namespace

void computeBoxGradientNormals(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                               const BoxGradientSettings& settings,
                               pcl::PointCloud<pcl::PointNormal>& out) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (auto& p : out)
    p.normal_x = p.normal_y = p.normal_z = p.curvature = nan;
  if (width < 3 || height < 3)
    return;

  const IntegralImages sums(cloud, settings.threads);
  const cv::Mat distance =
      distanceToEdges(cloud, settings.max_depth_change_factor, settings.threads);
  // Each half of the box must be at least half full for its mean to be trusted.
  constexpr double kMinFraction = 0.5;

  // A normal is estimated at every stride-th pixel in u and v and given to the valid pixels of its
  // stride x stride block that are not on an edge and do not differ from it in depth by more than
  // the edge threshold: the smoothing window (10 px) is much wider than a block, so neighbouring
  // normals differ little, and the work drops by stride^2.
  const int stride = std::max(1, settings.stride);
  const auto factor = static_cast<float>(settings.max_depth_change_factor);
  auto process_block_rows = [&](int block_begin, int block_end) {
    for (int v = block_begin * stride; v < std::min(height, block_end * stride); v += stride) {
      const float* dist_row = distance.ptr<float>(v);
      for (int u = 0; u < width; u += stride) {
        const pcl::PointXYZ& p = cloud(u, v);
        if (!std::isfinite(p.z))
          continue;
        double half = settings.max_half_window;
        if (settings.depth_dependent_smoothing)
          half *= std::clamp(p.z / 2.0, 0.25, 1.0);
        // Stay inside the image and away from edges: the box never straddles a discontinuity.
        const int r = std::min({static_cast<int>(half), static_cast<int>(dist_row[u]) - 1, u,
                                width - 1 - u, v, height - 1 - v});
        // Boxes squeezed by the image border or an edge to a few pixels give noisy normals (a
        // few pixels' noise with a long lever arm): require a third of the full window.
        if (r < std::max(2, static_cast<int>(half) / 3))
          continue;
        const int h = std::max(1, r / 2);
        Eigen::Vector3d left, right, up, down;
        if (!sums.mean(u - r, v - h, u - 1, v + h, kMinFraction, left) ||
            !sums.mean(u + 1, v - h, u + r, v + h, kMinFraction, right) ||
            !sums.mean(u - h, v - r, u + h, v - 1, kMinFraction, up) ||
            !sums.mean(u - h, v + 1, u + h, v + r, kMinFraction, down)) {
          continue;
        }
        Eigen::Vector3d normal = (right - left).cross(down - up);
        const double norm = normal.norm();
        if (!(norm > 0.0))
          continue;
        const Eigen::Vector3f n = (normal / norm).cast<float>();
        for (int bv = v; bv < std::min(height, v + stride); ++bv) {
          const float* block_dist = distance.ptr<float>(bv);
          for (int bu = u; bu < std::min(width, u + stride); ++bu) {
            pcl::PointNormal& q = out(bu, bv);
            if (!std::isfinite(q.z) || std::abs(q.z - p.z) > factor * p.z ||
                (block_dist[bu] < 1.0f && (bu != u || bv != v)))
              continue;
            // Face the sensor at the origin.
            const float sign = n.x() * q.x + n.y() * q.y + n.z() * q.z > 0.f ? -1.f : 1.f;
            q.normal_x = sign * n.x();
            q.normal_y = sign * n.y();
            q.normal_z = sign * n.z();
          }
        }
      }
    }
  };

  forEachChunk((height + stride - 1) / stride, settings.threads, process_block_rows);
}

}  // namespace quadric_slam
