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

// Axial depth noise of a Kinect v1 at depth z (m), one standard deviation (m): the model of
// Nguyen, Izadi and Lovell (3DIMPVT 2012), 0.0012 + 0.0019 (z - 0.4)^2, times noise_scale (real
// frames' plane residuals are about 1.4x the model), combined with the depth step of the disparity
// quantisation (1/8 pixel: a step of quantisation_factor * z^2, uniform, std step / sqrt(12)).
double kinectDepthSigma(double z, double noise_scale, double quantisation_factor);
// Its square, without the square root (per-point noise sums).
double kinectDepthVariance(double z, double noise_scale, double quantisation_factor);

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
    // their normals differ by less than this (rad) or within their noise (noise_sigmas), each
    // centroid lies within the noise of the other's plane (plus the bend and this angle's slope
    // over half their separation: real Kinect frames tilt the far part of a floor or wall by 1-4
    // deg against the near part) and the merged fit's RMS stays within the noise
    // (merge_rms_factor); [0, pi/2), 0 = never merge. Default 0.07 (4 deg).
    double merge_angle = 0.07;
    // Seeds are tried every seed_stride pixels in u and v, [1, 64].
    int seed_stride = 4;
    // Sensor noise (kinectDepthSigma): scale of the Nguyen model, > 0, default 1.4; depth step of
    // the disparity quantisation per z^2 (1/m), [0, 0.1], default 0.0029 (1/8 px over f b = 580 px
    // x 7.5 cm).
    double noise_scale = 1.4;
    double quantisation_factor = 0.0029;
    // Low-frequency bend of a flat surface in the depth image (the sensor's systematic distortion,
    // about 1 cm towards the image corners at 3 m): bend_factor * z^2 (1/m), [0, 0.1]. Tolerated
    // on top of the noise when growing, merging and filling.
    double bend_factor = 0.0011;
    // Growing: a point joins when within max(distance threshold above, noise_sigmas * sigma(z) +
    // bend(z)) of the region's plane. Merging: plane parameters must agree within noise_sigmas
    // standard deviations of their noise-derived covariance. (0, 10], default 3.
    double noise_sigmas = 3.0;
    // Regions smaller than min_points but of at least min_fragment_points (points of the cloud
    // grid, >= 3) are kept as fragments: they become planes only by merging with coplanar regions
    // (a wall split by occluders, holes or noisy normals). Default 100.
    int min_fragment_points = 100;
    // Merging: the merged fit's RMS must stay below merge_rms_factor times the noise expected of
    // its points (RMS of sigma(z) and the bend), [1, 10], default 1.5.
    double merge_rms_factor = 1.5;
    // Filling: free points 4-connected to a plane (no depth jump) join it when within the growing
    // threshold of its final plane and with a normal within fill_max_normal_angle (rad), [0,
    // pi/2); 0 = no filling. Default 0.45 (far normals are noisy; the distance test decides).
    double fill_max_normal_angle = 0.45;
    // Planes are first grown over square cells of cell_size x cell_size pixels of the cloud grid,
    // judged by the cells' own plane fits rather than the pixels' normals (plane_cells.h), then
    // over the pixels the cells left; [0, 64], 0 or 1 = pixels only. Default 16 (full-resolution
    // pixels: about 11 cm at 4 m).
    int cell_size = 16;
    // Cells nearer than this mean depth (m) are left to the pixel grower, [0, 10]. Near, pixel
    // normals are good, and their test keeps apart parallel surfaces a centimetre or two apart (a
    // cabinet door and its frame) that a cell's noise band joins. Cells from 2 m help the
    // segmentation too, but the larger planes they give cost the real kitchen's trajectory (1000
    // frames, refined ATE: no cells 2.58 cm, from 3 m 2.64, from 2 m 2.79): the mapper weighs far
    // planes by their noise and not yet by the sensor's systematic distortion. Default 3.
    double cell_min_depth = 3.0;
    // Neighbouring depths of a structured-light sensor share its disparity matcher's window (the
    // Kinect v1 correlates about 9 x 9 pixels): N points of one surface carry about N /
    // correlated_points independent measurements (the noise of plane and cell fits). In points of
    // the cloud grid, [1, 1000]: 64 on a full-resolution grid; a grid decimated by d holds
    // 64 / d^2 of them (multi_resolution_labels.h coarseParams). Default 64.
    double correlated_points = 64.0;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Region {
    std::vector<int> indices;  // row-major indices into the organized cloud
    PrimitiveShape plane;      // PCA plane; point = centroid
  };

  explicit PlaneRegionGrower(const Params& params);

  // Returned regions are distinct planes (coplanar pieces merged, see merge_angle and the noise
  // parameters), of at least min_points each.
  // valid[i] says whether point i may be used (finite point and normal, in range); used[i] is set
  // for the points of every returned region (and read: used points are skipped).
  std::vector<Region> grow(const pcl::PointCloud<pcl::PointNormal>& cloud,
                           const std::vector<std::uint8_t>& valid,
                           std::vector<std::uint8_t>& used) const;

  const Params& params() const { return params_; }

 private:
  std::vector<Region> mergeCoplanar(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                    std::vector<Region> regions) const;
  // Adds the free points connected to each region that fit its plane (fill_max_normal_angle).
  void fill(const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<std::uint8_t>& valid,
            std::vector<std::uint8_t>& used, std::vector<Region>& regions) const;

  Params params_;
};

// Largest absolute eigenvalue of the least-squares shape operator of a patch around its plane:
// the 2x2 map from in-plane position to in-plane normal change (1/m). ~0 for a plane, 1/r for a
// cylinder or sphere of radius r.
// Distance threshold of a point at depth z to its plane when growing and filling (m):
// max(max(min_distance, distance_factor z^2), noise_sigmas sigma(z) + bend_factor z^2).
double planePointThreshold(double z, const PlaneRegionGrower::Params& params);

// distance <= planePointThreshold(z, params); the depth-scaled threshold first, which needs no
// square root and decides most points.
inline bool withinPlaneThreshold(double distance, double z,
                                 const PlaneRegionGrower::Params& params) {
  return distance <= depthThreshold(z, params.distance_factor, params.min_distance) ||
         distance <= planePointThreshold(z, params);
}

// Expected variance of a point's distance to its plane at depth z (m^2): the sensor's noise
// (kinectDepthSigma) and the bend (bend_factor z^2).
double planePointVariance(double z, const PlaneRegionGrower::Params& params);

double patchCurvature(const pcl::PointCloud<pcl::PointNormal>& cloud,
                      const std::vector<int>& indices, const Eigen::Vector3d& plane_normal);

}  // namespace quadric_slam
