#include "quadric_slam/frontend/quadric_segmenter.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "quadric_slam/frontend/boundary_labels.h"
#include "quadric_slam/frontend/curved_candidates.h"
#include "quadric_slam/frontend/curved_verification.h"
#include "quadric_slam/frontend/ellipsoid_candidate.h"
#include "quadric_slam/frontend/multi_resolution_labels.h"
#include "quadric_slam/frontend/segmentation_frame.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok)
    throw std::invalid_argument("QuadricSegmenter: " + message);
}

std::string str(double value) {
  return std::to_string(value);
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

void QuadricSegmenter::Params::validate() const {
  require(min_range > 0 && min_range < max_range,
          "min_range and max_range must satisfy 0 < min_range < max_range (m), got " +
              str(min_range) + ", " + str(max_range));
  require(decimation >= 1 && decimation <= 8,
          "decimation must be in [1, 8], got " + std::to_string(decimation));
  require(threads >= 1 && threads <= 64,
          "threads must be in [1, 64], got " + std::to_string(threads));
  require(curved_decimation >= 1 && curved_decimation <= 8,
          "curved_decimation must be in [1, 8], got " + std::to_string(curved_decimation));
  require(boundary_rings >= 0 && boundary_rings <= 10,
          "boundary_rings must be in [0, 10], got " + std::to_string(boundary_rings));
  planes.validate();
  refiner.validate();
  require(cgal_stride >= 1 && cgal_stride <= 16,
          "cgal_stride must be in [1, 16], got " + std::to_string(cgal_stride));
  require(cgal_probability > 0 && cgal_probability < 1,
          "cgal_probability must be in (0, 1), got " + str(cgal_probability));
  require(quadric_rms_ratio >= 1, "quadric_rms_ratio must be >= 1, got " + str(quadric_rms_ratio));
  require(cgal_min_points >= 4,
          "cgal_min_points must be >= 4, got " + std::to_string(cgal_min_points));
  require(cgal_epsilon > 0, "cgal_epsilon must be > 0 m, got " + str(cgal_epsilon));
  require(cgal_cluster_epsilon > 0,
          "cgal_cluster_epsilon must be > 0 m, got " + str(cgal_cluster_epsilon));
  require(cgal_max_points >= 100,
          "cgal_max_points must be >= 100, got " + std::to_string(cgal_max_points));
  require(cgal_min_fraction >= 0 && cgal_min_fraction < 1,
          "cgal_min_fraction must be in [0, 1), got " + str(cgal_min_fraction));
  require(cgal_normal_threshold > 0 && cgal_normal_threshold < 1,
          "cgal_normal_threshold must be in (0, 1), got " + str(cgal_normal_threshold));
  require(curved_max_normal_angle > 0 && curved_max_normal_angle < M_PI / 2,
          "curved_max_normal_angle must be in (0, pi/2) rad, got " + str(curved_max_normal_angle));
  require(min_curved_points >= 4,
          "min_curved_points must be >= 4, got " + std::to_string(min_curved_points));
  require(min_sphere_radius > 0 && min_sphere_radius < max_sphere_radius,
          "sphere radii must satisfy 0 < min_sphere_radius < max_sphere_radius (m)");
  require(min_cylinder_radius > 0 && min_cylinder_radius < max_cylinder_radius,
          "cylinder radii must satisfy 0 < min_cylinder_radius < max_cylinder_radius (m)");
  require(min_cone_half_angle > 0 && min_cone_half_angle < max_cone_half_angle &&
              max_cone_half_angle < M_PI / 2,
          "cone half angles must satisfy 0 < min_cone_half_angle < max_cone_half_angle < pi/2");
  require(plane_rms_ratio >= 1, "plane_rms_ratio must be >= 1, got " + str(plane_rms_ratio));
  require(cylinder_rms_ratio >= 1,
          "cylinder_rms_ratio must be >= 1, got " + str(cylinder_rms_ratio));
  require(general_model_sigma >= 0 && general_model_sigma <= 0.1,
          "general_model_sigma must be in [0, 0.1] m, got " + str(general_model_sigma));
  require(max_rms_factor > 0 && max_rms_factor <= 10,
          "max_rms_factor must be in (0, 10], got " + str(max_rms_factor));
}

QuadricSegmenter::QuadricSegmenter(const Params& params) : params_(params) {
  params_.validate();
}

namespace {

// Adds a detection with its support (pixels of frame's grid) to result: label, fit, support
// statistics; marks the pixels used.
AcceptDetection acceptInto(SegmentationFrame& frame, Segmentation& result) {
  return [&frame, &result](const std::vector<int>& indices, const ShapeRefiner::Result& fit) {
    const pcl::PointCloud<pcl::PointNormal>& cloud = frame.cloud;
    const int width = frame.width;
    QuadricDetection detection;
    detection.shape = fit.shape;
    const std::vector<Eigen::Vector3d> points = pointsOf(cloud, indices);
    centreOnSupport(detection.shape, points);
    detection.covariance = fit.covariance;
    // The fit's covariance is about fit.shape.quadric(); re-centring moves the frame by a symmetry
    // element G (a slide along the cylinder axis; a relabelling of a general quadric's axes), so
    // re-express it: C' = M C M^T, M = Ad(G^-1).
    const Eigen::Isometry3d G =
        fit.shape.quadric().pose().inverse() * detection.shape.quadric().pose();
    const int k = minimalDimension(detection.shape.quadric_class);
    if (fit.covariance.rows() == k && fit.covariance.cols() == k) {
      const Eigen::MatrixXd M = minimalAdjoint(detection.shape.quadric_class, G.inverse());
      detection.covariance = M * fit.covariance * M.transpose();
    }
    detection.num_points = static_cast<int>(indices.size());
    detection.fit_rms = rmsDistance(detection.shape, points);
    detection.label = static_cast<std::uint16_t>(result.detections.size() + 1);
    detection.roi = roiOf(indices, width);
    const Eigen::Isometry3d T_quadric_frame = detection.shape.quadric().pose().inverse();
    detection.extent_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
    detection.extent_max = -detection.extent_min;
    for (const auto& q : points) {
      const Eigen::Vector3d local = T_quadric_frame * q;
      detection.extent_min = detection.extent_min.cwiseMin(local);
      detection.extent_max = detection.extent_max.cwiseMax(local);
    }
    for (int i : indices) {
      frame.used[i] = 1;
      result.labels.at<std::uint16_t>(i / width, i % width) = detection.label;
    }
    result.detections.push_back(std::move(detection));
  };
}

// The curved stages (2-3 of segmentGrid) on frame's grid decimated by p.curved_decimation, their
// segments then labelled on frame's free points (multi_resolution_labels.h): detections and labels
// on frame's grid. The used flags of frame are not changed.
Segmentation segmentCurvedCoarser(const SegmentationFrame& frame, const QuadricSegmenter::Params& p,
                                  const ShapeRefiner& refiner, SegmentationTimings& timings) {
  const int c = p.curved_decimation;
  const pcl::PointCloud<pcl::PointNormal> grid = decimated(frame.cloud, c);
  const int width = static_cast<int>(grid.width), height = static_cast<int>(grid.height);
  SegmentationFrame coarse_frame{grid, width, height, std::vector<std::uint8_t>(grid.size(), 0),
                                 std::vector<std::uint8_t>(grid.size(), 0)};
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const int i = v * c * frame.width + u * c;
      coarse_frame.valid[v * width + u] = frame.valid[i];
      coarse_frame.used[v * width + u] = frame.used[i];
    }
  }
  const QuadricSegmenter::Params coarse_params = coarseParams(p, c);
  Segmentation coarse;
  coarse.labels = cv::Mat::zeros(height, width, CV_16UC1);
  auto start = std::chrono::steady_clock::now();
  const CurvedCandidates candidates = findCurvedCandidates(coarse_frame, coarse_params);
  timings.ransac_points = static_cast<int>(candidates.points.size());
  timings.ransac_candidates = static_cast<int>(candidates.shapes.size());
  timings.ransac_ms = msSince(start);
  start = std::chrono::steady_clock::now();
  timings.curved_verified_again = verifyCurvedCandidates(coarse_frame, candidates, coarse_params,
                                                         refiner, acceptInto(coarse_frame, coarse));
  // The curved segments take only the free points of frame's grid (the labelling's own tests leave
  // out the invalid ones: no depth in range, no normal).
  Segmentation curved = upsample(frame.cloud, std::move(coarse), c, p, frame.used);
  timings.verify_ms = msSince(start);
  return curved;
}

