#include "quadric_slam/odometry/odometry_tracker.h"

#include "quadric_slam/odometry/alignment_choice.h"
#include "quadric_slam/types/param_checks.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace quadric_slam {
namespace {

// ICP puts degenerate_variance along the directions it could not constrain; sigma^2 H^-1 on the
// others is orders of magnitude smaller, so any fraction between them finds the same free ones.
constexpr double kFreeVarianceFraction = 0.5;
// The camera-speed bound on the corners' guesses is at least this (m, rad): a frame's stamp may
// be jittered, and at 30 Hz the bound itself would be a few centimetres.
constexpr double kMinSpeedBoundTranslation = 0.1;
constexpr double kMinSpeedBoundRotation = 0.2;
// Placing a frame by the corners alone needs this many times min_inliers, and this share of the
// matches, agreeing.
constexpr int kPlacementInlierFactor = 2;
constexpr double kPlacementInlierShare = 0.5;
// Earlier keyframes are screened with every kHistoryScreenStride-th corner of the frame; those
// with at least kHistoryScreenMinMatches matches, at most kHistoryKeyframesGuessed of them (the
// most matched), are asked for a full guess.
constexpr int kHistoryScreenStride = 16;
constexpr int kHistoryScreenMinMatches = 3;
constexpr int kHistoryKeyframesGuessed = 3;
// A degenerate pose must keep this share of the keyframe's corners' agreeing matches.
constexpr double kCornerAgreementShare = 0.5;

// The organized cloud's depths (m; 0 where none), for lifting image corners to 3D.
cv::Mat depthOf(const OdometryTracker::Cloud& cloud) {
  cv::Mat depth(static_cast<int>(cloud.height), static_cast<int>(cloud.width), CV_32FC1);
  float* out = depth.ptr<float>();
  for (const auto& p : cloud.points)
    *out++ = std::isfinite(p.z) ? p.z : 0.0f;
  return depth;
}

// The median depth of a sample of the cloud's points (m; 1 when it has none).
double medianDepth(const OdometryTracker::Cloud& cloud) {
  constexpr size_t kStride = 16;
  std::vector<float> depths;
  for (size_t i = 0; i < cloud.points.size(); i += kStride)
    if (std::isfinite(cloud.points[i].z) && cloud.points[i].z > 0)
      depths.push_back(cloud.points[i].z);
  if (depths.empty())
    return 1.0;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  return depths[depths.size() / 2];
}

bool usableImage(const cv::Mat* image, const CameraIntrinsics& intrinsics) {
  return image && !image->empty() && image->cols == intrinsics.width &&
         image->rows == intrinsics.height && (image->type() == CV_8UC1 || image->type() == CV_8UC3);
}

}  // namespace

void OdometryTracker::Params::validate() const {
  icp.validate();
  const ParamRangeCheck check("OdometryTracker::Params");
  if (!(keyframe_translation > 0 && std::isfinite(keyframe_translation)))
    check.fail("keyframe_translation", "(0, inf) m", keyframe_translation);
  if (!(keyframe_rotation > 0 && keyframe_rotation <= M_PI))
    check.fail("keyframe_rotation", "(0, pi] rad", keyframe_rotation);
  if (!(keyframe_min_overlap >= 0 && keyframe_min_overlap <= 1))
    check.fail("keyframe_min_overlap", "[0, 1]", keyframe_min_overlap);
  if (lost_frames_before_new_keyframe < 1 || lost_frames_before_new_keyframe > 1000)
    check.fail("lost_frames_before_new_keyframe", "[1, 1000]", lost_frames_before_new_keyframe);
  if (!(guess_min_translation > 0 && std::isfinite(guess_min_translation)))
    check.fail("guess_min_translation", "(0, inf) m", guess_min_translation);
  if (!(guess_min_rotation > 0 && guess_min_rotation <= M_PI))
    check.fail("guess_min_rotation", "(0, pi] rad", guess_min_rotation);
  if (!(guess_skip_inlier_fraction > 0 && guess_skip_inlier_fraction <= 1))
    check.fail("guess_skip_inlier_fraction", "(0, 1]", guess_skip_inlier_fraction);
  if (!(increment_covariance_scale > 0 && increment_covariance_scale <= 1e6))
    check.fail("increment_covariance_scale", "(0, 1e6]", increment_covariance_scale);
  if (!(increment_translation_fraction >= 0 && std::isfinite(increment_translation_fraction)))
    check.fail("increment_translation_fraction", "[0, inf)", increment_translation_fraction);
  if (!(velocity_hold_time >= 0 && velocity_hold_time <= 10))
    check.fail("velocity_hold_time", "[0, 10] s", velocity_hold_time);
  if (!(velocity_min_information >= 0 && velocity_min_information <= 1000))
    check.fail("velocity_min_information", "[0, 1000]", velocity_min_information);
  if (!(increment_rotation_per_metre >= 0 && std::isfinite(increment_rotation_per_metre)))
    check.fail("increment_rotation_per_metre", "[0, inf) rad/m", increment_rotation_per_metre);
  guess.validate();
  features.validate();
  if (feature_history_keyframes < 0 || feature_history_keyframes > 1000)
    check.fail("feature_history_keyframes", "[0, 1000]", feature_history_keyframes);
  if (!(feature_pose_sigma_translation > 0 && std::isfinite(feature_pose_sigma_translation)))
    check.fail("feature_pose_sigma_translation", "(0, inf) m", feature_pose_sigma_translation);
  if (!(feature_pose_sigma_rotation > 0 && feature_pose_sigma_rotation <= M_PI))
    check.fail("feature_pose_sigma_rotation", "(0, pi] rad", feature_pose_sigma_rotation);
  if (!(feature_min_interval >= 0 && std::isfinite(feature_min_interval)))
    check.fail("feature_min_interval", "[0, inf) s", feature_min_interval);
  if (!(feature_max_speed > 0 && std::isfinite(feature_max_speed)))
    check.fail("feature_max_speed", "(0, inf) m/s", feature_max_speed);
  if (!(feature_max_turn_rate > 0 && std::isfinite(feature_max_turn_rate)))
    check.fail("feature_max_turn_rate", "(0, inf) rad/s", feature_max_turn_rate);
  if (!(feature_fusion_icp_bias_per_z2 >= 0 && std::isfinite(feature_fusion_icp_bias_per_z2)))
    check.fail("feature_fusion_icp_bias_per_z2", "[0, inf) 1/m", feature_fusion_icp_bias_per_z2);
  if (!(feature_fusion_corner_floor > 0 && std::isfinite(feature_fusion_corner_floor)))
    check.fail("feature_fusion_corner_floor", "(0, inf) m", feature_fusion_corner_floor);
  surface_normals.validate();
  photometric.validate();
  if (!(photometric_information_scale > 0 && photometric_information_scale <= 1))
    check.fail("photometric_information_scale", "(0, 1]", photometric_information_scale);
  if (!(photometric_depth_floor_translation > 0 && photometric_depth_floor_translation <= 1))
    check.fail("photometric_depth_floor_translation", "(0, 1] m",
               photometric_depth_floor_translation);
  if (!(photometric_depth_floor_rotation > 0 && photometric_depth_floor_rotation <= 1))
    check.fail("photometric_depth_floor_rotation", "(0, 1] rad", photometric_depth_floor_rotation);
}

