// Frame-to-keyframe visual odometry on organized clouds with normals: owns the keyframe, the
// constant-velocity prior and the pose T_odom_camera. The odometry nodelet and offline runners
// both call track() once per frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <deque>
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "quadric_slam/odometry/feature_motion_guess.h"
#include "quadric_slam/odometry/photometric_refinement.h"
#include "quadric_slam/odometry/point_to_plane_icp.h"
#include "quadric_slam/odometry/quadric_motion_guess.h"
#include "quadric_slam/odometry/surface_normals.h"
#include "quadric_slam/types/camera_intrinsics.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

class OdometryTracker {
 public:
  using Cloud = PointToPlaneIcp::Cloud;
  using Matrix6 = Matrix6d;

  struct Params {
    PointToPlaneIcp::Params icp;
    // A new keyframe is taken when the camera has moved more than this from the keyframe (m). > 0
    double keyframe_translation = 0.10;
    // ... or turned more than this (rad). (0, pi]
    double keyframe_rotation = 0.1745;
    // ... or when the inlier fraction (overlap with the keyframe) drops below this. [0, 1]
    // (0.7: fresher keyframes over weakly constrained views; see config/odometry.yaml)
    double keyframe_min_overlap = 0.7;
    // Predict each frame with the last inter-frame motion (scaled by the time step) instead of the
    // last pose.
    bool constant_velocity = true;
    // After this many consecutive lost frames the current frame becomes the keyframe (at the last
    // pose), so tracking can resume. [1, 1000]
    int lost_frames_before_new_keyframe = 3;
    // When the frame's quadric observations are given: guess the motion from the surfaces the frame
    // shares with the keyframe (odometry/quadric_motion_guess.h) and, when the guess differs from
    // the constant-velocity prior by more than guess_min_translation or guess_min_rotation (m, rad,
    // > 0), run ICP from both and keep the better alignment (more inlier correspondences; at equal
    // counts within 2%, the smaller residual).
    bool quadric_motion_guess = true;
    double guess_min_translation = 0.02;
    double guess_min_rotation = 0.035;
    // The guess is not made when ICP from the prior is ok with at least this share of inlier
    // correspondences, (0, 1] (1: always guess). On real frames warped by known motions, ok
    // alignments at a wrong pose (ICP converged short) had 0.44-0.62, right ones 0.76-1.0
    // (0.96 at the 10th percentile): a well-supported alignment needs no second opinion, and the
    // guess and its extra ICP cost time on every frame.
    double guess_skip_inlier_fraction = 0.9;
    QuadricMotionGuesser::Params guess;
    // When track() is given the frame's image: guess the motion from the corners the frame shares
    // with the keyframe too (odometry/feature_motion_guess.h), under the same skip rule, and run
    // ICP from it when it differs from the best alignment so far; the better alignment is kept,
    // and a degenerate one is refined by the intensities from the guess as well. A hand-held
    // camera read at 1.5 Hz turns 10-40 degrees a step, where neither the prior nor the surfaces
    // of a wall-and-floor view start ICP in its basin.
    bool feature_motion_guess = false;
    FeatureMotionGuesser::Params features;
    // ... made only when every alignment is lost or the frame comes at least this long after the
    // previous one (s, >= 0; 0: under the skip rule on every frame): between frames 33 ms apart a
    // degenerate step is within the intensities' basin, and the corners cost 15-30 ms a frame.
    double feature_min_interval = 0.1;
    // When the keyframe's corners give no guess (a turn of 40-60 degrees between frames leaves
    // them few), or every alignment to the keyframe is lost, the corners of up to this many
    // earlier keyframes (those whose corners were made, newest first) are tried, [0, 1000]; 0:
    // none. A hand-held camera that swings away and back shares more with a keyframe of a second
    // ago than with the last one. ICP to the keyframe then starts from that guess; when it finds
    // no overlap the frame is placed by the corners alone (status degenerate, covariance
    // feature_pose_sigma_translation / _rotation, m / rad, > 0) and becomes the keyframe, instead
    // of being lost.
    int feature_history_keyframes = 0;
    double feature_pose_sigma_translation = 0.02;
    double feature_pose_sigma_rotation = 0.02;
    // A corners' guess that moves the camera from its last pose faster than feature_max_speed
    // (m/s, > 0) or feature_max_turn_rate (rad/s, > 0) over the time since the last frame (at
    // least 0.1 m / 0.2 rad) is refused: rooms repeat their surfaces' texture, and the corners of
    // one wall matched to another agree on a turn of 90 degrees. Placing a frame by the corners
    // alone also needs twice min_inliers agreeing, half of the matches.
    double feature_max_speed = 1.5;
    double feature_max_turn_rate = 2.0;
    // Where a strong corners' guess was made (a step of feature_min_interval or more), the
    // alignment's pose and the corners' are fused, each weighed by its information. ICP's
    // covariance (from its residuals) misses the bias between views far apart: the depth's
    // low-frequency distortion differs with the image position, about a centimetre at 3 m on a
    // Kinect v1, so feature_fusion_icp_bias_per_z2 z^2 (m; z the frame's median depth, m) is added
    // to its translation's standard deviation, and that over z to its rotation's. The corners'
    // (from their reprojections and depths) is floored at feature_fusion_corner_floor (m; over z
    // for the rotation). [0, inf) 1/m and (0, inf) m.
    double feature_fusion_icp_bias_per_z2 = 0.002;
    double feature_fusion_corner_floor = 0.003;
    // The ICP's normals from the frame's fitted surfaces (odometry/surface_normals.h): track()
    // does not change its cloud, so the caller calls adoptSurfaceNormals() before it (QuadricSlam
    // and the odometry nodelet do).
    SurfaceNormalParams surface_normals;
    // No runaway: when the constant-velocity prediction is more than guess_min_translation or
    // guess_min_rotation from the last pose, ICP also starts from the last pose (zero motion) and
    // the better alignment is kept, so a velocity the data do not confirm cannot carry the
    // estimate on. The velocity itself is only kept after a step that is ok (all six directions
    // constrained and the alignment accepted); after a degenerate or lost step the prior is the
    // last pose.
    bool zero_motion_start = true;
    // After a degenerate step the prior keeps the last confirmed (ok) velocity while it is at most
    // this old (s), along the directions the data could not constrain too; older, or after a lost
    // step, the prior is the last pose. [0, 10]; 0: the last pose after every degenerate step.
    double velocity_hold_time = 0.0;
    // An ok step sets the velocity only when the information along its weakest direction is at
    // least this many times what the keyframe normals' noise explains
    // (PointToPlaneIcp::Result::information_over_noise); a step that passes the degeneracy test
    // only just (a floor and a surface at an angle to it, held apart along their common line by
    // an edge) is kept but, like a degenerate one, leaves the last confirmed velocity in place: its
    // error along that line must not be carried into the next frames by the prior. [0, 1000];
    // 0: every ok step.
    double velocity_min_information = 0.0;
    // The increment covariance (Result::increment_covariance) is ICP's sigma^2 H^-1 part times
    // increment_covariance_scale, (0, 1e6]: H^-1 counts every depth pixel as an independent
    // measurement, but real depth noise is correlated over neighbouring pixels and the
    // point-to-plane model is not exact, so the raw figure is over-confident. To it is added, on
    // each axis, the variance of an error that grows with the step: increment_translation_fraction
    // (m per m of step, >= 0) on the translation and increment_rotation_per_metre (rad per m of
    // step, >= 0) on the rotation (the alignment of a longer step ends further from the truth).
    // Calibrated on the real kitchen and a generated sequence: config/odometry.yaml.
    double increment_covariance_scale = 4.0;
    double increment_translation_fraction = 0.05;
    double increment_rotation_per_metre = 0.05;
    // When track() is given the frame's image (registered to the depth): a degenerate alignment is
    // refined by the intensities (odometry/photometric_refinement.h) jointly with the depth: the
    // intensities' residuals over all six directions and, as a prior, the depth's information on
    // the directions it measured. The depth's covariance there is floored by
    // photometric_depth_floor_translation (m, > 0) and photometric_depth_floor_rotation (rad,
    // > 0): a surface's tilt and distance carry the sensor's systematic error, which the
    // alignment's own covariance does not know (on a real desk top alone the depth's tilt was
    // 0.5-1 degree off, and refining only the free directions around it left 13 mm of error;
    // jointly, 4 mm). The intensities' information is taken times photometric_information_scale,
    // (0, 1]: the pixels' errors are correlated and the brightness is not constant, so the raw
    // figure is over-confident. Such a step stays degenerate but, when refined, sets the velocity
    // of the prior like an ok one.
    bool photometric_refinement = false;
    PhotometricRefinement::Params photometric;
    double photometric_information_scale = 0.1;
    double photometric_depth_floor_translation = 0.003;
    double photometric_depth_floor_rotation = 0.005;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Result {
    Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();
    // Covariance of (dx, dy, dz, rx, ry, rz): the position error and the small rotation error
    // R_true = exp(r^) R, both in the odom frame (nav_msgs/Odometry pose covariance order).
    Matrix6 covariance = Matrix6::Zero();
    // The step from the previous frame's reported pose to this one, T_previous_this =
    // T_odom_previous^-1 T_odom_camera (identity for the first frame and a lost frame), and the
    // covariance of its right perturbation T_true = T_previous_this exp(xi^), xi = [rho; phi] in
    // this frame's body tangent (m, rad): the convention of the mapper's OdometryInput. Not
    // cumulative: the increments of consecutive frames are (conservatively, see track()) treated
    // as independent, so a consumer that skips frames composes the skipped increments into the
    // next one (QuadricSlam does). The first frame and a lost frame: degenerate_variance on every
    // direction (the motion is unknown); a degenerate frame: degenerate_variance along the
    // directions ICP could not constrain.
    Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
    Matrix6 increment_covariance = Matrix6::Zero();
    TrackingStatus status = TrackingStatus::kLost;
    bool new_keyframe = false;           // this frame became the keyframe
    int consecutive_lost = 0;            // lost frames in a row, this one included
    PointToPlaneIcp::Result icp;         // details of the alignment (empty for the first frame)
    QuadricMotionGuess guess;            // the surfaces' motion guess (found = false when not made)
    bool started_from_guess = false;     // ICP's result came from the guess, not the prior
    FeatureMotionGuess feature_guess;    // the corners' motion guess (found = false when not made)
    bool started_from_features = false;  // ICP's result came from the corners' guess
    // The corners' guess came from an earlier keyframe (feature_history_keyframes), this many
    // keyframes back (0: the current keyframe's); placed_by_features: no alignment to the keyframe
    // held, the pose is the corners' alone.
    int feature_keyframes_back = 0;
    bool placed_by_features = false;
    bool started_from_last_pose = false;  // ... from the last pose (zero motion), not the prior
    // The constant-velocity prior's prediction of this frame's pose (the last pose when no
    // confirmed velocity is held; identity for the first frame).
    Eigen::Isometry3d T_odom_predicted = Eigen::Isometry3d::Identity();
    // The intensities' refinement of a degenerate alignment (refined = false when not made).
    PhotometricRefinement::Result photometric;
  };

