#include "quadric_slam/frontend/multi_resolution_labels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "quadric_slam/frontend/parallel_chunks.h"
#include "quadric_slam/frontend/segmentation_frame.h"

namespace quadric_slam {

QuadricSegmenter::Params coarseParams(const QuadricSegmenter::Params& p, int d) {
  QuadricSegmenter::Params c = p;
  c.planes.min_points = std::max(3, p.planes.min_points / (d * d));
  c.planes.min_fragment_points = std::max(3, p.planes.min_fragment_points / (d * d));
  c.min_curved_points = std::max(4, p.min_curved_points / (d * d));
  c.planes.seed_stride = std::max(1, p.planes.seed_stride / d);
  c.planes.cell_size = p.planes.cell_size / d;
  c.planes.correlated_points = std::max(1.0, p.planes.correlated_points / (d * d));
  c.cgal_stride = std::max(1, (p.cgal_stride + d / 2) / d);
  c.decimation = 1;
  return c;
}

pcl::PointCloud<pcl::PointNormal> decimated(const pcl::PointCloud<pcl::PointNormal>& cloud, int d) {
  // Each point written once: sizing the cloud first would construct every point (a pass over the
  // grid's memory), and the copy is bound by reading the full cloud (a second thread measured no
  // faster).
  pcl::PointCloud<pcl::PointNormal> grid;
  const std::uint32_t width = cloud.width / d, height = cloud.height / d;
  grid.points.reserve(static_cast<std::size_t>(width) * height);
  for (std::uint32_t r = 0; r < height; ++r)
    for (std::uint32_t c = 0; c < width; ++c)
      grid.points.push_back(cloud(c * d, r * d));
  grid.width = width;
  grid.height = height;
  grid.is_dense = false;
  return grid;
}

namespace {

// Distance gate, in RMS of a detection's fit, within which a pixel inside a single surface's
// samples joins it without normal agreement (the 3-sigma band of the fit's own residuals).
constexpr double kNoiseGate = 3.0;

}  // namespace

Segmentation upsample(const pcl::PointCloud<pcl::PointNormal>& cloud, Segmentation coarse, int d,
                      const QuadricSegmenter::Params& p, const std::vector<std::uint8_t>& taken) {
  if (!taken.empty() && taken.size() != cloud.size())
    throw std::invalid_argument("upsample: taken must hold one flag per point of the cloud");
  Segmentation result;
  result.timings = coarse.timings;
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  result.labels = cv::Mat::zeros(height, width, CV_16UC1);
  const int n = static_cast<int>(coarse.detections.size());
  // What a pixel's test reads of each detection, in one place (read for every pixel).
  struct Target {
    const PrimitiveShape* shape;
    Eigen::Isometry3d T_quadric_camera;
    double cos_angle, noise_gate;
  };
  std::vector<Target> targets;
  targets.reserve(n);
  for (const QuadricDetection& detection : coarse.detections) {
    const bool plane = detection.shape.quadric_class == QuadricClass::kPlane;
    targets.push_back({&detection.shape, detection.shape.quadric().pose().inverse(),
                       std::cos(plane ? p.planes.max_normal_angle : p.curved_max_normal_angle),
                       std::max(1e-3, kNoiseGate * detection.fit_rms)});
  }
  // Per-chunk tallies of the labelled points (rows split over threads), merged afterwards.
  struct Tally {
    int count = 0;
    double sum_sq = 0.0;  // squared distances of the labelled points to their surface
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
    Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::max());
    int u_min = std::numeric_limits<int>::max(), v_min = std::numeric_limits<int>::max();
    int u_max = -1, v_max = -1;
  };
  // Rows are split over the threads by blocks of d rows: the d x d full-resolution pixels of a
  // block share their four neighbouring coarse samples, read once.
  const int block_rows = (height + d - 1) / d;
  const int threads = std::max(1, std::min(p.threads, block_rows));
  std::vector<std::vector<Tally>> tallies(threads);
  const int cw = coarse.labels.cols, ch = coarse.labels.rows;
  // Locals, so that the pixel loop keeps them in registers.
  const double min_range = p.min_range, max_range = p.max_range;
  const double distance_factor = p.planes.distance_factor, min_distance = p.planes.min_distance;
  forEachChunk(block_rows, threads, [&](int chunk, int block_row_begin, int block_row_end) {
    std::vector<Tally>& tally = tallies[chunk];
    tally.assign(n, Tally());
    // Labels pixel (u, v) with the best of the distinct candidate labels, if any fits.
    const auto labelPixel = [&](int u, int v, const std::uint16_t* labels, int distinct,
                                bool single_surface, std::uint16_t* label_row) {
      const std::size_t index = static_cast<std::size_t>(v) * width + u;
      if (!taken.empty() && taken[index])
        return;
      const pcl::PointNormal& q = cloud.points[index];
      if (!(q.z >= min_range && q.z <= max_range) || !std::isfinite(q.x) || !std::isfinite(q.y) ||
          !std::isfinite(q.normal_x) || !std::isfinite(q.normal_y) || !std::isfinite(q.normal_z))
        return;
      const Eigen::Vector3d point = pointOf(q);
      int best = 0;
      double best_distance = depthThreshold(q.z, distance_factor, min_distance);
      for (int c = 0; c < distinct; ++c) {
        const int label = labels[c];
        const Target& target = targets[label - 1];
        const double distance = std::abs(target.shape->distance(point));
        if (distance >= best_distance)
          continue;
        if ((!single_surface || distance > target.noise_gate) &&
            std::abs(target.shape->normalAt(point).dot(normalOf(q))) < target.cos_angle)
          continue;
        best = label;
        best_distance = distance;
      }
      if (best == 0)
        return;
      label_row[u] = static_cast<std::uint16_t>(best);
      Tally& t = tally[best - 1];
      ++t.count;
      t.sum_sq += best_distance * best_distance;
      const Eigen::Vector3d local = targets[best - 1].T_quadric_camera * point;
      t.lo = t.lo.cwiseMin(local);
      t.hi = t.hi.cwiseMax(local);
      t.u_min = std::min(t.u_min, u);
      t.v_min = std::min(t.v_min, v);
      t.u_max = std::max(t.u_max, u);
      t.v_max = std::max(t.v_max, v);
    };
    for (int j = block_row_begin; j < block_row_end; ++j) {
      const std::uint16_t* row0 = coarse.labels.ptr<std::uint16_t>(std::min(j, ch - 1));
      const std::uint16_t* row1 = coarse.labels.ptr<std::uint16_t>(std::min(j + 1, ch - 1));
      const int v_end = std::min(height, (j + 1) * d);
      for (int b = 0; b * d < width; ++b) {
        const int cu0 = std::min(b, cw - 1), cu1 = std::min(b + 1, cw - 1);
        const std::uint16_t candidates[4] = {row0[cu0], row0[cu1], row1[cu0], row1[cu1]};
        if ((candidates[0] | candidates[1] | candidates[2] | candidates[3]) == 0)
          continue;
        // Where the neighbouring samples name a single surface (the others unlabelled), a pixel
        // need not have an agreeing normal when it fits the surface as well as the surface's own
        // points do (within kNoiseGate x the fit's RMS): its normal is the noisiest evidence
        // there (at 3-4 m the normals of a flat wall scatter beyond the normal tolerance, which
        // left holes all over far surfaces). Other pixels, and all between two labelled
        // surfaces, need the normal to agree as well. Each surface is measured once per pixel.
        std::uint16_t labels[4];
        int distinct = 0;
        for (const std::uint16_t label : candidates)
          if (label != 0 && std::find(labels, labels + distinct, label) == labels + distinct)
            labels[distinct++] = label;
        const bool single_surface = distinct == 1;
        const int u_end = std::min(width, (b + 1) * d);
        for (int v = j * d; v < v_end; ++v) {
          std::uint16_t* label_row = result.labels.ptr<std::uint16_t>(v);
          for (int u = b * d; u < u_end; ++u)
            labelPixel(u, v, labels, distinct, single_surface, label_row);
        }
      }
    }
  });
  std::vector<int> count(n, 0);
  std::vector<double> sum_sq(n, 0.0);
  std::vector<Eigen::Vector3d> lo(n, Eigen::Vector3d::Constant(std::numeric_limits<double>::max()));
  std::vector<Eigen::Vector3d> hi(n,
                                  Eigen::Vector3d::Constant(-std::numeric_limits<double>::max()));
  std::vector<ImageRoi> box(n, ImageRoi{width, height, -1, -1});
  for (const std::vector<Tally>& chunk_tally : tallies) {
    for (int k = 0; k < n; ++k) {
      const Tally& t = chunk_tally[k];
      count[k] += t.count;
      sum_sq[k] += t.sum_sq;
      lo[k] = lo[k].cwiseMin(t.lo);
      hi[k] = hi[k].cwiseMax(t.hi);
      box[k].x_offset = std::min(box[k].x_offset, t.u_min);
      box[k].y_offset = std::min(box[k].y_offset, t.v_min);
      box[k].width = std::max(box[k].width, t.u_max);
      box[k].height = std::max(box[k].height, t.v_max);
    }
  }
  // Keep the detections with support, renumbered 1..m.
  std::vector<std::uint16_t> relabel(n + 1, 0);
  for (int k = 0; k < n; ++k) {
    if (count[k] == 0)
      continue;
    QuadricDetection detection = std::move(coarse.detections[k]);
    detection.label = static_cast<std::uint16_t>(result.detections.size() + 1);
    relabel[k + 1] = detection.label;
    // The covariance, sigma^2 (J^T J)^-1, follows the full-resolution support: J^T J grows with
    // the points, sigma^2 is their residual variance (the coarse fit's points may include a wider
    // band: plane cells take their pixels without a normal test).
    const double rms = std::sqrt(sum_sq[k] / count[k]);
    if (detection.fit_rms > 0)
      detection.covariance *= std::pow(rms / detection.fit_rms, 2);
    detection.covariance *= static_cast<double>(detection.num_points) / count[k];
    detection.num_points = count[k];
    detection.fit_rms = rms;
    detection.extent_min = lo[k];
    detection.extent_max = hi[k];
    detection.roi = ImageRoi{box[k].x_offset, box[k].y_offset, box[k].width - box[k].x_offset + 1,
                             box[k].height - box[k].y_offset + 1};
    result.detections.push_back(std::move(detection));
  }
  // The labels change only when a detection was dropped (renumbering is the identity otherwise).
  if (static_cast<int>(result.detections.size()) < n) {
    for (int v = 0; v < height; ++v) {
      std::uint16_t* row = result.labels.ptr<std::uint16_t>(v);
      for (int u = 0; u < width; ++u)
        row[u] = relabel[row[u]];
    }
  }
  return result;
}

}  // namespace quadric_slam
