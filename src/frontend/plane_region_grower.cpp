#include "quadric_slam/frontend/plane_region_grower.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>
#include <string>

namespace quadric_slam {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok)
    throw std::invalid_argument("PlaneRegionGrower: " + message);
}

Eigen::Vector3d pointOf(const pcl::PointNormal& p) {
  return Eigen::Vector3d(p.x, p.y, p.z);
}
Eigen::Vector3d normalOf(const pcl::PointNormal& p) {
  return Eigen::Vector3d(p.normal_x, p.normal_y, p.normal_z);
}

// Running first and second moments of a growing region, about a fixed reference point.
struct Moments {
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_sq = Eigen::Matrix3d::Zero();
  Eigen::Vector3d sum_normals = Eigen::Vector3d::Zero();
  double count = 0;

  void add(const Eigen::Vector3d& p, const Eigen::Vector3d& normal) {
    const Eigen::Vector3d q = p - reference;
    sum += q;
    sum_sq += q * q.transpose();
    sum_normals += normal;
    count += 1;
  }
  // Growth criterion while the region is small: the mean of its (smoothed) point normals is far
  // less noisy than a PCA plane through a few noisy points.
  void meanNormalPlane(Eigen::Vector3d& n, double& d) const {
    n = sum_normals.normalized();
    d = n.dot(sum / count + reference);
  }
  // Plane n.p = d through the centroid (normal towards the camera).
  void plane(Eigen::Vector3d& n, double& d) const {
    const Eigen::Vector3d mean = sum / count;
    const Eigen::Matrix3d C = sum_sq / count - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
    n = eig.eigenvectors().col(0);
    const Eigen::Vector3d centroid = mean + reference;
    if (n.dot(centroid) > 0)
      n = -n;
    d = n.dot(centroid);
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
  std::vector<Region> regions;
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
      moments.reference = pointOf(cloud.points[seed]);
      Eigen::Vector3d n = normalOf(cloud.points[seed]).normalized();
      if (!seedIsSmooth(cloud, valid, seed, n, cos_angle)) {
        state[seed] = 2;
        continue;
      }
      double d = n.dot(moments.reference);
      double next_refit = 16;
      queue.clear();
      queue.push_back(seed);
      state[seed] = 1;
      moments.add(moments.reference, n);
      for (std::size_t head = 0; head < queue.size(); ++head) {
        const int i = queue[head];
        const int u = i % width, v = i / width;
        const float zi = cloud.points[i].z;
        const int neighbours[4] = {u > 0 ? i - 1 : -1, u + 1 < width ? i + 1 : -1,
                                   v > 0 ? i - width : -1, v + 1 < height ? i + width : -1};
        for (int j : neighbours) {
          if (j < 0 || !valid[j] || used[j] || state[j] == 1)
            continue;
          const pcl::PointNormal& q = cloud.points[j];
          if (std::abs(q.z - zi) > params_.max_depth_jump_factor * zi)
            continue;
          const Eigen::Vector3d p = pointOf(q);
          const Eigen::Vector3d normal = normalOf(q);
          const double agreement = n.dot(normal);
          if (std::abs(agreement) < cos_angle)
            continue;
          if (std::abs(n.dot(p) - d) >
              depthThreshold(q.z, params_.distance_factor, params_.min_distance))
            continue;
          state[j] = 1;
          queue.push_back(j);
          moments.add(p, agreement < 0 ? Eigen::Vector3d(-normal) : normal);
          if (moments.count >= next_refit) {
            moments.meanNormalPlane(n, d);
            next_refit *= 2;
          }
        }
      }
      bool accepted = static_cast<int>(queue.size()) >= params_.min_points;
      if (accepted) {
        moments.plane(n, d);
        std::vector<int> indices(queue.begin(), queue.end());
        accepted = patchCurvature(cloud, indices, n) <= params_.max_curvature;
        if (accepted) {
          Region region;
          region.indices = std::move(indices);
          region.plane = PrimitiveShape::plane(n, d);
          region.plane.point = moments.sum / moments.count + moments.reference;
          for (int i : region.indices)
            used[i] = 1;
          regions.push_back(std::move(region));
        }
      }
      for (int i : queue)
        state[i] = accepted ? 0 : 2;
    }
  }
  return mergeCoplanar(cloud, std::move(regions));
}

std::vector<PlaneRegionGrower::Region> PlaneRegionGrower::mergeCoplanar(
    const pcl::PointCloud<pcl::PointNormal>& cloud, std::vector<Region> regions) const {
  if (params_.merge_angle <= 0)
    return regions;
  const double cos_merge = std::cos(params_.merge_angle);
  auto close = [&](const Region& a, const Region& b) {
    const double z = b.plane.point.z();
    return std::abs(a.plane.distance(b.plane.point)) <
           depthThreshold(z, params_.distance_factor, params_.min_distance);
  };
  bool merged = true;
  while (merged) {
    merged = false;
    for (std::size_t i = 0; i < regions.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < regions.size() && !merged; ++j) {
        Region& a = regions[i];
        const Region& b = regions[j];
        if (std::abs(a.plane.direction.dot(b.plane.direction)) < cos_merge)
          continue;
        if (!close(a, b) || !close(b, a))
          continue;
        a.indices.insert(a.indices.end(), b.indices.begin(), b.indices.end());
        Moments moments;
        moments.reference = a.plane.point;
        for (int k : a.indices)
          moments.add(pointOf(cloud.points[k]), Eigen::Vector3d::Zero());
        Eigen::Vector3d n;
        double d;
        moments.plane(n, d);
        a.plane = PrimitiveShape::plane(n, d);
        a.plane.point = moments.sum / moments.count + moments.reference;
        regions.erase(regions.begin() + j);
        merged = true;
      }
    }
  }
  return regions;
}

}  // namespace quadric_slam
