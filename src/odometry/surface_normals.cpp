#include "quadric_slam/odometry/surface_normals.h"

#include "quadric_slam/types/param_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"

namespace quadric_slam {

void SurfaceNormalParams::validate() const {
  const ParamRangeCheck require("SurfaceNormalParams");
  require(max_distance_rms > 0 && max_distance_rms <= 100, "surface_normal_max_distance_rms",
          "(0, 100]", max_distance_rms);
  require(min_max_distance >= 0 && min_max_distance <= 1, "surface_normal_min_max_distance",
          "[0, 1] m", min_max_distance);
  require(max_angle > 0 && max_angle <= M_PI / 2, "surface_normal_max_angle", "(0, pi/2] rad",
          max_angle);
  require(min_depth >= 0 && min_depth <= 100, "surface_normal_min_depth", "[0, 100] m", min_depth);
}

namespace {

// One observed surface as the loop over its pixels needs it: a plane as n . p + d (the common
// case, a few flops a point), anything else through the quadric's exact or first-order distance
// and its gradient.
struct SurfaceTest {
  const QuadricModel* quadric = nullptr;
  bool is_plane = false;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // plane only
  float offset = 0.0f;                               // plane only
  float max_distance = 0.0f;

  float distance(const Eigen::Vector3f& p) const {
    if (is_plane)
      return std::abs(normal.dot(p) + offset);
    return static_cast<float>(std::abs(surfaceDistance(*quadric, p.cast<double>())));
  }
  // Unit normal towards the camera (the estimator's orientation).
  Eigen::Vector3f normalAt(const Eigen::Vector3f& p) const {
    Eigen::Vector3f n =
        is_plane ? normal
                 : algebraicGradient(*quadric, p.cast<double>()).normalized().cast<float>();
    return n.dot(p) > 0.0f ? Eigen::Vector3f(-n) : n;
  }
};

SurfaceTest surfaceTest(const QuadricMeasurement& observation, const SurfaceNormalParams& params) {
  SurfaceTest test;
  test.quadric = &observation.quadric_camera;
  // The fit's RMS as a QuadricObservation message carries it (float32), so that the odometry
  // nodelet and the offline pipeline draw the same line.
  const double fit_rms = static_cast<float>(observation.fit_rms);
  test.max_distance =
      static_cast<float>(std::max(params.max_distance_rms * fit_rms, params.min_max_distance));
  test.is_plane = test.quadric->quadricClass() == QuadricClass::kPlane;
  if (test.is_plane) {
    const PlaneShape plane = planeShape(*test.quadric);  // n . p = d
    test.normal = plane.normal.cast<float>();
    test.offset = static_cast<float>(-plane.offset);
  }
  return test;
}

}  // namespace

int adoptSurfaceNormals(const std::vector<QuadricMeasurement>& observations,
                        const SurfaceNormalParams& params, int stride,
                        pcl::PointCloud<pcl::PointNormal>& cloud, SurfaceNormalScratch* scratch) {
  if (stride < 1)
    throw std::invalid_argument("adoptSurfaceNormals: stride must be >= 1");
  if (!params.enabled || observations.empty() || !cloud.isOrganized())
    return 0;
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  // The grid of every stride-th point: cell (i, j) is cloud point (i * stride, j * stride).
  const int grid_width = (width + stride - 1) / stride,
            grid_height = (height + stride - 1) / stride;
  const auto first_cell = [stride](int pixel) {
    return (std::max(0, pixel) + stride - 1) / stride;
  };
  const float min_cos = static_cast<float>(std::cos(params.max_angle));
  const float min_depth = static_cast<float>(params.min_depth);
  std::vector<SurfaceTest> tests;
  tests.reserve(observations.size());
  for (const QuadricMeasurement& observation : observations)
    tests.push_back(surfaceTest(observation, params));
  // First every surface claims its points, the nearest surface winning (checked against the
  // point's own normal, so that of two surfaces meeting at an edge each keeps its side); then
  // the winners' normals are written.
  const std::size_t size = static_cast<std::size_t>(grid_width) * grid_height;
  SurfaceNormalScratch local;
  SurfaceNormalScratch& work = scratch != nullptr ? *scratch : local;
  work.claimed_distance.assign(size, std::numeric_limits<float>::infinity());
  work.claimed_by.assign(size, -1);
  std::vector<float>& claimed_distance = work.claimed_distance;
  std::vector<int>& claimed_by = work.claimed_by;
  for (std::size_t s = 0; s < tests.size(); ++s) {
    const SurfaceTest& test = tests[s];
    const ImageRoi& roi = observations[s].image_roi;
    const int i0 = first_cell(roi.x_offset), j0 = first_cell(roi.y_offset);
    const int i1 = std::min(grid_width, first_cell(roi.x_offset + roi.width));
    const int j1 = std::min(grid_height, first_cell(roi.y_offset + roi.height));
    for (int j = j0; j < j1; ++j) {
      for (int i = i0; i < i1; ++i) {
        const std::size_t index = static_cast<std::size_t>(j) * grid_width + i;
        const pcl::PointNormal& point =
            cloud.points[static_cast<std::size_t>(j * stride) * width + i * stride];
        const Eigen::Vector3f p(point.x, point.y, point.z);
        const Eigen::Vector3f own(point.normal_x, point.normal_y, point.normal_z);
        if (!(p.z() >= min_depth) || !p.allFinite() || !own.allFinite())
          continue;
        const float distance = test.distance(p);
        if (!(distance <= test.max_distance) || !(distance < claimed_distance[index]))
          continue;
        if (!(test.normalAt(p).dot(own) >= min_cos * own.norm()))
          continue;
        claimed_distance[index] = distance;
        claimed_by[index] = static_cast<int>(s);
      }
    }
  }
  int replaced = 0;
  for (std::size_t index = 0; index < size; ++index) {
    if (claimed_by[index] < 0)
      continue;
    const std::size_t i = index % grid_width, j = index / grid_width;
    pcl::PointNormal& point = cloud.points[j * stride * width + i * stride];
    const Eigen::Vector3f n =
        tests[static_cast<std::size_t>(claimed_by[index])].normalAt({point.x, point.y, point.z});
    point.normal_x = n.x();
    point.normal_y = n.y();
    point.normal_z = n.z();
    ++replaced;
  }
  return replaced;
}

}  // namespace quadric_slam
