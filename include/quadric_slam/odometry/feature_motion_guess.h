// A motion guess between two frames from corner features of their images, lifted to 3D by the
// depth: for steps of tens of centimetres and tens of degrees (a hand-held camera read at 1-3 Hz,
// a busy pipeline that drops frames), beyond ICP's basin, in views the surfaces cannot fix (one
// wall and the floor leave three directions free whatever they are matched to).
//
// ORB corners (OpenCV) on each image, matched by descriptor: the nearest neighbour, kept when it is
// clearly nearer than the second (Lowe's ratio test). Each match is lifted to a pair of 3D points
// by the depth at its pixels; the rigid motion most pairs agree with is found by RANSAC over
// minimal sets of three (Eigen::umeyama). A pair agrees when each corner, moved into the other
// camera, reprojects within a few pixels of its match and its depth along the ray is within the
// depth's noise (growing as z^2 for a disparity sensor; odometry/corner_pair_geometry.h): a 3D
// distance wide enough for that noise let motions 10-20 cm apart agree with the same far corners.
// The consensus is refitted by least squares in 3D, then refined on the reprojection errors and
// depths (Ceres). Nothing here uses a prior: the guess holds for any step the two images still
// share corners over.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "quadric_slam/odometry/corner_pair_geometry.h"
#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// One frame's corners that have a depth: their 3D points (camera frame, m), sub-pixel positions,
// pyramid-level scales and ORB descriptors (one row each, in the same order), and the camera.
struct FeatureFrame {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<double> pixel_scales;
  cv::Mat descriptors;
  CameraIntrinsics intrinsics;
  bool empty() const { return points.empty(); }
};

struct FeatureMotionGuess {
  bool found = false;
  // Pose of the current camera in the reference camera's frame.
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
  int matches = 0;      // descriptor matches that passed the ratio test
  int inliers = 0;      // ... and agree with the motion
  std::string message;  // why nothing was found (empty when found)
  // The matched corners (columns in match order), to judge other poses by them.
  MatchedCorners reference, current;
  // What the agreeing corners say of T_reference_current: the information of its left
  // perturbation (odometry/corner_pair_geometry.h cornerPairInformation).
  Matrix6d information = Matrix6d::Zero();
};

class FeatureMotionGuesser {
 public:
  struct Params {
    // Corners kept per image, the strongest by the Harris score. [50, 20000]
    int max_features = 3000;
    // FAST's intensity threshold (grey levels), [1, 100]. Low: smooth, weakly textured surfaces
    // (painted walls, a carpet) still give corners, and max_features keeps the strongest.
    int fast_threshold = 2;
    // Scale pyramid levels (factor 1.2 each), [1, 16]: a step of tens of centimetres changes the
    // scale of what both images see.
    int pyramid_levels = 8;
    // A match is kept when its descriptor distance is below this share of the second nearest's.
    // (0, 1]
    double match_ratio = 0.8;
    // Corners whose depth lies outside [min_depth, max_depth] (m) are not used. 0 < min < max
    double min_depth = 0.3;
    double max_depth = 6.0;
    // A pair agrees with a motion when each corner, moved into the other camera, reprojects
    // within inlier_pixels (at the corner's pyramid level) of its match, and its depth is within
    // inlier_distance + inlier_distance_per_z2 z^2 (m; z the match's depth) of the match's: the
    // sensor's depth noise grows with z^2. > 0, > 0 and >= 0
    double inlier_pixels = 3.0;
    double inlier_distance = 0.02;
    double inlier_distance_per_z2 = 0.01;
    // RANSAC's minimal sets at most, [1, 100000]; fewer when the inlier share found so far makes
    // a better set unlikely (99 % confidence).
    int ransac_iterations = 300;
    // A guess needs this many inlier pairs ([3, 100000]) and this share of the matches ([0, 1]).
    int min_inliers = 12;
    double min_inlier_fraction = 0.3;
    // The inliers must spread at least this far (m, the standard deviation along their second
    // principal axis, >= 0): corners along one line leave the rotation about it free.
    double min_spread = 0.05;
    void validate() const;  // throws std::invalid_argument naming the field and its range
  };

  FeatureMotionGuesser();
  explicit FeatureMotionGuesser(const Params& params);

  // The corners of an 8-bit grey or colour image (intrinsics' size) that have a depth in depth
  // (metres per pixel, CV_32FC1; 0 or NaN: none), which may be the image decimated by an integer
  // factor (an organized cloud's grid). Throws std::invalid_argument when the sizes do not fit.
  FeatureFrame describe(const cv::Mat& image, const cv::Mat& depth,
                        const CameraIntrinsics& intrinsics);

  // The motion of the current frame in the reference frame's camera.
  FeatureMotionGuess guess(const FeatureFrame& reference, const FeatureFrame& current) const;

  // How many of every stride-th of the current frame's corners pass the ratio test against the
  // reference's: a cheap measure of how much two views share, to choose which to guess between.
  int screenMatches(const FeatureFrame& reference, const FeatureFrame& current, int stride) const;

  // How many of the guess's matched corners agree with T_reference_current (the inlier distance
  // above): a pose from another start judged by the corners.
  int agreeingMatches(const FeatureMotionGuess& guess,
                      const Eigen::Isometry3d& T_reference_current) const;

  const Params& params() const { return params_; }

 private:
  CornerPairGates gates() const;

  Params params_;
  cv::Ptr<cv::ORB> orb_;
  cv::BFMatcher matcher_{cv::NORM_HAMMING};
};

}  // namespace quadric_slam
