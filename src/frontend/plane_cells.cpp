#include "quadric_slam/frontend/plane_cells.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "quadric_slam/frontend/grid_flood.h"
#include "quadric_slam/frontend/segmentation_frame.h"

namespace quadric_slam {

namespace {

// Cells whose plane is seen at more than about 75 deg from its normal are not planar.
constexpr double kMinViewCosine = 0.26;
// Regions of fewer cells are left to the pixel grower: so small a plane is seen near, where pixel
// normals are good, or is a strip of a curved surface along which the cells happen to agree.
constexpr std::size_t kMinRegionCells = 4;
// A pixel of a region's cell joins unless its normal is more than 60 deg off the plane's: far
// pixel normals are too noisy for a tighter test, but a surface meeting the plane at a crease (a
// wall above a floor) must not pull it.
constexpr double kMinPixelNormalCosine = 0.5;

// Least squares of inverse depth over normalised image coordinates. On a plane n.p = d, a point
// p = z (x, y, 1) satisfies (-n / d).(x, y, 1) = 1 / z: inverse depth is affine in (x, y). The
// Kinect measures disparity, whose noise is about the same everywhere, so this regression weighs
// the points as the sensor does; unlike a PCA plane it cannot tip over when the depth noise
// exceeds the extent of the points (a 16-pixel cell is 11 cm wide at 4 m, the noise 4 cm).
struct InverseDepthMoments {
  Eigen::Matrix3d xtx = Eigen::Matrix3d::Zero();  // sum of (x, y, 1)(x, y, 1)^T
  Eigen::Vector3d xtw = Eigen::Vector3d::Zero();  // sum of (x, y, 1) w
  double wtw = 0;                                 // sum of w^2
  Eigen::Vector3d sum_points = Eigen::Vector3d::Zero();
  double count = 0;

  void add(const Eigen::Vector3d& p) {
    const double w = 1.0 / p.z();
    const Eigen::Vector3d x(p.x() * w, p.y() * w, 1.0);
    xtx += x * x.transpose();
    xtw += x * w;
    wtw += w * w;
    sum_points += p;
    count += 1;
  }
  void add(const InverseDepthMoments& other) {
    xtx += other.xtx;
    xtw += other.xtw;
    wtw += other.wtw;
    sum_points += other.sum_points;
    count += other.count;
  }
  Eigen::Vector3d centroid() const { return sum_points / count; }
};

// The plane of an inverse-depth fit: theta = (-n / d), so n = -theta / |theta|, d = -1 / |theta|.
struct InverseDepthPlane {
  Eigen::Vector3d theta = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(), centroid = Eigen::Vector3d::Zero();
  double offset = 0;
  double residual_variance = 0;  // of the inverse depths (1/m^2)
  bool ok = false;

