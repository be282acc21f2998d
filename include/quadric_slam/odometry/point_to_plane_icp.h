// Point-to-plane ICP between two organized clouds with normals: projective data association into
// the reference's image grid, coarse-to-fine over subsampled pyramid levels, distance and
// normal-angle gates, Huber weights and Gauss-Newton on SE(3), with degeneracy detection.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "quadric_slam/odometry/pose_math.h"
#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// Outcome of one tracking step.
enum class TrackingStatus {
  kOk,          // all six degrees of freedom constrained by the data
  kDegenerate,  // some directions unconstrained (e.g. a single plane): those keep the prior
  kLost,        // too few correspondences or an implausible result: the prior is returned
};
const char* toString(TrackingStatus status);

// Decimation factor d of an organized cloud made from an image of the intrinsics' size (as
// backProject does: width / d x height / d). Returns 0 and sets *problem when they do not fit.
int organizedCloudDecimation(const CameraIntrinsics& intrinsics, int cloud_width, int cloud_height,
                             std::string* problem);

class PointToPlaneIcp {
 public:
  using Cloud = pcl::PointCloud<pcl::PointNormal>;
  using Matrix6 = Matrix6d;
  using Vector6 = Vector6d;

  struct Params {
    // Pyramid levels; level l samples every (finest_stride * 2^l)-th point of the current cloud in
    // u and v, and runs before level l - 1 (coarse to fine). [1, 6]
    int pyramid_levels = 3;
    // Sampling step of the current cloud at the finest level (cloud pixels). [1, 32]
    int finest_stride = 4;
    // The reference keeps every n-th point in u and v, packed (24 bytes a point) so that it stays
    // in cache: 2 turns a 640 x 480 keyframe into 1.8 MB. Projective association picks the nearest
    // kept point; point-to-plane residuals hardly depend on which point of the plane it is. [1, 16]
    int reference_stride = 2;
    // Gauss-Newton iterations at most per level. [1, 100]
    int max_iterations = 10;
    // Distance gate between a transformed current point and its reference point at the finest
    // level (m); level l uses max_correspondence_distance * coarse_distance_factor^l. (0, 10]
    double max_correspondence_distance = 0.05;
    double coarse_distance_factor = 2.0;  // [1, 10]
    // Beyond this depth of the keyframe point the distance gate grows as (z / gate_growth_depth)^2,
    // as the structured-light depth noise does: at 4-4.5 m (noise sigma 3-5 cm) a fixed 5 cm gate
    // let only part of a wall's correct correspondences through, so the far walls could not hold
    // the pose. Nearer points keep max_correspondence_distance. (0, 100] m
    double gate_growth_depth = 2.0;
    // Normal-angle gate between the rotated current normal and the reference normal (rad). (0, pi]
    double max_normal_angle = 0.5236;
    // Weight residuals by the depth-noise model of structured-light sensors, sigma(z) ~ z^2
    // (Khoshelham & Elberink 2012): residuals are divided by (z / 1 m)^2 of the reference point,
    // z clamped to at least 0.5 m. Off: every correspondence has the same weight.
    bool depth_noise_weighting = true;
    // Huber threshold on the (depth-normalised, when depth_noise_weighting) point-to-plane
    // residual (m at 1 m depth). (0, 1]
    double huber_delta = 0.005;
    // Convergence: stop the finest level when the update is below both (m, rad); level l uses
    // 4^l times these (it has 4^l times fewer points). > 0
    double convergence_translation = 1e-4;
    double convergence_rotation = 1e-4;
    // Fewer inlier correspondences than this at the finest level means lost (coarse levels need
    // min_correspondences / 4^l, at least 12). [6, 1e7]
    int min_correspondences = 200;
    // A direction of H whose eigenvalue is below min_eigenvalue_ratio * largest eigenvalue is
    // unconstrained: the update leaves it at the prior and the status is degenerate. (0, 1)
    double min_eigenvalue_ratio = 1e-3;
    // A direction is also unconstrained when H's information along it is at most
    // noise_information_factor times what the keyframe normals' noise alone puts there
    // (odometry/constrained_directions.h). That noise part is estimated at each correspondence
    // from the disagreement of its two normals (the keyframe's and the rotated current one: two
    // independent noisy estimates of one surface; half their squared difference is one normal's
    // noise). Far planes (normal noise of 15-25 degrees at 3-4.5 m on a Kinect v1) then no longer
    // hold the pose along themselves. [0, 1000]; 0: the eigenvalue-ratio test alone.
    double noise_information_factor = 3.0;
    // Only keyframe points at least this deep (m) add to that noise part. Nearer, the normal
    // estimator's window (growing with the depth up to 2 m) keeps the normals' noise small, and two
    // normals of one surface disagree mostly where the views differ (curved surfaces, edges, other
    // pixels after a large step), which is geometry, not noise. [0, 100]
    double noise_information_min_depth = 1.5;
    // Variance given to unconstrained directions in the covariance (m^2 or rad^2). > 0
    double degenerate_variance = 1.0;
    // A result further than this from the initial guess is implausible: lost (m, rad). > 0
    double max_translation_from_guess = 0.3;
    double max_rotation_from_guess = 0.5;
    // Honest status: an alignment is wrong (lost) when, at the finest level, fewer than this share
    // of the current points that land on a keyframe point pass the distance gate
    // (Result::overlap_near_fraction): a pose that is off by more than the gate leaves whole
    // surfaces outside it even where the views overlap. (Not the normal gate: far walls' normals
    // are too noisy to pass it, right or wrong: 0.6-0.7 of the points of right steps at 3-4.5 m.)
    // Right steps (error < 3 cm / 3 deg) had at least 0.91 on the real 7-Scenes kitchen (full rate,
    // every 10th and every 20th frame) and 0.89 on generated fr1_desk / fr1_room sequences taken at
    // 3 and 1.5 Hz; of the wrong steps there (> 5 cm or 5 deg), 14 of 75 were below 0.7 (the rest,
    // sliding along a plane, keep their points near it). [0, 1]; 0 disables.
    double min_overlap_inlier_fraction = 0.7;
    // ... or when the depth-normalised RMS point-to-plane residual of the inliers exceeds this (m
    // at 1 m depth when depth_noise_weighting). (0, 1]; 1 disables. Right steps on the kitchen and
    // the generated fr1 sequences stayed below 0.0032.
    double max_rms_residual = 0.005;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Result {
    Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
    // Covariance of the left perturbation xi = (v, omega) in the reference frame,
    // T = exp(xi^) T_hat: sigma^2 H^-1 with sigma^2 the weighted residual variance.
    Matrix6 covariance = Matrix6::Identity();
    TrackingStatus status = TrackingStatus::kLost;
    int candidate_points = 0;  // usable sampled current points at the finest level
    // Sampled current points that land on a keyframe point with a normal at the finest level (the
    // overlap of the two views), whether or not they pass the gates.
    int projected_points = 0;
    int correspondences = 0;  // inliers at the finest level
    double inlier_fraction = 0;
    double overlap_inlier_fraction = 0;  // correspondences / projected_points
    // Share of projected_points within the distance gate (whatever their normals).
    double overlap_near_fraction = 0;
    double rms_residual = 0;  // point-to-plane RMS at the finest level (m; depth-normalised to
                              // 1 m when depth_noise_weighting)
    int iterations = 0;       // Gauss-Newton iterations over all levels
    int constrained_dof = 0;  // 6 unless degenerate
    // Smallest over largest eigenvalue of H at the finest level (1: evenly constrained, 0: a free
    // direction); compared with Params::min_eigenvalue_ratio.
    double eigenvalue_ratio = 0;
    // The smallest ratio, over all directions, of H's information to the part of it the keyframe
    // normals' noise explains (about 1 where the noise explains all of it); compared with
    // Params::noise_information_factor.
    double information_over_noise = 0;
    std::string message;  // why the status is not ok (empty when ok)
  };

