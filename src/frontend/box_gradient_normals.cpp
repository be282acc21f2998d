#include "quadric_slam/frontend/box_gradient_normals.h"

#include "quadric_slam/frontend/parallel_chunks.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace quadric_slam {
namespace {

bool hasData(const pcl::PointXYZ& p) {
  const float limit = static_cast<float>(kBoxGradientMaxCoordinate);
  // Written so that NaN fails every comparison and counts as no data.
  return std::abs(p.x) <= limit && std::abs(p.y) <= limit && p.z > 0.f && p.z <= limit;
}

// The depth of a point with data, NaN otherwise (NaN fails every comparison below).
float depthIfData(const pcl::PointXYZ& p) {
  return hasData(p) ? p.z : std::numeric_limits<float>::quiet_NaN();
}

// Marks edge pixels (1): without data, or whose right or lower neighbour jumps in depth by more
// than factor * depth. Returns the largest absolute coordinate of the points with data.
float markEdges(const pcl::PointCloud<pcl::PointXYZ>& cloud, float factor, int threads,
                std::vector<std::uint8_t>& edge) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  edge.resize(cloud.size());
  std::vector<float> bounds(static_cast<std::size_t>(std::max(1, threads)), 0.f);
  forEachChunk(height, threads, [&](int chunk, int v_begin, int v_end) {
    // Depths (NaN = no data) of the current row and the one below, each computed once.
    std::vector<float> depth(width), depth_below(width);
    const auto fill = [&](int v, std::vector<float>& out) {
      const pcl::PointXYZ* row = &cloud.points[static_cast<std::size_t>(v) * width];
      for (int u = 0; u < width; ++u)
        out[u] = depthIfData(row[u]);
    };
    fill(v_begin, depth);
    float bound = 0.f;
    for (int v = v_begin; v < v_end; ++v) {
      if (v + 1 < height)
        fill(v + 1, depth_below);
      else
        std::fill(depth_below.begin(), depth_below.end(), std::numeric_limits<float>::quiet_NaN());
      const pcl::PointXYZ* row = &cloud.points[static_cast<std::size_t>(v) * width];
      std::uint8_t* edge_row = &edge[static_cast<std::size_t>(v) * width];
      for (int u = 0; u < width; ++u) {
        const float z = depth[u];
        if (!(z > 0.f)) {
          edge_row[u] = 1;
          continue;
        }
        bound = std::max({bound, std::abs(row[u].x), std::abs(row[u].y), z});
        const float limit = factor * z;
        const bool jump_right = u + 1 < width && std::abs(depth[u + 1] - z) > limit;
        edge_row[u] = jump_right || std::abs(depth_below[u] - z) > limit ? 1 : 0;
      }
      depth.swap(depth_below);
    }
    bounds[static_cast<std::size_t>(chunk)] = bound;
  });
  return *std::max_element(bounds.begin(), bounds.end());
}

// One cell of a summed-area table: sums of the quantised x, y, z and of the edge flags over the
// pixels above and left of it. Unsigned so that overflow wraps (defined behaviour): differences of
// wrapped sums are exact whenever the true box sum fits in 32 bits.
struct Cell {
  std::uint32_t x, y, z, edges;
};

// The sum of a box of pixels [u0, u1] from the table rows above (top = row v0) and below
// (bottom = row v1 + 1) it.
struct BoxSum {
  std::int64_t x, y, z;
};

inline std::uint32_t edgesIn(const Cell* top, const Cell* bottom, int u0, int u1) {
  return bottom[u1 + 1].edges - bottom[u0].edges - top[u1 + 1].edges + top[u0].edges;
}

inline BoxSum sumIn(const Cell* top, const Cell* bottom, int u0, int u1) {
  const auto wrapped = [&](std::uint32_t Cell::*field) {
    return static_cast<std::int64_t>(static_cast<std::int32_t>(
        bottom[u1 + 1].*field - bottom[u0].*field - top[u1 + 1].*field + top[u0].*field));
  };
  return {wrapped(&Cell::x), wrapped(&Cell::y), wrapped(&Cell::z)};
}

