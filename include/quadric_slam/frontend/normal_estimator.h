// Surface normals of an organized cloud. The default method, box_gradient, is the project's own
// integral-image estimator (frontend/box_gradient_normals.h), four to seven times faster than PCL's
// on a 640x480 frame (bench_normals); PCL's IntegralImageNormalEstimation (Holzer et al. 2012, the
// paper's choice, Section IV) is available through its method names.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>

namespace quadric_slam {

class NormalEstimator {
 public:
  struct Params {
    // box_gradient (own, fast), or one of PCL's integral-image methods: average_3d_gradient,
    // covariance_matrix, average_depth_change, simple_3d_gradient.
    std::string method = "box_gradient";
    // Depth discontinuity threshold: neighbours differing by more than factor * depth are not
    // smoothed across (dimensionless).
    double max_depth_change_factor = 0.02;
    // Smoothing window half-size (pixels of the organized cloud); scaled with depth when
    // depth_dependent_smoothing is set.
    double normal_smoothing_size = 10.0;
    bool depth_dependent_smoothing = true;
    // Worker threads of box_gradient (PCL's methods are single-threaded).
    int threads = 2;
    // box_gradient estimates a normal at every normal_stride-th pixel in u and v and shares it
    // with its block (not across edges): stride^2 less work, blocks far smaller than the
    // smoothing window. 1 = every pixel. [1, 4]
    int normal_stride = 2;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  explicit NormalEstimator(const Params& params);

  // Normals of an organized cloud, oriented towards the sensor origin. The output has the input's
  // size and points; where a normal cannot be estimated (no data, discontinuity, border) its
  // normal and curvature are NaN. Throws std::invalid_argument for an unorganized cloud.
  pcl::PointCloud<pcl::PointNormal> compute(const pcl::PointCloud<pcl::PointXYZ>& cloud) const;
  // The same into out, whose storage is reused when it already has the input's size (a stream of
  // frames then allocates nothing per frame).
  void compute(const pcl::PointCloud<pcl::PointXYZ>& cloud,
               pcl::PointCloud<pcl::PointNormal>& out) const;

  const Params& params() const { return params_; }

 private:
  Params params_;
};

}  // namespace quadric_slam