OdometryTracker::OdometryTracker(const Params& params)
    : params_((params.validate(), params)),
      icp_(params.icp),
      guesser_(params.guess),
      feature_guesser_(params.features),
      photometric_(params.photometric) {}

int OdometryTracker::adoptSurfaceNormals(const std::vector<QuadricMeasurement>& observations,
                                         Cloud& cloud) {
  const int stride = std::gcd(params_.icp.reference_stride, params_.icp.finest_stride);
  return quadric_slam::adoptSurfaceNormals(observations, params_.surface_normals, stride, cloud,
                                           &surface_normal_scratch_);
}

void OdometryTracker::reset() {
  initialized_ = false;
  icp_.clearReference();
  keyframe_observations_.clear();
  keyframe_intensity_ = IntensityPyramid();
  keyframe_features_ = FeatureFrame();
  keyframe_image_.release();
  keyframe_depth_.release();
  feature_history_.clear();
  T_odom_keyframe_ = T_odom_camera_ = last_motion_ = Eigen::Isometry3d::Identity();
  keyframe_covariance_ = covariance_ = keyframe_relative_covariance_ = Matrix6::Zero();
  velocity_dt_ = velocity_stamp_ = last_stamp_ = 0;
  consecutive_lost_ = 0;
}

void OdometryTracker::setKeyframe(const Cloud& cloud, const CameraIntrinsics& intrinsics,
                                  const std::vector<QuadricMeasurement>* observations,
                                  IntensityPyramid& intensity, const cv::Mat* feature_image,
                                  FeatureFrame* features) {
  icp_.setReference(cloud, intrinsics);
  keyframe_intensity_ = std::move(intensity);
  intensity = IntensityPyramid();
  // The keyframe being replaced keeps its corners for later frames (when they were made).
  if (params_.feature_history_keyframes > 0 && !keyframe_features_.empty()) {
    feature_history_.push_back({std::move(keyframe_features_), T_odom_keyframe_});
    while (static_cast<int>(feature_history_.size()) > params_.feature_history_keyframes)
      feature_history_.pop_front();
  }
  keyframe_features_ = FeatureFrame();
  keyframe_image_.release();
  keyframe_depth_.release();
  keyframe_intrinsics_ = intrinsics;
  if (features) {
    keyframe_features_ = std::move(*features);
  } else if (feature_image) {
    // Most keyframes are never asked for their corners (the prior is good): keep what makes them.
    keyframe_image_ = feature_image->clone();
    keyframe_depth_ = depthOf(cloud);
  }
  keyframe_observations_.clear();
  if (observations) {
    for (const QuadricMeasurement& m : *observations) {
      keyframe_observations_.push_back(m);
      keyframe_observations_.back().support_points.clear();  // the guess needs the shapes only
    }
  }
  T_odom_keyframe_ = T_odom_camera_;
  keyframe_covariance_ = covariance_;
  keyframe_relative_covariance_ = Matrix6::Zero();  // the reported pose is the keyframe's
}