// The summed-area table rows of one band of the image, kept in a ring: row i (the sums over image
// rows < i, relative to the band's first row) lives in slot i mod ring size, so the rows a sweep
// down the image needs stay in cache.
class SummedAreaRing {
 public:
  SummedAreaRing(const pcl::PointCloud<pcl::PointXYZ>& cloud, const std::vector<std::uint8_t>& edge,
                 double scale, int rows_needed, int first_row)
      : cloud_(cloud),
        edge_(edge),
        scale_(static_cast<float>(scale)),
        width_(static_cast<int>(cloud.width)),
        mask_(ringSize(rows_needed) - 1),
        cells_(static_cast<std::size_t>(ringSize(rows_needed)) * (width_ + 1)),
        built_(first_row) {
    std::fill_n(mutableRow(first_row), width_ + 1, Cell{0, 0, 0, 0});
  }

  const Cell* row(int i) const {
    return &cells_[static_cast<std::size_t>(i & mask_) * (width_ + 1)];
  }

  // Builds the rows up to `last` (at most the image height).
  void buildUpTo(int last) {
    last = std::min(last, static_cast<int>(cloud_.height));
    for (; built_ < last; ++built_) {
      const Cell* above = row(built_);
      Cell* here = mutableRow(built_ + 1);
      const pcl::PointXYZ* points = &cloud_.points[static_cast<std::size_t>(built_) * width_];
      const std::uint8_t* edges = &edge_[static_cast<std::size_t>(built_) * width_];
      Cell running{0, 0, 0, 0};
      here[0] = running;
      for (int u = 0; u < width_; ++u) {
        if (edges[u] == 0) {
          running.x += quantised(points[u].x);
          running.y += quantised(points[u].y);
          running.z += quantised(points[u].z);
        } else {
          // An edge pixel adds only its flag: a box holding one is never summed.
          running.edges += 1;
        }
        here[u + 1] = {above[u + 1].x + running.x, above[u + 1].y + running.y,
                       above[u + 1].z + running.z, above[u + 1].edges + running.edges};
      }
    }
  }

 private:
  static int ringSize(int rows_needed) {
    int size = 1;
    while (size < rows_needed)
      size *= 2;
    return size;
  }
  // Rounded to the nearest step (half away from zero), as one truncating conversion: std::lrint is
  // a library call here and would dominate the table build.
  std::uint32_t quantised(float value) const {
    const float scaled = value * scale_;
    return static_cast<std::uint32_t>(
        static_cast<std::int32_t>(scaled + (scaled >= 0.f ? 0.5f : -0.5f)));
  }
  Cell* mutableRow(int i) { return &cells_[static_cast<std::size_t>(i & mask_) * (width_ + 1)]; }

  const pcl::PointCloud<pcl::PointXYZ>& cloud_;
  const std::vector<std::uint8_t>& edge_;
  float scale_;
  int width_;
  int mask_;
  std::vector<Cell> cells_;
  int built_;  // the last table row built
};

}  // namespace

void shapeNormalsOutput(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                        pcl::PointCloud<pcl::PointNormal>& out) {
  if (out.width != cloud.width || out.height != cloud.height || out.size() != cloud.size())
    out = pcl::PointCloud<pcl::PointNormal>(cloud.width, cloud.height);
  out.header = cloud.header;
  out.is_dense = false;
}

