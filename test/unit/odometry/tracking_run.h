// Test support: runs OdometryTracker over a frame source the way the offline pipeline does
// (back-projection, normals, quadric segmentation for the motion guess, tracking) and records per
// processed frame the tracker's status and alignment statistics beside the error of its step
// against the ground truth. The tests of honest status read these records; with the environment
// variable QS_TRACKING_CSV_DIR set they are also written to <dir>/<name>.csv, from which the
// thresholds of config/odometry.yaml were chosen.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/frontend/detection_measurement.h"
#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/sim/trajectory.h"

namespace quadric_slam {
namespace test {

struct TrackedFrame {
  double stamp = 0;
  TrackingStatus status = TrackingStatus::kLost;
  bool new_keyframe = false;
  bool from_guess = false, from_last_pose = false;
  int candidate_points = 0, projected_points = 0, correspondences = 0;
  double inlier_fraction = 0, overlap_inlier_fraction = 0, overlap_near_fraction = 0,
         rms_residual = 0, eigenvalue_ratio = 0, information_over_noise = 0;
  int constrained_dof = 0;
  // The step from the last frame whose pose the tracker stands by (not lost, or a new keyframe)
  // to this one: true size and the estimate's error against the truth.
  double true_step_m = 0, true_step_deg = 0;
  double step_error_m = 0, step_error_deg = 0;
  // The step's error against the truth in the tracker's increment convention (T_true = T_est
  // exp(xi^), body tangent [rho; phi]) and its squared Mahalanobis distance under the reported
  // increment covariance (NEES; chi-square with 6 degrees of freedom when the covariance is right:
  // median 5.35). Zero for the first frame.
  Vector6d increment_error = Vector6d::Zero();
  double increment_nees = 0;
  // Root of the reported increment variance's translation and rotation traces (m, degrees).
  double increment_sigma_t_m = 0, increment_sigma_r_deg = 0;
};

struct TrackingRun {
  std::vector<TrackedFrame> frames;
  Trajectory estimate;  // T_odom_camera of every processed frame once initialised
  int ok = 0, degenerate = 0, lost = 0;