OdometryTracker::Matrix6 OdometryTracker::keyframeRelativeCovariance(
    const PointToPlaneIcp::Result& icp) const {
  // ICP: T_keyframe_current = exp(xi^) T_hat, xi in the keyframe frame. As a right perturbation,
  // exp(xi^) T_hat = T_hat exp((Ad(T_hat^-1) xi)^), so the body covariance is Ad C Ad^T.
  const Matrix6 ad = adjointSE3(icp.T_reference_current.inverse());
  const Matrix6 body = ad * icp.covariance * ad.transpose();
  return 0.5 * (body + body.transpose());
}

OdometryTracker::Result OdometryTracker::output(TrackingStatus status, bool new_keyframe) const {
  Result out;
  out.T_odom_camera = T_odom_camera_;
  out.status = status;
  out.new_keyframe = new_keyframe;
  out.consecutive_lost = consecutive_lost_;
  // Left perturbation exp(xi^) T: t_true = t + v + omega x t, so (dt, r) = [I -[t]x; 0 I] xi.
  Matrix6 M = Matrix6::Identity();
  M.topRightCorner<3, 3>() = -skew(T_odom_camera_.translation());
  out.covariance = M * covariance_ * M.transpose();
  return out;
}

void OdometryTracker::alignFromEarlierKeyframes(
    const Cloud& cloud, const std::function<FeatureFrame*()>& frame_features,
    PointToPlaneIcp::Result& best, Result& out) {
  const FeatureFrame* current = frame_features();
  if (!current)
    return;
  // Not the newest earlier keyframe but the one with the strongest consensus: a camera swinging
  // back sees again what it saw several keyframes ago, and a few corners matched over a sliver of
  // overlap can agree on a wrong motion (on generated fr1_room at 1.5 Hz, after a 58-degree turn,
  // the keyframe before agreed 53 of 109 matches on a pose 39 degrees off; three back agreed 777
  // of 815 on the right one). A full guess costs 15-30 ms: a sample of the frame's corners first
  // tells which earlier keyframes share the most with it, and only those are asked.
  const int n = static_cast<int>(feature_history_.size());
  std::vector<std::pair<int, int>> shared;  // (screened matches, keyframes back)
  for (int back = 1; back <= n; ++back) {
    const int matches = feature_guesser_.screenMatches(feature_history_[n - back].features,
                                                       *current, kHistoryScreenStride);
    if (matches >= kHistoryScreenMinMatches)
      shared.emplace_back(matches, back);
  }
  std::stable_sort(shared.begin(), shared.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  if (static_cast<int>(shared.size()) > kHistoryKeyframesGuessed)
    shared.resize(kHistoryKeyframesGuessed);
  FeatureMotionGuess g;
  int back_chosen = 0;
  Eigen::Isometry3d T_past_keyframe = Eigen::Isometry3d::Identity(), start = T_past_keyframe;
  for (const auto& screened : shared) {
    const int back = screened.second;
    const PastKeyframe& past = feature_history_[n - back];
    FeatureMotionGuess candidate = feature_guesser_.guess(past.features, *current);
    if (!candidate.found || candidate.inliers <= g.inliers)
      continue;
    const Eigen::Isometry3d T_past = past.T_odom_keyframe.inverse() * T_odom_keyframe_;
    const Eigen::Isometry3d candidate_start = T_past.inverse() * candidate.T_reference_current;
    if (!withinCameraSpeed(candidate_start))
      continue;
    g = std::move(candidate);
    back_chosen = back;
    T_past_keyframe = T_past;
    start = candidate_start;
  }
  // The keyframe's own guess, when found, stands unless an earlier keyframe's is stronger.
  if (!g.found || (out.feature_guess.found && g.inliers <= out.feature_guess.inliers))
    return;
  // The corners of the earlier keyframe judge an alignment as in alignFromBestStart.
  const auto agreement = [&](const PointToPlaneIcp::Result& r) {
    return feature_guesser_.agreeingMatches(g, T_past_keyframe * r.T_reference_current);
  };
  PointToPlaneIcp::Result from_past = icp_.align(cloud, start);
  const bool strong = strongGuess(g);
  const int best_agreement = best.status == TrackingStatus::kLost ? 0 : agreement(best);
  const int past_agreement = from_past.status == TrackingStatus::kLost ? 0 : agreement(from_past);
  // Little of the keyframe may overlap, so ICP against it may not hold from the corners' start:
  // a strong guess's alignment must keep half of its agreeing corners. When none does, the
  // corners alone place the frame, which becomes the keyframe.
  const double kept = strong ? kCornerAgreementShare * g.inliers : 0.0;
  const bool replaces = from_past.status != TrackingStatus::kLost &&
                        past_agreement > best_agreement && past_agreement >= kept;
  const bool placed = !replaces && strong && best_agreement < kept;
  if (!replaces && !placed) {
    if (!out.feature_guess.found) {  // reported, though it changed nothing
      out.feature_guess = std::move(g);
      out.feature_keyframes_back = back_chosen;
    }
    return;
  }
  out.feature_guess = std::move(g);
  out.feature_keyframes_back = back_chosen;
  if (replaces) {
    best = std::move(from_past);
    out.started_from_features = true;
    out.started_from_last_pose = out.started_from_guess = false;
    return;
  }
  best = placedByCorners(start, back_chosen);
  out.placed_by_features = true;
  out.started_from_features = true;
  out.started_from_last_pose = out.started_from_guess = false;
}

PointToPlaneIcp::Result OdometryTracker::placedByCorners(
    const Eigen::Isometry3d& T_keyframe_current, int keyframes_back) const {
  PointToPlaneIcp::Result placed;
  placed.status = TrackingStatus::kDegenerate;
  placed.T_reference_current = T_keyframe_current;
  placed.covariance.setZero();
  placed.covariance.diagonal().head<3>().setConstant(
      std::pow(params_.feature_pose_sigma_translation, 2));
  placed.covariance.diagonal().tail<3>().setConstant(
      std::pow(params_.feature_pose_sigma_rotation, 2));
  placed.message = "placed by the corners of " +
                   (keyframes_back == 0 ? std::string("the keyframe")
                                        : "a keyframe " + std::to_string(keyframes_back) + " back");
  return placed;
}

Eigen::Isometry3d OdometryTracker::cornersReferenceFromKeyframe(const Result& out) const {
  const int n = static_cast<int>(feature_history_.size());
  if (!out.feature_guess.found || out.feature_keyframes_back <= 0 || out.feature_keyframes_back > n)
    return Eigen::Isometry3d::Identity();
  return feature_history_[n - out.feature_keyframes_back].T_odom_keyframe.inverse() *
         T_odom_keyframe_;
}

Eigen::Isometry3d OdometryTracker::fusedWithCorners(const PointToPlaneIcp::Result& icp,
                                                    const FeatureMotionGuess& corners,
                                                    const Eigen::Isometry3d& T_corners_keyframe,
                                                    double depth) const {
  // Both as left perturbations in the keyframe frame (the ICP's convention): an earlier
  // keyframe's guess is carried over by the adjoint, xi_keyframe = Ad(T_keyframe_earlier) xi.
  const Eigen::Isometry3d T_keyframe_corners =
      T_corners_keyframe.inverse() * corners.T_reference_current;
  const Matrix6 carry_back = adjointSE3(T_corners_keyframe);  // = Ad(T_keyframe_earlier)^-1
  Matrix6 corners_covariance =
      (carry_back.transpose() * corners.information * carry_back).ldlt().solve(Matrix6::Identity());
  const double corner_floor = params_.feature_fusion_corner_floor;
  corners_covariance.diagonal().head<3>().array() += corner_floor * corner_floor;
  corners_covariance.diagonal().tail<3>().array() += std::pow(corner_floor / depth, 2);
  Matrix6 icp_covariance = icp.covariance;
  const double bias = params_.feature_fusion_icp_bias_per_z2 * depth * depth;
  icp_covariance.diagonal().head<3>().array() += bias * bias;
  icp_covariance.diagonal().tail<3>().array() += std::pow(bias / depth, 2);
  const Matrix6 corners_information = corners_covariance.ldlt().solve(Matrix6::Identity());
  const Matrix6 icp_information = icp_covariance.ldlt().solve(Matrix6::Identity());
  // The information-weighted mean, from the alignment's pose towards the corners'.
  const Vector6d towards_corners = logSE3(T_keyframe_corners * icp.T_reference_current.inverse());
  const Vector6d step =
      (corners_information + icp_information).ldlt().solve(corners_information * towards_corners);
  return expSE3(step) * icp.T_reference_current;
}

bool OdometryTracker::strongGuess(const FeatureMotionGuess& guess) const {
  return guess.found &&
         guess.inliers >= kPlacementInlierFactor * feature_guesser_.params().min_inliers &&
         guess.inliers >= kPlacementInlierShare * guess.matches;
}

bool OdometryTracker::withinCameraSpeed(const Eigen::Isometry3d& T_keyframe_current) const {
  const Eigen::Isometry3d step = T_odom_camera_.inverse() * T_odom_keyframe_ * T_keyframe_current;
  const double dt = std::max(step_dt_, 0.0);
  return step.translation().norm() <=
             std::max(params_.feature_max_speed * dt, kMinSpeedBoundTranslation) &&
         pose_math::rotationAngle(step) <=
             std::max(params_.feature_max_turn_rate * dt, kMinSpeedBoundRotation);
}

const FeatureFrame* OdometryTracker::keyframeFeatures() {
  if (keyframe_features_.empty() && !keyframe_image_.empty()) {
    keyframe_features_ =
        feature_guesser_.describe(keyframe_image_, keyframe_depth_, keyframe_intrinsics_);
    keyframe_image_.release();
    keyframe_depth_.release();
  }
  return keyframe_features_.empty() ? nullptr : &keyframe_features_;
}

bool OdometryTracker::startsElsewhere(const Eigen::Isometry3d& a,
                                      const Eigen::Isometry3d& b) const {
  const Eigen::Isometry3d difference = a.inverse() * b;
  return difference.translation().norm() >= params_.guess_min_translation ||
         pose_math::rotationAngle(difference) >= params_.guess_min_rotation;
}

PointToPlaneIcp::Result OdometryTracker::alignFromBestStart(
    const Cloud& cloud, const Eigen::Isometry3d& T_keyframe_prior,
    const Eigen::Isometry3d& T_keyframe_last, const std::vector<QuadricMeasurement>* observations,
    const std::function<FeatureFrame*()>& frame_features, Result& out) {
  PointToPlaneIcp::Result best = icp_.align(cloud, T_keyframe_prior);
  if (params_.zero_motion_start && startsElsewhere(T_keyframe_prior, T_keyframe_last)) {
    PointToPlaneIcp::Result from_last = icp_.align(cloud, T_keyframe_last);
    // At a tie the last pose wins: the velocity was not confirmed.
    if (!betterAlignment(best, from_last)) {
      best = std::move(from_last);
      out.started_from_last_pose = true;
    }
  }
  if (best.status == TrackingStatus::kOk &&
      best.inlier_fraction >= params_.guess_skip_inlier_fraction) {
    out.guess.message = "not needed: ICP from the prior is ok with enough inliers";
    out.feature_guess.message = out.guess.message;
    return best;
  }
  // The corners first: where the two images share enough of them they measure all six
  // directions, while the surfaces of a wall-and-floor view leave three free and may match a
  // wall to a parallel one (on generated fr1_room at 1.5 Hz such a match moved the camera 60-90
  // cm where the corners were right within 2 cm).
  // At full rate a degenerate step is within the intensities' basin: the corners (15-30 ms a
  // frame) are made when the alignment is lost or the frame comes feature_min_interval after
  // the last.
  const bool corners_wanted =
      params_.feature_motion_guess &&
      (best.status == TrackingStatus::kLost || step_dt_ >= params_.feature_min_interval);
  if (corners_wanted) {
    const FeatureFrame* reference = keyframeFeatures();
    const FeatureFrame* current = reference ? frame_features() : nullptr;
    if (current)
      out.feature_guess = feature_guesser_.guess(*reference, *current);
    if (out.feature_guess.found && !withinCameraSpeed(out.feature_guess.T_reference_current)) {
      out.feature_guess.found = false;
      out.feature_guess.message = "beyond the camera's speed from its last pose";
    }
  }
  if (out.feature_guess.found &&
      startsElsewhere(best.T_reference_current, out.feature_guess.T_reference_current)) {
    PointToPlaneIcp::Result from_features =
        icp_.align(cloud, out.feature_guess.T_reference_current);
    // The prior and the last pose are unmeasured along any direction the depth leaves free (on a
    // wall and the floor ICP from the last pose held 15 degrees of a turn back with more inliers
    // than from the right pose): the corners judge. The alignment the more matched corners agree
    // with wins, at equal counts the better alignment, at a tie the corners'.
    const int best_agreement =
        feature_guesser_.agreeingMatches(out.feature_guess, best.T_reference_current);
    const int features_agreement =
        feature_guesser_.agreeingMatches(out.feature_guess, from_features.T_reference_current);
    if (from_features.status != TrackingStatus::kLost &&
        (features_agreement > best_agreement ||
         (features_agreement == best_agreement && !betterAlignment(best, from_features)))) {
      best = std::move(from_features);
      out.started_from_features = true;
      out.started_from_last_pose = false;
    }
  }
  if (corners_wanted && !feature_history_.empty() &&
      (!out.feature_guess.found || best.status == TrackingStatus::kLost ||
       !strongGuess(out.feature_guess)))
    alignFromEarlierKeyframes(cloud, frame_features, best, out);
  if (out.feature_guess.found) {
    out.guess.message = "not needed: the corners' guess was found";
    return best;
  }
  if (params_.quadric_motion_guess && observations && !keyframe_observations_.empty()) {
    out.guess = guesser_.guess(keyframe_observations_, *observations, T_keyframe_prior);
    // (When the prior already starts where the surfaces say, there is nothing to try.)
    if (out.guess.found && startsElsewhere(T_keyframe_prior, out.guess.T_reference_current)) {
      PointToPlaneIcp::Result from_guess = icp_.align(cloud, out.guess.T_reference_current);
      if (guessAlignmentReplaces(from_guess, best)) {
        best = std::move(from_guess);
        out.started_from_guess = true;
        out.started_from_last_pose = false;
      }
    }
  }
  return best;
}

OdometryTracker::Result OdometryTracker::track(const Cloud& cloud,
                                               const CameraIntrinsics& intrinsics, double stamp,
                                               const std::vector<QuadricMeasurement>* observations,
                                               const cv::Mat* image) {
  std::string problem;
  if (organizedCloudDecimation(intrinsics, static_cast<int>(cloud.width),
                               static_cast<int>(cloud.height), &problem) == 0)
    throw std::invalid_argument("OdometryTracker::track: " + problem);
  const auto usable = [&] { return icp_.usablePoints(cloud) >= params_.icp.min_correspondences; };
  // The frame's intensities, for the photometric refinement and as the next keyframe's.
  // Built when first needed: a degenerate alignment refines with it, a new keyframe keeps it.
  const bool have_image = params_.photometric_refinement && usableImage(image, intrinsics);
  // The frame's corners, made when first needed (the motion guess), kept for a new keyframe.
  const cv::Mat* feature_image =
      params_.feature_motion_guess && usableImage(image, intrinsics) ? image : nullptr;
  FeatureFrame feature_storage;
  bool features_made = false;
  const std::function<FeatureFrame*()> frameFeatures = [&]() -> FeatureFrame* {
    if (!feature_image)
      return nullptr;
    if (!features_made)
      feature_storage = feature_guesser_.describe(*feature_image, depthOf(cloud), intrinsics);
    features_made = true;
    return &feature_storage;
  };
  IntensityPyramid intensity_storage;
  const auto frameIntensity = [&]() -> IntensityPyramid& {
    if (have_image && intensity_storage.empty())
      intensity_storage = IntensityPyramid::fromImage(*image, params_.photometric.levels);
    return intensity_storage;
  };
  const auto keepAsKeyframe = [&] {
    setKeyframe(cloud, intrinsics, observations, frameIntensity(), feature_image,
                features_made ? &feature_storage : nullptr);
  };

  if (!initialized_) {
    if (!usable()) {
      ++consecutive_lost_;
      Result out = output(TrackingStatus::kLost, false);
      out.icp.message = "first frame has too few usable points";
      return out;
    }
    T_odom_camera_ = Eigen::Isometry3d::Identity();
    covariance_ = Matrix6::Zero();
    keepAsKeyframe();
    initialized_ = true;
    last_motion_ = Eigen::Isometry3d::Identity();
    velocity_dt_ = 0;
    velocity_stamp_ = stamp;
    last_stamp_ = stamp;
    consecutive_lost_ = 0;
    Result out = output(TrackingStatus::kOk, true);
    out.icp.status = TrackingStatus::kOk;
    // No previous frame: the motion into this one is unknown.
    out.increment_covariance = Matrix6::Identity() * params_.icp.degenerate_variance;
    return out;
  }

  // Constant-velocity prior: the last inter-frame motion scaled to this time step.
  const double dt = stamp - last_stamp_;
  Eigen::Isometry3d prediction = T_odom_camera_;
  if (params_.constant_velocity) {
    const double k = (velocity_dt_ > 0 && dt > 0) ? std::clamp(dt / velocity_dt_, 0.0, 3.0) : 1.0;
    prediction =
        pose_math::orthonormalized(T_odom_camera_ * pose_math::scaleMotion(last_motion_, k));
  }
  const Eigen::Isometry3d T_keyframe_odom = T_odom_keyframe_.inverse();
  step_dt_ = dt;
  Result out;
  PointToPlaneIcp::Result icp =
      alignFromBestStart(cloud, T_keyframe_odom * prediction, T_keyframe_odom * T_odom_camera_,
                         observations, frameFeatures, out);
  bool photometric = false;
  // With the keyframe's corners' guess found, a degenerate pose must keep at least half of its
  // agreeing corners: along the directions the depth leaves free the intensities of a far,
  // repetitively textured wall have minima tens of centimetres apart, the corners one.
  // (An earlier keyframe's corners judge the same way, the pose carried into that keyframe.)
  const Eigen::Isometry3d T_corners_keyframe = cornersReferenceFromKeyframe(out);
  const Eigen::Isometry3d T_keyframe_corners =
      T_corners_keyframe.inverse() * out.feature_guess.T_reference_current;
  const auto cornersAgree = [&](const Eigen::Isometry3d& T_keyframe_current) {
    return !out.feature_guess.found ||
           kCornerAgreementShare * out.feature_guess.inliers <=
               feature_guesser_.agreeingMatches(out.feature_guess,
                                                T_corners_keyframe * T_keyframe_current);
  };
  if (have_image && icp.status == TrackingStatus::kDegenerate && !keyframe_intensity_.empty()) {
    // Along the directions the depth left free an alignment stays where it started: the
    // constant-velocity prior, the last pose or the surfaces' guess, any of which may be far off
    // there (a hand-held camera at 3 Hz turns 10-25 degrees per step and changes its turn rate;
    // a guess may match a parallel surface to the wrong one). The intensities' basin is a few
    // degrees wide, so they are refined from the alignment and from it moved along its free
    // directions to the prior's and to the last pose's, and the best match is kept.
    const Eigen::Matrix<double, 6, Eigen::Dynamic> free =
        freeDirections(icp.covariance, params_.icp.degenerate_variance, kFreeVarianceFraction);
    std::vector<Eigen::Isometry3d> starts = {icp.T_reference_current};
    std::vector<Eigen::Isometry3d> others = {T_keyframe_odom * prediction,
                                             T_keyframe_odom * T_odom_camera_};
    if (out.feature_guess.found)
      others.push_back(T_keyframe_corners);
    for (const Eigen::Isometry3d& other : others) {
      const Eigen::Isometry3d moved =
          priorAlongFreeDirections(icp.T_reference_current, other, free);
      if (std::all_of(starts.begin(), starts.end(),
                      [&](const Eigen::Isometry3d& s) { return startsElsewhere(s, moved); }))
        starts.push_back(moved);
    }
    const PointToPlaneIcp::Result aligned = icp;
    for (const Eigen::Isometry3d& start : starts) {
      PointToPlaneIcp::Result candidate = aligned;
      candidate.T_reference_current = start;
      PhotometricRefinement::Result refined;
      if (refinePhotometrically(cloud, intrinsics, frameIntensity(), candidate, refined) &&
          cornersAgree(candidate.T_reference_current) &&
          (!photometric || betterPhotometricMatch(refined, out.photometric))) {
        icp = std::move(candidate);
        out.photometric = std::move(refined);
        photometric = true;
      }
    }
  }
  if (out.started_from_guess && icp.status == TrackingStatus::kDegenerate && !photometric) {
    // Nothing measured the guess along the directions the depth left free (alignment_choice.h).
    icp.T_reference_current = priorAlongFreeDirections(
        icp.T_reference_current, T_keyframe_odom * prediction,
        freeDirections(icp.covariance, params_.icp.degenerate_variance, kFreeVarianceFraction));
  }
  if (icp.status == TrackingStatus::kDegenerate && !photometric &&
      !cornersAgree(icp.T_reference_current)) {
    // The corners measured the directions the depth left free.
    const Eigen::Isometry3d moved = priorAlongFreeDirections(
        icp.T_reference_current, T_keyframe_corners,
        freeDirections(icp.covariance, params_.icp.degenerate_variance, kFreeVarianceFraction));
    if (cornersAgree(moved) || !strongGuess(out.feature_guess)) {
      icp.T_reference_current = moved;
    } else {
      // Where the depth constrains the alignment it still disagrees with a strong guess: ICP
      // matched a surface to the wrong one (little of the keyframe overlaps, or a wall to a
      // parallel one), and the corners alone place the frame.
      icp = placedByCorners(T_keyframe_corners, out.feature_keyframes_back);
      out.placed_by_features = true;
    }
  }

  // A strong corners' guess measures the step too: between views 0.3-0.7 s apart ICP drifted
  // 1-4 cm per step on generated far walls where the corners were within 0.2-1.5 cm.
  if (out.feature_guess.found && strongGuess(out.feature_guess) &&
      icp.status != TrackingStatus::kLost && !out.placed_by_features)
    icp.T_reference_current =
        fusedWithCorners(icp, out.feature_guess, T_corners_keyframe, medianDepth(cloud));
  const Eigen::Isometry3d previous = T_odom_camera_;
  bool new_keyframe = false;
  // The increment T_previous_this and its covariance (Result::increment_covariance).
  //
  // Every tracked frame c is aligned to the keyframe K, not to the previous frame p: ICP gives
  // T_Kc = T_hat_Kc exp(e_c) with Cov(e_c) = C_c (body tangent, keyframeRelativeCovariance).
  // The increment is T_pc = T_Kp^-1 T_Kc, and with T_Kp = T_hat_Kp exp(e_p),
  //   T_pc = exp(-e_p) T_hat_pc exp(e_c) = T_hat_pc exp(-Ad(T_hat_pc^-1) e_p + e_c),
  // so, e_p and e_c coming from different current clouds,
  //   Cov(xi_pc) = Ad(T_hat_cp) C_p Ad(T_hat_cp)^T + C_c,
  // with C_p = 0 when p is the keyframe (then T_pc is one alignment). Both alignments share the
  // keyframe's cloud; its noise correlates e_p and e_c positively, which makes the true increment
  // covariance smaller than this, never larger (the keyframe's error cancels in T_Kp^-1 T_Kc).
  // Consecutive increments are correlated through e_p too (one is -Ad e_p, the next +e_p): a
  // consumer that adds them as independent steps over many frames (the mapper between its
  // keyframes) over-states the uncertainty of the sum, never under-states it. The keyframe itself
  // is chained: when c becomes the next keyframe, the following increments are relative to it and
  // C_c is carried by the increment that reached it.
  Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
  Matrix6 increment_covariance = Matrix6::Identity() * params_.icp.degenerate_variance;
  if (icp.status == TrackingStatus::kLost) {
    // Keep the last pose (no velocity: the motion is unknown) and grow the uncertainty.
    ++consecutive_lost_;
    last_motion_ = Eigen::Isometry3d::Identity();
    velocity_dt_ = 0;
    covariance_ += Matrix6::Identity() * params_.icp.degenerate_variance;
    if (consecutive_lost_ >= params_.lost_frames_before_new_keyframe && usable()) {
      keepAsKeyframe();
      new_keyframe = true;
      // Restarted at the last pose, which the camera has left by an unknown motion: the earlier
      // keyframes' poses are in another anchor than the poses to come.
      feature_history_.clear();
    }
  } else {
    consecutive_lost_ = 0;
    T_odom_camera_ = pose_math::orthonormalized(T_odom_keyframe_ * icp.T_reference_current);
    // First-order composition: T_odom_cur = exp(a) T_odom_kf exp(b) T_kf_cur
    //                                     = exp(a + Ad(T_odom_kf) b) T_odom_cur.
    const Matrix6 ad = adjointSE3(T_odom_keyframe_);
    covariance_ = keyframe_covariance_ + ad * icp.covariance * ad.transpose();
    // The increment (derivation above); p is the previous reported pose (the last tracked one
    // after lost frames, which keep it).
    increment = pose_math::orthonormalized(previous.inverse() * T_odom_camera_);
    const Matrix6 current_relative = keyframeRelativeCovariance(icp);
    const Matrix6 ad_back = adjointSE3(increment.inverse());
    increment_covariance =
        params_.increment_covariance_scale *
        (ad_back * keyframe_relative_covariance_ * ad_back.transpose() + current_relative);
    increment_covariance = 0.5 * (increment_covariance + increment_covariance.transpose());
    // The calibration's error that grows with the step (a variance on each axis, so a degenerate
    // direction stays large).
    const double step = increment.translation().norm();
    const double st = params_.increment_translation_fraction * step;
    const double sr = params_.increment_rotation_per_metre * step;
    increment_covariance.diagonal() +=
        (Vector6d() << st * st, st * st, st * st, sr * sr, sr * sr, sr * sr).finished();
    keyframe_relative_covariance_ = current_relative;
    // Only a step constrained in all six directions and accepted by the data sets the velocity;
    // along a degenerate direction the motion is the prior's, which must not feed itself. After a
    // degenerate step the last confirmed velocity is kept (not this step's motion) while it is at
    // most velocity_hold_time old: a hand-held camera keeps moving along a far wall that cannot
    // measure it, and zero motion there is as wrong as a velocity carried for long.
    if ((icp.status == TrackingStatus::kOk &&
         icp.information_over_noise >= params_.velocity_min_information) ||
        photometric) {
      last_motion_ = pose_math::orthonormalized(previous.inverse() * T_odom_camera_);
      velocity_dt_ = dt > 0 ? dt : 0;
      velocity_stamp_ = stamp;
    } else if (!(stamp - velocity_stamp_ <= params_.velocity_hold_time)) {
      last_motion_ = Eigen::Isometry3d::Identity();
    }
    const Eigen::Isometry3d& from_keyframe = icp.T_reference_current;
    if (from_keyframe.translation().norm() > params_.keyframe_translation ||
        pose_math::rotationAngle(from_keyframe) > params_.keyframe_rotation ||
        icp.inlier_fraction < params_.keyframe_min_overlap || out.placed_by_features) {
      keepAsKeyframe();
      new_keyframe = true;
    }
  }
  last_stamp_ = stamp;
  Result result = output(icp.status, new_keyframe);
  // (A lost frame keeps the pose: identity with the unknown motion's degenerate_variance.)
  result.increment = increment;
  result.increment_covariance = increment_covariance;
  result.icp = std::move(icp);
  result.guess = std::move(out.guess);
  result.started_from_guess = out.started_from_guess;
  result.started_from_last_pose = out.started_from_last_pose;
  result.feature_guess = std::move(out.feature_guess);
  result.started_from_features = out.started_from_features;
  result.feature_keyframes_back = out.feature_keyframes_back;
  result.placed_by_features = out.placed_by_features;
  result.T_odom_predicted = prediction;
  result.photometric = std::move(out.photometric);
  return result;
}

bool OdometryTracker::refinePhotometrically(const Cloud& cloud, const CameraIntrinsics& intrinsics,
                                            const IntensityPyramid& intensity,
                                            PointToPlaneIcp::Result& icp,
                                            PhotometricRefinement::Result& out) const {
  if (freeDirections(icp.covariance, params_.icp.degenerate_variance, kFreeVarianceFraction)
          .cols() == 0) {
    out = PhotometricRefinement::Result();
    out.T_reference_current = icp.T_reference_current;
    out.message = "no free direction to refine";
    return false;
  }
  // The depth's information on the directions it measured, weighed against the intensities'
  // (refine() scales those by their residual variance; the step's covariance below scales them
  // by photometric_information_scale, so the prior is divided by it here).
  Matrix6 floor = Matrix6::Zero();
  floor.diagonal().head<3>().setConstant(std::pow(params_.photometric_depth_floor_translation, 2));
  floor.diagonal().tail<3>().setConstant(std::pow(params_.photometric_depth_floor_rotation, 2));
  const Matrix6 depth_information = measuredInformation(
      icp.covariance, params_.icp.degenerate_variance, kFreeVarianceFraction, floor);
  const double scale = params_.photometric_information_scale;
  out =
      photometric_.refine(keyframe_intensity_, intensity, cloud, intrinsics,
                          icp.T_reference_current, Matrix6::Identity(), depth_information / scale);
  if (!out.refined)
    return false;
  // The covariance of the joint estimate: the scaled intensities' information plus the depth's.
  const Matrix6 information = scale * out.information;
  const Eigen::LDLT<Matrix6> ldlt(information);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
    out.refined = false;
    out.message = "the intensities' information is singular";
    out.T_reference_current = icp.T_reference_current;
    return false;
  }
  icp.covariance = ldlt.solve(Matrix6::Identity());
  icp.covariance = 0.5 * (icp.covariance + icp.covariance.transpose());
  icp.T_reference_current = out.T_reference_current;
  return true;
}

}  // namespace quadric_slam
