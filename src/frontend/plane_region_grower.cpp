#include "quadric_slam/frontend/plane_region_grower.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "quadric_slam/frontend/grid_flood.h"
#include "quadric_slam/frontend/plane_cells.h"
#include "quadric_slam/frontend/point_moments.h"
#include "quadric_slam/frontend/segmentation_frame.h"

namespace quadric_slam {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok)
    throw std::invalid_argument("PlaneRegionGrower: " + message);
}

// A growing region: its points' moments and the sum of their normals.
struct Moments {
  PointMoments points;
  Eigen::Vector3d sum_normals = Eigen::Vector3d::Zero();

  void add(const Eigen::Vector3d& p, const Eigen::Vector3d& normal) {
    points.add(p);
    sum_normals += normal;
  }
  // Growth criterion while the region is small: the mean of its (smoothed) point normals is far
  // less noisy than a PCA plane through a few noisy points.
  void meanNormalPlane(Eigen::Vector3d& n, double& d) const {
    n = sum_normals.normalized();
    d = n.dot(points.centroid());
  }
};

// A seed whose normal agrees with the normals two pixels away in u and v (a noisy or edge normal
// would start a region in a wrong direction).
bool seedIsSmooth(const pcl::PointCloud<pcl::PointNormal>& cloud,
                  const std::vector<std::uint8_t>& valid, int seed, const Eigen::Vector3d& n,
                  double cos_angle) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  const int u = seed % width, v = seed / width;
  if (u < 2 || v < 2 || u + 2 >= width || v + 2 >= height)
    return false;
  const double cos_half = std::cos(0.5 * std::acos(cos_angle));
  for (int j : {seed - 2, seed + 2, seed - 2 * width, seed + 2 * width}) {
    if (!valid[j] || std::abs(n.dot(normalOf(cloud.points[j]))) < cos_half)
      return false;
  }
  return true;
}

}  // namespace

void PlaneRegionGrower::Params::validate() const {
  require(max_normal_angle > 0 && max_normal_angle < M_PI / 2,
          "max_normal_angle must be in (0, pi/2) rad, got " + std::to_string(max_normal_angle));
  require(distance_factor >= 0 && distance_factor <= 1,
          "distance_factor must be in [0, 1] 1/m, got " + std::to_string(distance_factor));
  require(min_distance > 0 && min_distance <= 1,
          "min_distance must be in (0, 1] m, got " + std::to_string(min_distance));
  require(max_depth_jump_factor > 0 && max_depth_jump_factor <= 1,
          "max_depth_jump_factor must be in (0, 1], got " + std::to_string(max_depth_jump_factor));
  require(min_points >= 3, "min_points must be >= 3, got " + std::to_string(min_points));
  require(max_curvature >= 0,
          "max_curvature must be >= 0 1/m, got " + std::to_string(max_curvature));
  require(merge_angle >= 0 && merge_angle < M_PI / 2,
          "merge_angle must be in [0, pi/2) rad, got " + std::to_string(merge_angle));
  require(seed_stride >= 1 && seed_stride <= 64,
          "seed_stride must be in [1, 64], got " + std::to_string(seed_stride));
  require(noise_scale > 0, "noise_scale must be > 0, got " + std::to_string(noise_scale));
  require(
      quantisation_factor >= 0 && quantisation_factor <= 0.1,
      "quantisation_factor must be in [0, 0.1] 1/m, got " + std::to_string(quantisation_factor));
  require(bend_factor >= 0 && bend_factor <= 0.1,
          "bend_factor must be in [0, 0.1] 1/m, got " + std::to_string(bend_factor));
  require(noise_sigmas > 0 && noise_sigmas <= 10,
          "noise_sigmas must be in (0, 10], got " + std::to_string(noise_sigmas));
  require(min_fragment_points >= 3,
          "min_fragment_points must be >= 3, got " + std::to_string(min_fragment_points));
  require(merge_rms_factor >= 1 && merge_rms_factor <= 10,
          "merge_rms_factor must be in [1, 10], got " + std::to_string(merge_rms_factor));
  require(cell_size >= 0 && cell_size <= 64,
          "cell_size must be in [0, 64] pixels, got " + std::to_string(cell_size));
  require(cell_min_depth >= 0 && cell_min_depth <= 10,
          "cell_min_depth must be in [0, 10] m, got " + std::to_string(cell_min_depth));
  require(correlated_points >= 1 && correlated_points <= 1000,
          "correlated_points must be in [1, 1000], got " + std::to_string(correlated_points));
  require(fill_max_normal_angle >= 0 && fill_max_normal_angle < M_PI / 2,
          "fill_max_normal_angle must be in [0, pi/2) rad, got " +
              std::to_string(fill_max_normal_angle));
}