  explicit InverseDepthPlane(const InverseDepthMoments& m) {
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(m.xtx);
    if (m.count < 3 || ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-12))
      return;
    theta = ldlt.solve(m.xtw);
    const double norm = theta.norm();
    if (!(norm > 1e-9))
      return;
    normal = -theta / norm;
    offset = -1.0 / norm;
    centroid = m.centroid();
    residual_variance = std::max(0.0, (m.wtw - theta.dot(m.xtw)) / m.count);
    ok = true;
  }
  double distance(const Eigen::Vector3d& p) const { return std::abs(normal.dot(p) - offset); }
};

// Depth jumps inside a cell, in standard deviations of the sensor's depth noise (the difference of
// two neighbours has sqrt(2) of it: 4.2 sigma of that, which noise alone exceeds somewhere in a
// few of a thousand cells of a hundred pairs each).
constexpr double kJumpSigmas = 6.0;

// One cell's plane and how well it is determined.
struct Cell {
  InverseDepthMoments moments;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero(), centroid = Eigen::Vector3d::Zero();
  double normal_variance = 0;    // of the normal's direction (rad^2)
  double centroid_variance = 0;  // of the centroid along the normal (m^2)
  double flatness = 0;           // RMS of the fit / the expected noise
  bool planar = false;
};

// The cell whose top-left pixel is (u0, v0), at most size x size pixels (clipped to the grid).
Cell fitCell(const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<std::uint8_t>& valid,
             const std::vector<std::uint8_t>& used, int u0, int v0, int size,
             const PlaneRegionGrower::Params& params) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  const int u1 = std::min(width, u0 + size), v1 = std::min(height, v0 + size);
  Cell cell;
  // First the cheap tests, on the depths alone: no depth jump inside, enough points, far enough.
  // Most cells of a near scene stop here, before the moments are summed.
  double sum_z = 0;
  int depths = 0;
  for (int v = v0; v < v1; ++v) {
    for (int u = u0; u < u1; ++u) {
      const int i = v * width + u;
      if (!valid[i] || used[i])
        continue;
      const float z = cloud.points[i].z;
      // A depth jump to the right or below: the cell spans an occluding edge. Beyond 3 m the
      // noise of two neighbours' difference nears max_depth_jump_factor z; over a cell's hundred
      // pairs a jump must also exceed kJumpSigmas of it.
      for (int j : {u + 1 < u1 ? i + 1 : -1, v + 1 < v1 ? i + width : -1}) {
        if (j < 0 || !valid[j])
          continue;
        const double step = std::abs(cloud.points[j].z - z);
        if (step > params.max_depth_jump_factor * z &&
            step >
                kJumpSigmas * kinectDepthSigma(z, params.noise_scale, params.quantisation_factor))
          return cell;
      }
      sum_z += z;
      ++depths;
    }
  }
  const int area = (u1 - u0) * (v1 - v0);
  if (depths < std::max(6, area / 2) || sum_z < params.cell_min_depth * depths)
    return cell;
  for (int v = v0; v < v1; ++v) {
    for (int u = u0; u < u1; ++u) {
      const int i = v * width + u;
      if (valid[i] && !used[i])
        cell.moments.add(pointOf(cloud.points[i]));
    }
  }
  // The noise at the cell's mean depth (a cell spans little depth unless seen at a grazing angle,
  // and such cells are not planar below): of the depths, and of the inverse depths (sigma / z^2).
  const double mean_z = sum_z / cell.moments.count;
  const double variance = planePointVariance(mean_z, params);
  const double w_variance = variance / std::pow(mean_z, 4);
  const InverseDepthPlane fit(cell.moments);
  if (!fit.ok)
    return cell;
  const double count = cell.moments.count;
  const double independent = std::max(1.0, count / params.correlated_points);
  cell.normal = fit.normal;
  cell.centroid = fit.centroid;
  // Covariance of theta, w_variance (X^T X)^-1 over the independent measurements; the normal's
  // direction varies with theta's component across theta, scaled by 1 / |theta|.
  const Eigen::Matrix3d theta_covariance =
      w_variance * cell.moments.xtx.inverse() * (count / independent);
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - fit.normal * fit.normal.transpose();
  cell.normal_variance = (across * theta_covariance * across).trace() / fit.theta.squaredNorm();
  cell.centroid_variance = variance / independent;
  cell.flatness = std::sqrt(fit.residual_variance / w_variance);
  // Seen at a grazing angle the sensor smears depth along the ray (and a curved surface's
  // silhouette looks flat there): such a cell says nothing reliable about a plane.
  const bool facing = std::abs(fit.normal.dot(fit.centroid.normalized())) >= kMinViewCosine;
  cell.planar = facing && cell.flatness <= params.merge_rms_factor;
  return cell;
}

}  // namespace

