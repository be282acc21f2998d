// Test helper: ray-casts analytic scenes (a room seen from inside, solid boxes, spheres, infinite
// planes) into organized depth clouds from a known camera pose, with optional Gaussian depth noise,
// and computes their normals with the project's NormalEstimator. Header-only; used by the odometry
// unit tests and by the bench_odometry tool.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"

namespace quadric_slam {
namespace synthetic {

struct Box {
  Eigen::Vector3d min, max;
};
struct Sphere {
  Eigen::Vector3d centre;
  double radius;
};
struct Plane {
  Eigen::Vector3d normal;  // unit; points p with normal . p = offset
  double offset;
};

struct Scene {
  bool has_room = false;
  Box room;  // seen from inside: its six walls
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;
  std::vector<Plane> planes;

  // Distance along the ray o + t d (d unit) to the first surface, or +inf.
  double raycast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double best = std::numeric_limits<double>::infinity();
    if (has_room) {
      double t_exit = best;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12)
          continue;
        const double wall = d[a] > 0 ? room.max[a] : room.min[a];
        t_exit = std::min(t_exit, (wall - o[a]) / d[a]);
      }
      if (t_exit > 0)
        best = std::min(best, t_exit);
    }
    for (const Box& b : boxes) {
      double t_near = -std::numeric_limits<double>::infinity(), t_far = best;
      bool miss = false;
      for (int a = 0; a < 3 && !miss; ++a) {
        if (std::abs(d[a]) < 1e-12) {
          miss = o[a] < b.min[a] || o[a] > b.max[a];
          continue;
        }
        double t0 = (b.min[a] - o[a]) / d[a], t1 = (b.max[a] - o[a]) / d[a];
        if (t0 > t1)
          std::swap(t0, t1);
        t_near = std::max(t_near, t0);
        t_far = std::min(t_far, t1);
        miss = t_near > t_far;
      }
      if (!miss && t_near > 0 && t_near < best)
        best = t_near;
    }
    for (const Sphere& s : spheres) {
      const Eigen::Vector3d oc = o - s.centre;
      const double bq = oc.dot(d), c = oc.squaredNorm() - s.radius * s.radius;
      const double disc = bq * bq - c;
      if (disc < 0)
        continue;
      const double t = -bq - std::sqrt(disc);
      if (t > 0 && t < best)
        best = t;
    }
    for (const Plane& p : planes) {
      const double denom = p.normal.dot(d);
      if (std::abs(denom) < 1e-12)
        continue;
      const double t = (p.offset - p.normal.dot(o)) / denom;
      if (t > 0 && t < best)
        best = t;
    }
    return best;
  }
};

// A 4 x 4 x 2.7 m room (z up) with two boxes on the floor and a sphere in front of the corner at
// (2, 2): seen from about (-0.3, -0.3, 1.5) every direction of motion is constrained.
inline Scene roomScene() {
  Scene s;
  s.has_room = true;
  s.room = {Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(2.0, 2.0, 2.7)};
  s.boxes.push_back({Eigen::Vector3d(0.9, 0.5, 0.0), Eigen::Vector3d(1.5, 1.1, 0.6)});
  s.boxes.push_back({Eigen::Vector3d(1.4, 1.5, 0.0), Eigen::Vector3d(2.0, 2.0, 1.0)});
  s.spheres.push_back({Eigen::Vector3d(0.3, 1.3, 1.0), 0.3});
  return s;
}

// Camera (optical frame: x right, y down, z forward) at eye looking at target, world z up.
inline Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

inline CameraIntrinsics vgaIntrinsics() {
  CameraIntrinsics k;
  k.fx = 525.0;
  k.fy = 525.0;
  k.cx = 319.5;
  k.cy = 239.5;
  k.width = 640;
  k.height = 480;
  return k;
}

// Organized depth cloud (decimated like backProject) of the scene seen from T_world_camera; depth
// noise is Gaussian with standard deviation noise_per_m2 * z^2 (m); depths beyond max_range are
// no data.
inline pcl::PointCloud<pcl::PointXYZ> renderDepth(const Scene& scene,
                                                  const Eigen::Isometry3d& T_world_camera,
                                                  const CameraIntrinsics& k, int decimation,
                                                  double noise_per_m2, unsigned seed,
                                                  double max_range = 8.0) {
  pcl::PointCloud<pcl::PointXYZ> cloud(k.width / decimation, k.height / decimation);
  cloud.is_dense = false;
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d o = T_world_camera.translation();
  for (int row = 0; row < static_cast<int>(cloud.height); ++row) {
    for (int col = 0; col < static_cast<int>(cloud.width); ++col) {
      const int u = col * decimation, v = row * decimation;
      const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const double len = ray.norm();
      const double t = scene.raycast(o, R * ray / len);
      pcl::PointXYZ& p = cloud(col, row);
      double z = t / len;  // depth along the optical axis
      if (!std::isfinite(z) || z > max_range || z < 0.1) {
        p.x = p.y = p.z = nan;
        continue;
      }
      if (noise_per_m2 > 0)
        z += noise_per_m2 * z * z * gauss(rng);
      p.x = static_cast<float>((u - k.cx) * z / k.fx);
      p.y = static_cast<float>((v - k.cy) * z / k.fy);
      p.z = static_cast<float>(z);
    }
  }
  return cloud;
}

// renderDepth followed by the project's normal estimation (default parameters).
inline pcl::PointCloud<pcl::PointNormal>::Ptr renderCloud(
    const Scene& scene, const Eigen::Isometry3d& T_world_camera, const CameraIntrinsics& k,
    int decimation = 1, double noise_per_m2 = 0.0, unsigned seed = 1) {
  static const NormalEstimator estimator{NormalEstimator::Params()};
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>(
      estimator.compute(renderDepth(scene, T_world_camera, k, decimation, noise_per_m2, seed)));
  return out;
}

}  // namespace synthetic
}  // namespace quadric_slam