  // Largest step error among the frames reported ok (m, degrees).
  double worstOkTranslation() const {
    double worst = 0;
    for (const TrackedFrame& f : frames)
      if (f.status == TrackingStatus::kOk)
        worst = std::max(worst, f.step_error_m);
    return worst;
  }
  double worstOkRotationDeg() const {
    double worst = 0;
    for (const TrackedFrame& f : frames)
      if (f.status == TrackingStatus::kOk)
        worst = std::max(worst, f.step_error_deg);
    return worst;
  }
};

inline double rotationDegrees(const Eigen::Isometry3d& T) {
  return Eigen::AngleAxisd(T.rotation()).angle() * 180.0 / M_PI;
}

inline void writeTrackingCsv(const TrackingRun& run, const std::string& name) {
  const char* dir = std::getenv("QS_TRACKING_CSV_DIR");
  if (!dir || !*dir)
    return;
  std::ofstream csv(std::string(dir) + "/" + name + ".csv");
  csv << "stamp,status,new_keyframe,from_guess,from_last_pose,candidate_points,projected_points,"
         "correspondences,inlier_fraction,overlap_inlier_fraction,overlap_near_fraction,rms_"
         "residual,eigenvalue_ratio,information_over_noise,constrained_dof,"
         "true_step_m,true_step_deg,step_error_m,step_error_deg,increment_nees,"
         "increment_sigma_t_m,increment_sigma_r_deg\n";
  for (const TrackedFrame& f : run.frames) {
    csv << std::fixed << f.stamp << ',' << toString(f.status) << ',' << f.new_keyframe << ','
        << f.from_guess << ',' << f.from_last_pose << ',' << f.candidate_points << ','
        << f.projected_points << ',' << f.correspondences << ',' << f.inlier_fraction << ','
        << f.overlap_inlier_fraction << ',' << f.overlap_near_fraction << ',' << f.rms_residual
        << ',' << f.eigenvalue_ratio << ',' << f.information_over_noise << ',' << f.constrained_dof
        << ',' << f.true_step_m << ',' << f.true_step_deg << ',' << f.step_error_m << ','
        << f.step_error_deg << ',' << f.increment_nees << ',' << f.increment_sigma_t_m << ','
        << f.increment_sigma_r_deg << '\n';
  }
}

// Tracks every `every`-th frame of `source` (at most max_frames of them) with the stages and
// parameters of `params` (segmentation only for the motion guess; the frames' images, when the
// source has them, for the corners' guess and the photometric refinement). `truth`: T_world_camera,
// interpolated at each frame's stamp.
inline TrackingRun runTracker(FrameSource& source, const Trajectory& truth,
                              const SlamParams& params, int every, int max_frames) {
  const NormalEstimator normals(params.normals);
  const QuadricSegmenter segmenter(params.segmentation);
  OdometryTracker tracker(params.odometry);
  TrackingRun run;
  RgbdFrame frame;
  pcl::PointCloud<pcl::PointNormal> cloud;
  Eigen::Isometry3d est_reference = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d true_reference = Eigen::Isometry3d::Identity();
  bool have_reference = false;
  for (long index = 0; static_cast<int>(run.frames.size()) < max_frames && source.next(frame);
       ++index) {
    if (index % every != 0)
      continue;
    normals.compute(
        backProject(depthViewOf(frame.depth_m), frame.intrinsics, params.back_projection), cloud);
    const FrameMeasurements measurements =
        toFrameMeasurements(segmenter.segment(cloud), frame.stamp, frame.frame_id);
    tracker.adoptSurfaceNormals(measurements.observations, cloud);  // as QuadricSlam does
    // The frame's image when the source renders one (the corners' guess and the intensities).
    const OdometryTracker::Result result =
        tracker.track(cloud, frame.intrinsics, frame.stamp, &measurements.observations,
                      frame.rgb.empty() ? nullptr : &frame.rgb);
    TrackedFrame f;
    f.stamp = frame.stamp;
    f.status = result.status;
    f.new_keyframe = result.new_keyframe;
    f.from_guess = result.started_from_guess;
    f.from_last_pose = result.started_from_last_pose;
    f.candidate_points = result.icp.candidate_points;
    f.projected_points = result.icp.projected_points;
    f.correspondences = result.icp.correspondences;
    f.inlier_fraction = result.icp.inlier_fraction;
    f.overlap_inlier_fraction = result.icp.overlap_inlier_fraction;
    f.overlap_near_fraction = result.icp.overlap_near_fraction;
    f.rms_residual = result.icp.rms_residual;
    f.eigenvalue_ratio = result.icp.eigenvalue_ratio;
    f.information_over_noise = result.icp.information_over_noise;
    f.constrained_dof = result.icp.constrained_dof;
    ++(result.status == TrackingStatus::kOk           ? run.ok
       : result.status == TrackingStatus::kDegenerate ? run.degenerate
                                                      : run.lost);
    if (tracker.initialized()) {
      const Eigen::Isometry3d true_pose = interpolatePose(truth, frame.stamp);
      run.estimate.push_back({frame.stamp, result.T_odom_camera});
      if (have_reference) {
        const Eigen::Isometry3d est_step = est_reference.inverse() * result.T_odom_camera;
        const Eigen::Isometry3d true_step = true_reference.inverse() * true_pose;
        const Eigen::Isometry3d error = est_step.inverse() * true_step;
        f.true_step_m = true_step.translation().norm();
        f.true_step_deg = rotationDegrees(true_step);
        f.step_error_m = error.translation().norm();
        f.step_error_deg = rotationDegrees(error);
        f.increment_error = logSE3(error);
        const Matrix6d& covariance = result.increment_covariance;
        f.increment_nees = f.increment_error.dot(covariance.ldlt().solve(f.increment_error));
        f.increment_sigma_t_m = std::sqrt(covariance.topLeftCorner<3, 3>().trace());
        f.increment_sigma_r_deg =
            std::sqrt(covariance.bottomRightCorner<3, 3>().trace()) * 180.0 / M_PI;
      }
      if (result.status != TrackingStatus::kLost || result.new_keyframe) {
        est_reference = result.T_odom_camera;
        true_reference = true_pose;
        have_reference = true;
      }
    }
    run.frames.push_back(f);
  }
  return run;
}

// ATE RMSE (m) of the run's estimate against the truth (rigid alignment, as evaluate_ate.py).
inline double ateRmse(const TrackingRun& run, const Trajectory& truth) {
  return AbsoluteTrajectoryError().evaluate(truth, run.estimate).rmse();
}

}  // namespace test
}  // namespace quadric_slam