std::vector<PlaneRegionGrower::Region> growPlaneCells(
    const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<std::uint8_t>& valid,
    std::vector<std::uint8_t>& used, const PlaneRegionGrower::Params& params) {
  std::vector<PlaneRegionGrower::Region> regions;
  const int size = params.cell_size;
  if (size < 2 || cloud.empty())
    return regions;
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  const int cells_u = (width + size - 1) / size, cells_v = (height + size - 1) / size;
  std::vector<Cell> cells(static_cast<std::size_t>(cells_u) * cells_v);
  for (int cv = 0; cv < cells_v; ++cv)
    for (int cu = 0; cu < cells_u; ++cu)
      cells[cv * cells_u + cu] = fitCell(cloud, valid, used, cu * size, cv * size, size, params);

  std::vector<int> seeds;
  for (int c = 0; c < static_cast<int>(cells.size()); ++c)
    if (cells[c].planar)
      seeds.push_back(c);
  std::stable_sort(seeds.begin(), seeds.end(),
                   [&](int a, int b) { return cells[a].flatness < cells[b].flatness; });

  const double k2 = params.noise_sigmas * params.noise_sigmas;
  const double min_angle = params.max_normal_angle;
  const double max_angle = std::min(2.0 * params.max_normal_angle, 0.5 * M_PI - 1e-3);
  const int min_points = std::min(params.min_points, params.min_fragment_points);
  // 0 = free, 1 = in the region being grown, 2 = in a rejected region (joins, does not seed),
  // 3 = in an accepted region.
  std::vector<std::uint8_t> state(cells.size(), 0);
  std::vector<int> queue;
  for (int seed : seeds) {
    if (state[seed] != 0)
      continue;
    InverseDepthMoments moments = cells[seed].moments;
    InverseDepthPlane plane(moments);
    queue.assign(1, seed);
    state[seed] = 1;
    floodFill4(cells_u, cells_v, queue, [&](int, int j) {
      const Cell& cell = cells[j];
      if (!cell.planar || state[j] == 1 || state[j] == 3)
        return false;
      // The normals agree within the noise of the cell's normal (the region's is far smaller).
      const double cos_nn = std::min(1.0, std::abs(plane.normal.dot(cell.normal)));
      const double allowed_angle =
          std::clamp(std::sqrt(k2 * cell.normal_variance), min_angle, max_angle);
      if (std::acos(cos_nn) > allowed_angle)
        return false;
      const double z = cell.centroid.z();
      if (plane.distance(cell.centroid) >
          std::sqrt(k2 * cell.centroid_variance) + params.bend_factor * z * z)
        return false;
      InverseDepthMoments grown = moments;
      grown.add(cell.moments);
      const InverseDepthPlane refit(grown);
      if (!refit.ok)
        return false;
      state[j] = 1;
      moments = grown;
      plane = refit;
      return true;
    });

    PlaneRegionGrower::Region region;
    const double d = plane.offset;
    if (queue.size() < kMinRegionCells) {
      for (int c : queue)
        state[c] = 2;
      continue;
    }
    for (int c : queue) {
      const int u0 = (c % cells_u) * size, v0 = (c / cells_u) * size;
      for (int v = v0; v < std::min(height, v0 + size); ++v)
        for (int u = u0; u < std::min(width, u0 + size); ++u) {
          const int i = v * width + u;
          if (!valid[i] || used[i])
            continue;
          const pcl::PointNormal& q = cloud.points[i];
          if (withinPlaneThreshold(std::abs(plane.normal.dot(pointOf(q)) - d), q.z, params) &&
              std::abs(plane.normal.dot(normalOf(q))) >= kMinPixelNormalCosine)
            region.indices.push_back(i);
        }
    }
    const bool accepted =
        static_cast<int>(region.indices.size()) >= min_points &&
        patchCurvature(cloud, region.indices, plane.normal) <= params.max_curvature;
    for (int c : queue)
      state[c] = accepted ? 3 : 2;
    if (!accepted)
      continue;
    for (int i : region.indices)
      used[i] = 1;
    region.plane = PrimitiveShape::plane(plane.normal, d);
    region.plane.point = plane.centroid;
    regions.push_back(std::move(region));
  }
  return regions;
}

}  // namespace quadric_slam
