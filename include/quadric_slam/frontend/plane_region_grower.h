// Planes from the organized structure: region growing over the image grid on points + normals.
// A region grows from a seed pixel into 4-neighbours whose normal agrees with the region's plane
// and whose point lies near it; the plane is refitted (PCA) whenever the region doubles. A grown
// region is a plane when it is large enough and flat: the least-squares shape operator of its
// normals (normal change per metre across the region) is below max_curvature, which keeps strips
// of large cylinders out.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <vector>

#include "quadric_slam/frontend/primitive_shape.h"

namespace quadric_slam {

// Distance threshold of a depth measurement at depth z: max(min_distance, factor * z^2) (m); the
// z^2 growth follows the Kinect's depth noise.
inline double depthThreshold(double z, double factor, double min_distance) {
  return std::max(min_distance, factor * z * z);
}

class PlaneRegionGrower {
 public:
  struct Params {
    // Largest angle between a point's normal and the region's plane normal (rad), (0, pi/2).
    // Default 0.26 (15 deg).
    double max_normal_angle = 0.26;
    // Point-to-plane distance threshold: max(min_distance, distance_factor * z^2).
    double distance_factor = 0.008;  // (1/m), [0, 1]
    double min_distance = 0.006;     // (m), (0, 1]
    // Neighbouring depths differing by more than this factor times the depth are not connected
    // (dimensionless), (0, 1].
    double max_depth_jump_factor = 0.04;
    // Smallest plane (points of the cloud grid), >= 3. Default 500 (a floor seen far and at a
    // grazing angle, or in a corner of the image, keeps only a few hundred valid points).
    int min_points = 500;
    // Largest shape-operator eigenvalue of a plane (1/m); a cylinder of radius r has 1/r. >= 0.
    double max_curvature = 1.5;
    // Regions of one plane split in the image (e.g. a floor behind an object) are merged when
    // their normals differ by less than this (rad) and each centroid lies within the distance
    // threshold of the other's plane; [0, pi/2), 0 = never merge. Default 0.035 (2 deg).
    double merge_angle = 0.035;
    // Seeds are tried every seed_stride pixels in u and v, [1, 64].
    int seed_stride = 4;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Region {
    std::vector<int> indices;  // row-major indices into the organized cloud
    PrimitiveShape plane;      // PCA plane; point = centroid
  };

  explicit PlaneRegionGrower(const Params& params);

  // Returned regions are distinct planes (coplanar pieces merged, see merge_angle).
  // valid[i] says whether point i may be used (finite point and normal, in range); used[i] is set
  // for the points of every returned region (and read: used points are skipped).
  std::vector<Region> grow(const pcl::PointCloud<pcl::PointNormal>& cloud,
                           const std::vector<std::uint8_t>& valid,
                           std::vector<std::uint8_t>& used) const;

  const Params& params() const { return params_; }

 private:
  std::vector<Region> mergeCoplanar(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                    std::vector<Region> regions) const;

  Params params_;
};

// Largest absolute eigenvalue of the least-squares shape operator of a patch around its plane:
// the 2x2 map from in-plane position to in-plane normal change (1/m). ~0 for a plane, 1/r for a
// cylinder or sphere of radius r.
double patchCurvature(const pcl::PointCloud<pcl::PointNormal>& cloud,
                      const std::vector<int>& indices, const Eigen::Vector3d& plane_normal);

}  // namespace quadric_slam