// The segmentation proper, on the grid of the cloud it is given.
Segmentation segmentGrid(const pcl::PointCloud<pcl::PointNormal>& cloud,
                         const QuadricSegmenter::Params& p) {
  Segmentation result;
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  result.labels = cv::Mat::zeros(height, width, CV_16UC1);
  if (cloud.empty())
    return result;

  SegmentationFrame frame{cloud, width, height, std::vector<std::uint8_t>(cloud.size(), 0),
                          std::vector<std::uint8_t>(cloud.size(), 0)};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const pcl::PointNormal& q = cloud.points[i];
    frame.valid[i] = std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
                     std::isfinite(q.normal_x) && std::isfinite(q.normal_y) &&
                     std::isfinite(q.normal_z) && q.z >= p.min_range && q.z <= p.max_range;
  }

  const ShapeRefiner refiner(p.refiner);
  const AcceptDetection accept = acceptInto(frame, result);

  auto start = std::chrono::steady_clock::now();
  // 1. Planes from the image grid.
  const PlaneRegionGrower grower(p.planes);
  for (const PlaneRegionGrower::Region& region : grower.grow(cloud, frame.valid, frame.used)) {
    const ShapeRefiner::Result fit =
        refiner.evaluate(region.plane, pointsOf(cloud, region.indices));
    accept(region.indices, fit);
  }

  result.timings.planes_ms = msSince(start);
  start = std::chrono::steady_clock::now();

  const int c = p.curved_decimation;
  if (c > 1 && width >= 4 * c && height >= 4 * c) {
    // 2-3. The curved stages on a coarser grid, whose cost grows with the samples; the planes
    // stay on this one (a plane's extent and the merging of its fragments need it). Their labels
    // follow the planes' in numbering.
    Segmentation curved = segmentCurvedCoarser(frame, p, refiner, result.timings);
    for (QuadricDetection& detection : curved.detections)
      detection.label = static_cast<std::uint16_t>(detection.label + result.detections.size());
    const auto offset = static_cast<std::uint16_t>(result.detections.size());
    for (int v = 0; v < height; ++v) {
      const std::uint16_t* from = curved.labels.ptr<std::uint16_t>(v);
      std::uint16_t* to = result.labels.ptr<std::uint16_t>(v);
      for (int u = 0; u < width; ++u)
        if (from[u] != 0)
          to[u] = static_cast<std::uint16_t>(from[u] + offset);
    }
    for (QuadricDetection& detection : curved.detections)
      result.detections.push_back(std::move(detection));
    return result;
  }

  // 2. Curved candidates (curved_candidates.h).
  const CurvedCandidates candidates = findCurvedCandidates(frame, p);
  result.timings.ransac_points = static_cast<int>(candidates.points.size());
  result.timings.ransac_candidates = static_cast<int>(candidates.shapes.size());
  result.timings.ransac_ms = msSince(start);
  start = std::chrono::steady_clock::now();

  // 3. Each curved candidate verified, refined and re-assigned, biggest first
  // (curved_verification.h).
  result.timings.curved_verified_again =
      verifyCurvedCandidates(frame, candidates, p, refiner, accept);
  result.timings.verify_ms = msSince(start);
  return result;
}

}  // namespace