double kinectDepthVariance(double z, double noise_scale, double quantisation_factor) {
  const double axial = noise_scale * (0.0012 + 0.0019 * (z - 0.4) * (z - 0.4));
  const double step = quantisation_factor * z * z;
  return axial * axial + step * step / 12.0;
}

double kinectDepthSigma(double z, double noise_scale, double quantisation_factor) {
  return std::sqrt(kinectDepthVariance(z, noise_scale, quantisation_factor));
}

double planePointThreshold(double z, const PlaneRegionGrower::Params& params) {
  return std::max(
      depthThreshold(z, params.distance_factor, params.min_distance),
      params.noise_sigmas * kinectDepthSigma(z, params.noise_scale, params.quantisation_factor) +
          params.bend_factor * z * z);
}

double planePointVariance(double z, const PlaneRegionGrower::Params& params) {
  const double bend = params.bend_factor * z * z;
  return kinectDepthVariance(z, params.noise_scale, params.quantisation_factor) + bend * bend;
}

PlaneRegionGrower::PlaneRegionGrower(const Params& params) : params_(params) {
  params_.validate();
}

double patchCurvature(const pcl::PointCloud<pcl::PointNormal>& cloud,
                      const std::vector<int>& indices, const Eigen::Vector3d& plane_normal) {
  const Eigen::Vector3d n = plane_normal.normalized();
  const Eigen::Vector3d e1 = n.unitOrthogonal();
  const Eigen::Vector3d e2 = n.cross(e1);
  // Fit dn = M x + c over the patch (x in-plane position, dn in-plane normal component).
  Eigen::Vector2d sx = Eigen::Vector2d::Zero(), sn = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sxx = Eigen::Matrix2d::Zero(), snx = Eigen::Matrix2d::Zero();
  double count = 0;
  const Eigen::Vector3d origin = pointOf(cloud.points[indices.front()]);
  for (int i : indices) {
    const pcl::PointNormal& q = cloud.points[i];
    Eigen::Vector3d normal = normalOf(q);
    if (normal.dot(n) < 0)
      normal = -normal;
    const Eigen::Vector3d p = pointOf(q) - origin;
    const Eigen::Vector2d x(p.dot(e1), p.dot(e2));
    const Eigen::Vector2d dn(normal.dot(e1), normal.dot(e2));
    sx += x;
    sn += dn;
    sxx += x * x.transpose();
    snx += dn * x.transpose();
    count += 1;
  }
  const Eigen::Vector2d mx = sx / count, mn = sn / count;
  const Eigen::Matrix2d cxx = sxx / count - mx * mx.transpose();
  const Eigen::Matrix2d cnx = snx / count - mn * mx.transpose();
  if (std::abs(cxx.determinant()) < 1e-12)
    return 0.0;
  const Eigen::Matrix2d M = cnx * cxx.inverse();
  const Eigen::Matrix2d sym = 0.5 * (M + M.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(sym);
  return eig.eigenvalues().cwiseAbs().maxCoeff();
}

std::vector<PlaneRegionGrower::Region> PlaneRegionGrower::grow(
    const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<std::uint8_t>& valid,
    std::vector<std::uint8_t>& used) const {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  const double cos_angle = std::cos(params_.max_normal_angle);
  // Cells first (plane_cells.h): large and far surfaces, filled out to their borders at once (or
  // the pixels along an occluding edge, in cells that straddle it, would grow regions of their
  // own); then pixels, for what the cells left.
  std::vector<Region> regions = growPlaneCells(cloud, valid, used, params_);
  fill(cloud, valid, used, regions);
  // 0 = free, 1 = in the current region, 2 = tried as part of a rejected region (no seed).
  std::vector<std::uint8_t> state(cloud.size(), 0);
  std::vector<int> queue;
  queue.reserve(cloud.size());

  for (int sv = params_.seed_stride / 2; sv < height; sv += params_.seed_stride) {
    for (int su = params_.seed_stride / 2; su < width; su += params_.seed_stride) {
      const int seed = sv * width + su;
      if (!valid[seed] || used[seed] || state[seed] != 0)
        continue;
      Moments moments;
      moments.points.reference = pointOf(cloud.points[seed]);
      Eigen::Vector3d n = normalOf(cloud.points[seed]).normalized();
      if (!seedIsSmooth(cloud, valid, seed, n, cos_angle)) {
        state[seed] = 2;
        continue;
      }
      double d = n.dot(moments.points.reference);
      double next_refit = 16;
      queue.clear();
      queue.push_back(seed);
      state[seed] = 1;
      moments.add(moments.points.reference, n);
      floodFill4(width, height, queue, [&](int i, int j) {
        if (!valid[j] || used[j] || state[j] == 1)
          return false;
        const pcl::PointNormal& q = cloud.points[j];
        const float zi = cloud.points[i].z;
        if (std::abs(q.z - zi) > params_.max_depth_jump_factor * zi)
          return false;
        const Eigen::Vector3d p = pointOf(q);
        const Eigen::Vector3d normal = normalOf(q);
        const double agreement = n.dot(normal);
        if (std::abs(agreement) < cos_angle)
          return false;
        if (!withinPlaneThreshold(std::abs(n.dot(p) - d), q.z, params_))
          return false;
        state[j] = 1;
        moments.add(p, agreement < 0 ? Eigen::Vector3d(-normal) : normal);
        if (moments.points.count >= next_refit) {
          moments.meanNormalPlane(n, d);
          next_refit *= 2;
        }
        return true;
      });
      // Fragments (at least min_fragment_points) are kept for merging; what stays below
      // min_points after merging is released.
      bool accepted = static_cast<int>(queue.size()) >=
                      std::min(params_.min_points, params_.min_fragment_points);
      if (accepted) {
        const MomentPlane fit(moments.points);
        n = fit.normal;
        d = fit.offset();
        std::vector<int> indices(queue.begin(), queue.end());
        accepted = patchCurvature(cloud, indices, n) <= params_.max_curvature;
        if (accepted) {
          Region region;
          region.indices = std::move(indices);
          region.plane = PrimitiveShape::plane(n, d);
          region.plane.point = fit.centroid;
          for (int i : region.indices)
            used[i] = 1;
          regions.push_back(std::move(region));
        }
      }
      for (int i : queue)
        state[i] = accepted ? 0 : 2;
    }
  }
  regions = mergeCoplanar(cloud, std::move(regions));
  std::vector<Region> planes;
  for (Region& region : regions) {
    if (static_cast<int>(region.indices.size()) >= params_.min_points) {
      planes.push_back(std::move(region));
    } else {
      for (int i : region.indices)
        used[i] = 0;
    }
  }
  fill(cloud, valid, used, planes);
  // Each region passed the flatness test when it was grown, but merging and filling widen it: on a
  // cone or cylinder 2-3 m away, where the normals scatter by 10-20 degrees, a narrow strip along
  // the surface passes, and the filling (fill_max_normal_angle) then spreads it over the visible
  // side, whose normals now bend well beyond max_curvature (measured 1.1 -> 3.4 1/m on a cone).
  // Such a region is a curved surface's: its points go back to the curved stages.
  std::vector<Region> flat;
  for (Region& region : planes) {
    if (patchCurvature(cloud, region.indices, region.plane.direction) <= params_.max_curvature) {
      flat.push_back(std::move(region));
    } else {
      for (int i : region.indices)
        used[i] = 0;
    }
  }
  return flat;
}

namespace {

// A region's plane and its noise-derived uncertainty, from its points' moments.
struct PlaneStats {
  PointMoments moments;
  double sum_variance = 0;  // sum over the points of sigma(z)^2 + bend(z)^2 (m^2)
  Eigen::Vector3d normal, centroid, axis1, axis2;
  double rms = 0;                   // RMS distance of the points to the plane (m)
  double spread1 = 0, spread2 = 0;  // in-plane variances of the points (m^2)
  double count = 0;
  double correlated_points = 1;  // PlaneRegionGrower::Params::correlated_points

  void update() {
    count = moments.count;
    const MomentPlane fit(moments);
    centroid = fit.centroid;
    normal = fit.normal;
    axis1 = fit.axes.col(1);
    axis2 = fit.axes.col(2);
    rms = fit.rms();
    spread1 = std::max(1e-8, fit.eigenvalues[1]);
    spread2 = std::max(1e-8, fit.eigenvalues[2]);
  }
  void add(const PlaneStats& other) {
    moments.add(other.moments);
    sum_variance += other.sum_variance;
    update();
  }
  // Mean expected variance of a point's distance to the plane (noise and bend, m^2).
  double noiseVariance() const { return sum_variance / count; }
  // Independent measurements among the region's points (Params::correlated_points).
  double independent() const { return std::max(1.0, count / correlated_points); }
  // Variance of the plane's offset at x (m^2): the centroid's, and the normal's tilt about it.
  double offsetVariance(const Eigen::Vector3d& x) const {
    const double noise = noiseVariance() / independent();
    const Eigen::Vector3d r = x - centroid;
    return noise +
           noise * (std::pow(r.dot(axis1), 2) / spread1 + std::pow(r.dot(axis2), 2) / spread2);
  }
  // Variance of the normal's direction (rad^2), its larger in-plane component.
  double tiltVariance() const { return noiseVariance() / independent() / spread1; }
};

// Share of the valid points between two coplanar regions that must lie beyond their plane for the
// camera to be taken as seeing past it (a gap, not a hole or an occluder).
constexpr double kSeenPastShare = 0.25;

// Whether the camera sees past the plane n.x = d between two regions: along the image line joining
// their pixel centroids, the valid points of neither region that lie beyond the plane (on the side
// away from the camera, outside the plane's distance threshold) are at least kSeenPastShare of the
// valid points there (and at least two). Fragments of one surface are separated by holes in the
// depth or by nearer objects; two parallel surfaces at nearly the same offset (a table top and the
// top of a post beside it) by what the camera sees behind them. owner[i] is the region of point i
// (-1 for none).
bool seesPastPlaneBetween(const pcl::PointCloud<pcl::PointNormal>& cloud,
                          const std::vector<int>& owner, int region_a, int region_b,
                          const Eigen::Vector2d& pixel_a, const Eigen::Vector2d& pixel_b,
                          const Eigen::Vector3d& n, double d,
                          const PlaneRegionGrower::Params& params) {
  const int width = static_cast<int>(cloud.width);
  const int steps = static_cast<int>(std::ceil((pixel_b - pixel_a).lpNorm<Eigen::Infinity>()));
  // The camera (origin) is on the side where n.x - d has the sign of -d.
  const double away = d >= 0 ? 1.0 : -1.0;
  int tested = 0, beyond = 0, last = -1;
  for (int k = 1; k < steps; ++k) {
    const Eigen::Vector2d pixel = pixel_a + (pixel_b - pixel_a) * (static_cast<double>(k) / steps);
    const int i =
        static_cast<int>(std::lround(pixel.y())) * width + static_cast<int>(std::lround(pixel.x()));
    if (i == last || owner[i] == region_a || owner[i] == region_b)
      continue;
    last = i;
    const pcl::PointNormal& q = cloud.points[i];
    if (!std::isfinite(q.z))
      continue;
    ++tested;
    const double behind = away * (n.dot(pointOf(q)) - d);
    if (behind > 0 && !withinPlaneThreshold(behind, q.z, params))
      ++beyond;
  }
  return beyond >= 2 && beyond >= kSeenPastShare * tested;
}

}  // namespace

std::vector<PlaneRegionGrower::Region> PlaneRegionGrower::mergeCoplanar(
    const pcl::PointCloud<pcl::PointNormal>& cloud, std::vector<Region> regions) const {
  if (params_.merge_angle <= 0 || regions.size() < 2)
    return regions;
  // Largest first: big regions absorb the fragments.
  std::stable_sort(regions.begin(), regions.end(), [](const Region& a, const Region& b) {
    return a.indices.size() > b.indices.size();
  });
  const int width = static_cast<int>(cloud.width);
  // Each point's region (a region keeps its id when it absorbs another) and each region's pixel
  // centroid, for the test of what lies between two regions.
  std::vector<int> owner(cloud.size(), -1), ids(regions.size());
  std::vector<Eigen::Vector2d> pixel_centroids(regions.size(), Eigen::Vector2d::Zero());
  for (std::size_t r = 0; r < regions.size(); ++r) {
    ids[r] = static_cast<int>(r);
    for (int k : regions[r].indices) {
      owner[k] = ids[r];
      pixel_centroids[r] += Eigen::Vector2d(k % width, k / width);
    }
    pixel_centroids[r] /= static_cast<double>(regions[r].indices.size());
  }
  std::vector<PlaneStats> stats(regions.size());
  for (std::size_t r = 0; r < regions.size(); ++r) {
    PlaneStats& st = stats[r];
    st.correlated_points = params_.correlated_points;
    st.moments.reference = regions[r].plane.point;
    for (int k : regions[r].indices) {
      const pcl::PointNormal& q = cloud.points[k];
      st.moments.add(pointOf(q));
      st.sum_variance += planePointVariance(q.z, params_);
    }
    st.update();
  }
  const double k2 = params_.noise_sigmas * params_.noise_sigmas;
  const double min_cos = std::cos(params_.merge_angle);
  // Whether b's plane agrees with a's within their covariance, and the merged fit stays within
  // the noise.
  const auto coplanar = [&](const PlaneStats& a, const PlaneStats& b) {
    const double cos_ab = std::abs(a.normal.dot(b.normal));
    const double angle = std::acos(std::min(1.0, cos_ab));
    const double tilt = std::sqrt(k2 * (a.tiltVariance() + b.tiltVariance()));
    if (cos_ab < min_cos && angle > tilt)
      return false;
    for (const auto& [p, q] : {std::make_pair(&a, &b), std::make_pair(&b, &a)}) {
      const double distance = p->normal.dot(q->centroid - p->centroid);
      const double z = q->centroid.z();
      const double bend = params_.bend_factor * z * z;
      // The sensor's distortion tilts parts of one surface against each other by up to about
      // merge_angle: the offsets may differ by that slope over half their separation.
      const Eigen::Vector3d separation = q->centroid - p->centroid;
      const double in_plane = (separation - p->normal.dot(separation) * p->normal).norm();
      const double allowed =
          std::sqrt(k2 * (p->offsetVariance(q->centroid) + q->noiseVariance() / q->independent())) +
          bend + 0.5 * in_plane * std::sin(params_.merge_angle);
      if (std::abs(distance) > allowed)
        return false;
    }
    PlaneStats merged = a;
    merged.add(b);
    return merged.rms <= params_.merge_rms_factor * std::sqrt(merged.noiseVariance());
  };
  const auto seesPast = [&](std::size_t i, std::size_t j) {
    PlaneStats merged = stats[i];
    merged.add(stats[j]);
    return seesPastPlaneBetween(cloud, owner, ids[i], ids[j], pixel_centroids[i],
                                pixel_centroids[j], merged.normal,
                                merged.normal.dot(merged.centroid), params_);
  };
  bool merged_any = true;
  while (merged_any) {
    merged_any = false;
    for (std::size_t i = 0; i < regions.size(); ++i) {
      for (std::size_t j = i + 1; j < regions.size();) {
        if (!coplanar(stats[i], stats[j]) || seesPast(i, j)) {
          ++j;
          continue;
        }
        Region& a = regions[i];
        const double na = static_cast<double>(a.indices.size());
        const double nb = static_cast<double>(regions[j].indices.size());
        pixel_centroids[i] = (na * pixel_centroids[i] + nb * pixel_centroids[j]) / (na + nb);
        for (int k : regions[j].indices)
          owner[k] = ids[i];
        a.indices.insert(a.indices.end(), regions[j].indices.begin(), regions[j].indices.end());
        PlaneStats& st = stats[i];
        st.add(stats[j]);
        a.plane = PrimitiveShape::plane(st.normal, st.normal.dot(st.centroid));
        a.plane.point = st.centroid;
        regions.erase(regions.begin() + j);
        stats.erase(stats.begin() + j);
        ids.erase(ids.begin() + j);
        pixel_centroids.erase(pixel_centroids.begin() + j);
        merged_any = true;
      }
    }
  }
  return regions;
}

void PlaneRegionGrower::fill(const pcl::PointCloud<pcl::PointNormal>& cloud,
                             const std::vector<std::uint8_t>& valid,
                             std::vector<std::uint8_t>& used, std::vector<Region>& regions) const {
  if (params_.fill_max_normal_angle <= 0)
    return;
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  const double cos_angle = std::cos(params_.fill_max_normal_angle);
  std::vector<int> queue;
  for (Region& region : regions) {
    const Eigen::Vector3d n = region.plane.direction;
    const double d = n.dot(region.plane.point);
    queue = region.indices;
    floodFill4(width, height, queue, [&](int i, int j) {
      if (!valid[j] || used[j])
        return false;
      const pcl::PointNormal& q = cloud.points[j];
      const float zi = cloud.points[i].z;
      if (std::abs(q.z - zi) > params_.max_depth_jump_factor * zi)
        return false;
      if (std::abs(n.dot(normalOf(q))) < cos_angle)
        return false;
      if (!withinPlaneThreshold(std::abs(n.dot(pointOf(q)) - d), q.z, params_))
        return false;
      used[j] = 1;
      region.indices.push_back(j);
      return true;
    });
  }
}

}  // namespace quadric_slam