  explicit OdometryTracker(const Params& params);

  // Tracks one organized cloud with normals (camera frame) taken at stamp (s). intrinsics are those
  // of the full-resolution image the cloud was made from (it may be decimated). The first usable
  // frame defines the odom frame (T_odom_camera = identity). Throws std::invalid_argument only when
  // the cloud's size does not fit the intrinsics; bad data otherwise gives status lost.
  // observations: the frame's quadric observations (camera frame), for the motion guess; nullptr
  // tracks from the constant-velocity prior alone.
  // image: the frame's 8-bit grey or colour image registered to the depth at the intrinsics'
  // size, for Params::photometric_refinement (nullptr, or another size: depth alone).
  Result track(const Cloud& cloud, const CameraIntrinsics& intrinsics, double stamp,
               const std::vector<QuadricMeasurement>* observations = nullptr,
               const cv::Mat* image = nullptr);

  // Gives the points of cloud that lie on the frame's observed surfaces the surfaces' normals
  // (Params::surface_normals; odometry/surface_normals.h), on the grid the ICP reads (every
  // gcd(reference_stride, finest_stride)-th point). Call it before track() with the same
  // observations. Returns the number of normals replaced.
  int adoptSurfaceNormals(const std::vector<QuadricMeasurement>& observations, Cloud& cloud);