void computeBoxGradientNormals(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                               const BoxGradientSettings& settings,
                               pcl::PointCloud<pcl::PointNormal>& out) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  shapeNormalsOutput(cloud, out);
  if (cloud.empty())
    return;

  const int max_half = std::max(1, settings.max_half_window);
  const auto factor = static_cast<float>(settings.max_depth_change_factor);
  std::vector<std::uint8_t> edge;
  const float bound = std::max(markEdges(cloud, factor, settings.threads, edge), 1e-3f);
  // The largest box summed is the edge test's (2r+1) x (2h+1) with r = max_half, h = r / 2; its
  // sum of quantised coordinates must stay below 2^31 (10% margin for rounding).
  const double largest_box = (2.0 * max_half + 1.0) * (2.0 * (max_half / 2) + 1.0);
  const double scale = 0.9 * std::numeric_limits<std::int32_t>::max() / (largest_box * bound);

  const int stride = std::max(1, settings.stride);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int block_rows = (height + stride - 1) / stride;
  forEachChunk(block_rows, settings.threads, [&](int, int block_begin, int block_end) {
    const int v_begin = block_begin * stride;
    const int v_end = std::min(height, block_end * stride);
    // The table rows from v - max_half to v + max_half + 1 are in use while row v is estimated.
    SummedAreaRing sums(cloud, edge, scale, 2 * max_half + 2, std::max(0, v_begin - max_half));
    for (int v = v_begin; v < v_end; v += stride) {
      sums.buildUpTo(v + max_half + 1);
      for (int u = 0; u < width; u += stride) {
        const pcl::PointXYZ& p = cloud(u, v);
        Eigen::Vector3f n(nan, nan, nan);
        if (edge[static_cast<std::size_t>(v) * width + u] == 0) {
          double half = max_half;
          if (settings.depth_dependent_smoothing)
            half *= std::clamp(p.z / 2.0, 0.25, 1.0);
          // Boxes squeezed by the image border or an edge to a few pixels give noisy normals (a
          // few pixels' noise with a long lever arm): require a third of the full window.
          const int r_min = std::max(2, static_cast<int>(half) / 3);
          int r = std::min({static_cast<int>(half), u, width - 1 - u, v, height - 1 - v});
          // The window of radius r: a horizontal band [u-r, u+r] x [v-h, v+h] and a vertical one
          // [u-h, u+h] x [v-r, v+r], h = r / 2; free when neither holds an edge pixel.
          const auto window_free = [&](int radius) {
            const int h = std::max(1, radius / 2);
            return edgesIn(sums.row(v - h), sums.row(v + h + 1), u - radius, u + radius) == 0 &&
                   edgesIn(sums.row(v - radius), sums.row(v + radius + 1), u - h, u + h) == 0;
          };
          bool usable = r >= r_min;
          if (usable && !window_free(r)) {
            // Largest free radius in [r_min, r): windows are nested, so bisect.
            usable = window_free(r_min);
            int free = r_min, blocked = r;
            while (usable && blocked - free > 1) {
              const int mid = (free + blocked) / 2;
              (window_free(mid) ? free : blocked) = mid;
            }
            r = free;
          }
          if (usable) {
            const int h = std::max(1, r / 2);
            const Cell* band_top = sums.row(v - h);
            const Cell* band_bottom = sums.row(v + h + 1);
            const BoxSum left = sumIn(band_top, band_bottom, u - r, u - 1);
            const BoxSum right = sumIn(band_top, band_bottom, u + 1, u + r);
            const BoxSum up = sumIn(sums.row(v - r), sums.row(v), u - h, u + h);
            const BoxSum down = sumIn(sums.row(v + 1), sums.row(v + r + 1), u - h, u + h);
            // The opposite boxes have equal pixel counts and every pixel holds data, so the
            // differences of their sums are the central differences up to one positive factor.
            const Eigen::Vector3d along_u(static_cast<double>(right.x - left.x),
                                          static_cast<double>(right.y - left.y),
                                          static_cast<double>(right.z - left.z));
            const Eigen::Vector3d along_v(static_cast<double>(down.x - up.x),
                                          static_cast<double>(down.y - up.y),
                                          static_cast<double>(down.z - up.z));
            const Eigen::Vector3d normal = along_u.cross(along_v);
            const double norm = normal.norm();
            if (norm > 0.0)
              n = (normal / norm).cast<float>();
          }
        }
        // Share the normal with the block's pixels that hold data, are not on an edge and lie
        // within the edge threshold of the estimated point; write every field of each point once.
        for (int bv = v; bv < std::min(height, v + stride); ++bv) {
          for (int bu = u; bu < std::min(width, u + stride); ++bu) {
            const std::size_t index = static_cast<std::size_t>(bv) * width + bu;
            const pcl::PointXYZ& q = cloud.points[index];
            pcl::PointNormal& o = out.points[index];
            o.x = q.x;
            o.y = q.y;
            o.z = q.z;
            o.data[3] = 1.f;
            o.curvature = nan;
            const bool shares =
                std::isfinite(n.x()) && edge[index] == 0 && std::abs(q.z - p.z) <= factor * p.z;
            if (!shares) {
              o.normal_x = o.normal_y = o.normal_z = nan;
              continue;
            }
            // Face the sensor at the origin.
            const float sign = n.x() * q.x + n.y() * q.y + n.z() * q.z > 0.f ? -1.f : 1.f;
            o.normal_x = sign * n.x();
            o.normal_y = sign * n.y();
            o.normal_z = sign * n.z();
          }
        }
      }
    }
  });
}

}  // namespace quadric_slam