  explicit PointToPlaneIcp(const Params& params);

  // Sets the reference (keyframe): an organized cloud in its camera frame, and the intrinsics of
  // the full-resolution image it came from (the cloud may be decimated by an integer factor).
  // Copies what it needs (every reference_stride-th point, packed). Throws std::invalid_argument
  // when the sizes do not fit.
  void setReference(const Cloud& reference, const CameraIntrinsics& intrinsics);
  bool hasReference() const { return has_reference_; }
  void clearReference() { has_reference_ = false; }

  // Aligns an organized current cloud to the reference, starting from T_reference_current_guess
  // (the prior). Never throws on bad data: an empty or unusable cloud gives status lost.
  Result align(const Cloud& current, const Eigen::Isometry3d& T_reference_current_guess);

  // Number of points align() would sample at the finest level (finite point and normal).
  int usablePoints(const Cloud& current) const;

  const Params& params() const { return params_; }

 private:
  struct Sample {
    Eigen::Vector3f p, n;
    int grid_u, grid_v;  // position in the finest sampling grid
  };
  struct RefPoint {
    float x, y, z, nx, ny, nz;  // z NaN where the reference has no point or no normal
  };
  struct Normals {
    Matrix6 H;
    Matrix6 noise;  // expected contribution of the keyframe normals' noise to H
    Vector6 b;
    double weighted_sq = 0;
    int count = 0;
    int projected = 0;  // samples landing on a reference point (before the gates)
    int near = 0;       // ... of which pass the distance gate
  };
  void sampleFinest(const Cloud& current);
  void selectLevel(int level);
  void accumulate(const Eigen::Isometry3d& T, double max_distance, Normals& eq) const;

  Params params_;
  double cos_max_normal_angle_;
  bool has_reference_ = false;
  std::vector<RefPoint> reference_;  // packed reference grid, row-major
  int ref_w_ = 0, ref_h_ = 0;
  float fx_ = 0, fy_ = 0, cx_ = 0, cy_ = 0;  // intrinsics in reference grid cells
  // Buffers reused between calls (no allocation per iteration, none per frame once warm).
  std::vector<Sample> finest_samples_, samples_;
};

}  // namespace quadric_slam