  // Forgets the keyframe, pose and velocity: the next usable frame starts a new odom frame.
  void reset();

  bool initialized() const { return initialized_; }
  const Eigen::Isometry3d& pose() const { return T_odom_camera_; }
  const Params& params() const { return params_; }

 private:
  // intensity: the frame's pyramid (moved into the keyframe's; empty when none). features: the
  // frame's corners when they were made (moved into the keyframe's), else nullptr and, with
  // feature_image (the frame's image, nullptr when none), the image and depth are kept to make
  // the keyframe's corners when first needed.
  void setKeyframe(const Cloud& cloud, const CameraIntrinsics& intrinsics,
                   const std::vector<QuadricMeasurement>* observations, IntensityPyramid& intensity,
                   const cv::Mat* feature_image = nullptr, FeatureFrame* features = nullptr);
  // The keyframe's corners (made from the kept image on the first call); nullptr when the
  // keyframe came without an image.
  const FeatureFrame* keyframeFeatures();
  // Refines a degenerate alignment by the intensities jointly with the depth (Params::
  // photometric_refinement); track() calls it only with both pyramids (the frame's and the
  // keyframe's). Returns whether the pose changed.
  bool refinePhotometrically(const Cloud& cloud, const CameraIntrinsics& intrinsics,
                             const IntensityPyramid& intensity, PointToPlaneIcp::Result& icp,
                             PhotometricRefinement::Result& out) const;
  // ICP from the prior, from the last pose and from the surfaces' and the corners' guesses when
  // they differ from the prior; the best of them. frame_features: the frame's corners, made when
  // first asked for (nullptr when the frame has no image for them).
  PointToPlaneIcp::Result alignFromBestStart(const Cloud& cloud,
                                             const Eigen::Isometry3d& T_keyframe_prior,
                                             const Eigen::Isometry3d& T_keyframe_last,
                                             const std::vector<QuadricMeasurement>* observations,
                                             const std::function<FeatureFrame*()>& frame_features,
                                             Result& out);
  // The corners of earlier keyframes (feature_history_keyframes) when the keyframe's gave no
  // guess or a weak one, or every alignment is lost: screened with a sample of the frame's
  // corners, the few sharing the most are asked, and ICP runs from the guess with the most
  // agreeing matches within the camera's speed (when it has more than the keyframe's); kept when
  // its corners agree with it better than with best and it keeps half of a strong guess's; when
  // no alignment does and the guess is strong, the frame is placed by the corners alone.
  void alignFromEarlierKeyframes(const Cloud& cloud,
                                 const std::function<FeatureFrame*()>& frame_features,
                                 PointToPlaneIcp::Result& best, Result& out);
  // The alignment's pose T_keyframe_current fused with a strong corners' guess (made against the
  // keyframe T_corners_keyframe relates to, cornersReferenceFromKeyframe), each by its information
  // (Params::feature_fusion_*); depth: the frame's median depth (m).
  Eigen::Isometry3d fusedWithCorners(const PointToPlaneIcp::Result& icp,
                                     const FeatureMotionGuess& corners,
                                     const Eigen::Isometry3d& T_corners_keyframe,
                                     double depth) const;
  // A degenerate alignment at the corners' pose, with the feature_pose_sigma_* covariance.
  PointToPlaneIcp::Result placedByCorners(const Eigen::Isometry3d& T_keyframe_current,
                                          int keyframes_back) const;
  // T_reference_keyframe for the keyframe whose corners made out.feature_guess (identity for the
  // keyframe's own; an earlier keyframe's, feature_keyframes_back, in the odometry chain).
  Eigen::Isometry3d cornersReferenceFromKeyframe(const Result& out) const;
  // Enough of the guess's matches agree (kPlacementInlierFactor x min_inliers, and
  // kPlacementInlierShare of the matches) to place a frame by it alone, or to stand without
  // asking the earlier keyframes.
  bool strongGuess(const FeatureMotionGuess& guess) const;
  // The corners' guess T_keyframe_current is within the camera's speed from its last pose over
  // step_dt_ (feature_max_speed, feature_max_turn_rate).
  bool withinCameraSpeed(const Eigen::Isometry3d& T_keyframe_current) const;
  // The two starts are further apart than guess_min_translation or guess_min_rotation.
  bool startsElsewhere(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) const;
  Result output(TrackingStatus status, bool new_keyframe) const;
  // Covariance of the right perturbation of T_keyframe_current (current body tangent) from ICP's
  // left-perturbation covariance in the keyframe frame (uncalibrated).
  Matrix6 keyframeRelativeCovariance(const PointToPlaneIcp::Result& icp) const;