Segmentation QuadricSegmenter::segment(const pcl::PointCloud<pcl::PointNormal>& cloud) const {
  Segmentation result = segmentWithNormals(cloud);
  const auto start = std::chrono::steady_clock::now();
  BoundaryCompletion boundary;
  boundary.rings = params_.boundary_rings;
  boundary.min_range = params_.min_range;
  boundary.max_range = params_.max_range;
  boundary.distance_factor = params_.planes.distance_factor;
  boundary.min_distance = params_.planes.min_distance;
  completeBoundaryLabels(cloud, boundary, result);
  // The model error of the general detections, added once their support (which scales the
  // least-squares part) is final.
  for (QuadricDetection& d : result.detections)
    if (d.shape.quadric_class == QuadricClass::kGeneral && d.covariance.rows() == 9)
      d.covariance +=
          ellipsoidModelCovariance(d.shape.general_quadric, params_.general_model_sigma);
  result.timings.boundary_ms = msSince(start);
  return result;
}

Segmentation QuadricSegmenter::segmentWithNormals(
    const pcl::PointCloud<pcl::PointNormal>& cloud) const {
  if (!cloud.isOrganized() && !cloud.empty())
    throw std::invalid_argument("QuadricSegmenter: the cloud must be organized");
  const int d = params_.decimation;
  if (d == 1 || cloud.width < static_cast<std::uint32_t>(4 * d) ||
      cloud.height < static_cast<std::uint32_t>(4 * d))
    return segmentGrid(cloud, params_);
  const auto start = std::chrono::steady_clock::now();
  const pcl::PointCloud<pcl::PointNormal> grid = decimated(cloud, d);
  const double decimate_ms = msSince(start);
  Segmentation coarse = segmentGrid(grid, coarseParams(params_, d));
  const auto upsample_start = std::chrono::steady_clock::now();
  Segmentation result = upsample(cloud, std::move(coarse), d, params_);
  result.timings.upsample_ms = decimate_ms + msSince(upsample_start);
  return result;
}

cv::Mat colouriseLabels(const cv::Mat& labels) {
  cv::Mat rgb(labels.rows, labels.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      const unsigned label = labels.at<std::uint16_t>(y, x);
      if (label == 0)
        continue;
      // Golden-angle hue steps give neighbouring labels distinct colours.
      const double hue = std::fmod(label * 137.508, 360.0) / 60.0;
      const double f = hue - std::floor(hue);
      const double s = 0.85, v = 0.95;
      const double pp = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
      double r = v, g = t, b = pp;
      switch (static_cast<int>(hue) % 6) {
        case 1:
          r = q;
          g = v;
          b = pp;
          break;
        case 2:
          r = pp;
          g = v;
          b = t;
          break;
        case 3:
          r = pp;
          g = q;
          b = v;
          break;
        case 4:
          r = t;
          g = pp;
          b = v;
          break;
        case 5:
          r = v;
          g = pp;
          b = q;
          break;
        default:
          break;
      }
      rgb.at<cv::Vec3b>(y, x) =
          cv::Vec3b(static_cast<unsigned char>(255 * r), static_cast<unsigned char>(255 * g),
                    static_cast<unsigned char>(255 * b));
    }
  }
  return rgb;
}

}  // namespace quadric_slam