  Params params_;
  PointToPlaneIcp icp_;
  QuadricMotionGuesser guesser_;
  FeatureMotionGuesser feature_guesser_;
  // The keyframe's corners, or (until they are first needed) its image and depth to make them.
  FeatureFrame keyframe_features_;
  cv::Mat keyframe_image_, keyframe_depth_;
  CameraIntrinsics keyframe_intrinsics_;
  // Earlier keyframes' corners and poses (feature_history_keyframes), oldest first.
  struct PastKeyframe {
    FeatureFrame features;
    Eigen::Isometry3d T_odom_keyframe;
  };
  std::deque<PastKeyframe> feature_history_;
  double step_dt_ = 0;  // the time since the last frame (s), for withinCameraSpeed()
  PhotometricRefinement photometric_;
  IntensityPyramid keyframe_intensity_;          // empty when the keyframe came without an image
  SurfaceNormalScratch surface_normal_scratch_;  // adoptSurfaceNormals' buffers, kept
  // The keyframe's observations without their supporting points (empty when none were given).
  std::vector<QuadricMeasurement> keyframe_observations_;
  bool initialized_ = false;
  Eigen::Isometry3d T_odom_keyframe_ = Eigen::Isometry3d::Identity();
  Matrix6 keyframe_covariance_ = Matrix6::Zero();  // left perturbation in odom, (v, omega)
  Eigen::Isometry3d T_odom_camera_ = Eigen::Isometry3d::Identity();
  Matrix6 covariance_ = Matrix6::Zero();  // left perturbation in odom, (v, omega)
  // Covariance of the reported pose relative to the keyframe, T_keyframe_camera (right
  // perturbation, body tangent): zero when the reported pose is the keyframe's.
  Matrix6 keyframe_relative_covariance_ = Matrix6::Zero();
  // The velocity of the prior: T_prev_cur of the last ok step, its time span (0: none) and stamp.
  Eigen::Isometry3d last_motion_ = Eigen::Isometry3d::Identity();
  double velocity_dt_ = 0;
  double velocity_stamp_ = 0;
  double last_stamp_ = 0;
  int consecutive_lost_ = 0;
};

}  // namespace quadric_slam
