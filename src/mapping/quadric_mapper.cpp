#include "quadric_slam/mapping/quadric_mapper.h"

#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "quadric_slam/mapping/factors.h"
#include "quadric_slam/mapping/motion_bound.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool isRigid(const Eigen::Isometry3d& T) {
  if (!T.matrix().allFinite())
    return false;
  const Eigen::Matrix3d R = T.linear();
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 &&
         R.determinant() > 0.0;
}

double rotationAngle(const Eigen::Isometry3d& T) {
  return Eigen::AngleAxisd(T.linear()).angle();
}

}  // namespace

void QuadricMapper::Params::validate() const {
  const ParamRangeCheck requireRange("QuadricMapper::Params");
  map.validate();
  window.validate();
  model_error.validate();
  requireRange(keyframe_translation > 0.0, "keyframe_translation", "(0, inf) m");
  requireRange(keyframe_rotation > 0.0, "keyframe_rotation", "(0, inf) rad");
  requireRange(keyframe_min_new_landmarks >= 1, "keyframe_min_new_landmarks", "[1, inf)");
  requireRange(keyframe_min_overlap >= 0.0 && keyframe_min_overlap <= 1.0, "keyframe_min_overlap",
               "[0, 1]");
  requireRange(odometry_translation_sigma >= 0.0, "odometry_translation_sigma", "[0, inf) m");
  requireRange(odometry_translation_fraction >= 0.0, "odometry_translation_fraction", "[0, inf)");
  requireRange(odometry_rotation_sigma >= 0.0, "odometry_rotation_sigma", "[0, inf) rad");
  requireRange(odometry_rotation_fraction >= 0.0, "odometry_rotation_fraction", "[0, inf)");
  requireRange(odometry_rotation_per_metre >= 0.0, "odometry_rotation_per_metre", "[0, inf) rad/m");
  requireRange(max_camera_speed >= 0.0 && std::isfinite(max_camera_speed), "max_camera_speed",
               "[0, inf) m/s");
  requireRange(max_camera_angular_speed >= 0.0 && std::isfinite(max_camera_angular_speed),
               "max_camera_angular_speed", "[0, inf) rad/s");
  requireRange(odometry_translation_sigma > 0.0 || odometry_translation_fraction > 0.0,
               "odometry_translation_sigma", "(0, inf) m when odometry_translation_fraction is 0");
  requireRange(odometry_rotation_sigma > 0.0 || odometry_rotation_fraction > 0.0 ||
                   odometry_rotation_per_metre > 0.0,
               "odometry_rotation_sigma", "(0, inf) rad when the other rotation terms are 0");
}

QuadricMapper::QuadricMapper(const Params& params)
    : params_(params), map_(params.map), window_(params.window) {
  params_.validate();
}

std::string QuadricMapper::validateMeasurement(const QuadricMeasurement& measurement) {
  const QuadricModel& z = measurement.quadric_camera;
  if (!z.pose().matrix().allFinite() || !z.scale().allFinite() || !z.signature().allFinite())
    return "quadric parameters not finite";
  if (!isRigid(z.pose()))
    return "quadric pose not rigid";
  const int k = minimalDimension(z.quadricClass());
  if (measurement.covariance.rows() != k || measurement.covariance.cols() != k)
    return "covariance is not " + std::to_string(k) + "x" + std::to_string(k) + " for a " +
           toString(z.quadricClass());
  try {
    if (!sqrtInformation(measurement.covariance, "measurement").allFinite())
      return "covariance not invertible";
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

Matrix6d QuadricMapper::incrementCovariance(const Eigen::Isometry3d& T_previous_this) const {
  const double dt = T_previous_this.translation().norm();
  const double dr = rotationAngle(T_previous_this);
  const double st = params_.odometry_translation_sigma + params_.odometry_translation_fraction * dt;
  const double sr = params_.odometry_rotation_sigma + params_.odometry_rotation_fraction * dr +
                    params_.odometry_rotation_per_metre * dt;
  // Keep the covariance positive definite for a zero increment with zero constant terms.
  const double st2 = std::max(st * st, 1e-12), sr2 = std::max(sr * sr, 1e-12);
  return (Vector6d() << st2, st2, st2, sr2, sr2, sr2).finished().asDiagonal();
}

MapperFrameResult QuadricMapper::process(const FrameMeasurements& frame,
                                         const OdometryInput& odometry) {
  const auto start = std::chrono::steady_clock::now();
  MapperFrameResult result;
  result.stamp = frame.stamp;
  // The current best pose of the latest frame, reported for refused frames.
  auto latestEstimate = [&]() {
    if (window_.keyframes().empty())
      return Eigen::Isometry3d(T_map_odom_start_ * T_odom_previous_);
    const Keyframe& kf = window_.keyframes().back();
    return Eigen::Isometry3d(kf.T_map_camera * kf.T_odom_camera.inverse() * T_odom_previous_);
  };
  auto refuse = [&](FrameStatus status, const std::string& why) {
    result.status = status;
    result.message = why;
    result.T_map_camera = latestEstimate();
    result.T_map_odom = result.T_map_camera * T_odom_previous_.inverse();
    return result;
  };

  if (!std::isfinite(frame.stamp))
    return refuse(FrameStatus::kRejectedStamp, "stamp is not finite");
  if (has_frame_ && frame.stamp <= last_stamp_)
    return refuse(FrameStatus::kRejectedStamp,
                  "stamp " + std::to_string(frame.stamp) + " s is not after the previous " +
                      std::to_string(last_stamp_) + " s (call reset() for a looping input)");
  const Eigen::Isometry3d& T_odom_camera = odometry.T_odom_camera;
  if (!isRigid(T_odom_camera))
    return refuse(FrameStatus::kRejectedOdometry, "T_odom_camera is not a finite rigid transform");
  const Eigen::Isometry3d T_previous_this =
      has_frame_ ? Eigen::Isometry3d(T_odom_previous_.inverse() * T_odom_camera)
                 : Eigen::Isometry3d::Identity();
  Matrix6d increment_covariance;
  if (odometry.increment_covariance.size() != 0) {
    if (odometry.increment_covariance.rows() != 6 || odometry.increment_covariance.cols() != 6)
      return refuse(FrameStatus::kRejectedOdometry, "increment covariance is not 6x6");
    try {
      sqrtInformation(odometry.increment_covariance, "increment covariance");
    } catch (const std::invalid_argument& e) {
      return refuse(FrameStatus::kRejectedOdometry, e.what());
    }
    // Degenerate and lost frames report a variance (1 m^2 and more) no camera motion explains.
    increment_covariance =
        has_frame_
            ? boundIncrementCovariance(odometry.increment_covariance, frame.stamp - last_stamp_,
                                       params_.max_camera_speed, params_.max_camera_angular_speed)
            : Matrix6d(odometry.increment_covariance);
  } else {
    increment_covariance = incrementCovariance(T_previous_this);
  }

  // Accepted: from here on the state changes.
  ++frame_index_;
  has_frame_ = true;
  last_stamp_ = frame.stamp;
  T_odom_previous_ = T_odom_camera;
  result.increment_covariance = increment_covariance;
  const Matrix6d Ad = adjointSE3(T_previous_this.inverse());
  covariance_since_keyframe_ =
      Ad * covariance_since_keyframe_ * Ad.transpose() + increment_covariance;

  std::vector<QuadricMeasurement> valid;
  for (const QuadricMeasurement& measurement : frame.observations) {
    const std::string why = validateMeasurement(measurement);
    if (why.empty()) {
      // The mapper keeps measurements in candidates and window keyframes; their supporting
      // points are the reconstruction's business, not the estimator's, so they stay out.
      valid.push_back(measurement);
      MeasurementModelError::add(valid.back(), params_.model_error);
      valid.back().support_points.clear();
      valid.back().support_points.shrink_to_fit();
      valid.back().support_colours.clear();
      valid.back().support_colours.shrink_to_fit();
      continue;
    }
    ++result.rejected_measurements;
    result.message +=
        (result.message.empty() ? "" : "; ") + std::string("measurement dropped: ") + why;
  }

  // 1. Prediction from the latest keyframe and the odometry since.
  const bool first = window_.keyframes().empty();
  Eigen::Isometry3d T_map_predicted = T_map_odom_start_ * T_odom_camera;
  Eigen::Isometry3d T_keyframe_this = Eigen::Isometry3d::Identity();
  if (!first) {
    const Keyframe& kf = window_.keyframes().back();
    T_keyframe_this = kf.T_odom_camera.inverse() * T_odom_camera;
    T_map_predicted = kf.T_map_camera * T_keyframe_this;
  }
  const bool relocalised = T_map_odom_relocalised_.has_value();
  if (relocalised) {
    T_map_predicted = *T_map_odom_relocalised_ * T_odom_camera;
    // The odometry factor below then agrees with the initial poses (and carries no weight).
    if (!first)
      T_keyframe_this = window_.keyframes().back().T_map_camera.inverse() * T_map_predicted;
  }

  // 2. Association and bookkeeping.
  result.update =
      map_.integrate(frame_index_, frame.stamp, valid, T_map_predicted, covariance_since_keyframe_);

  // 3. Keyframe rule: motion, a relocalisation, or a view of the map the window does not hold yet.
  bool keyframe = first || relocalised ||
                  T_keyframe_this.translation().norm() > params_.keyframe_translation ||
                  rotationAngle(T_keyframe_this) > params_.keyframe_rotation;
  Keyframe kf;
  std::set<int> seen, new_to_window;
  for (size_t m = 0; m < valid.size(); ++m) {
    const MeasurementResult& r = result.update.measurements[m];
    if (r.fate != MeasurementFate::kLandmark && r.fate != MeasurementFate::kPromoted &&
        r.fate != MeasurementFate::kJoined)
      continue;
    if (r.without_factor)
      continue;  // a cylinder on a cone landmark (or the reverse): counted, no factor
    kf.observations.push_back({r.id, valid[m]});
    seen.insert(r.id);
    if (!window_.containsLandmark(r.id))
      new_to_window.insert(r.id);
  }
  if (!seen.empty()) {
    const double overlap = 1.0 - static_cast<double>(new_to_window.size()) / seen.size();
    keyframe = keyframe ||
               static_cast<int>(new_to_window.size()) >= params_.keyframe_min_new_landmarks ||
               overlap < params_.keyframe_min_overlap;
  }
  result.association_seconds = secondsSince(start);

  // 4. Window optimisation on keyframes.
  if (keyframe) {
    kf.frame_index = frame_index_;
    kf.stamp = frame.stamp;
    kf.T_map_camera = T_map_predicted;
    kf.T_odom_camera = T_odom_camera;
    kf.T_previous_this = T_keyframe_this;
    // After a relocalisation the motion since the previous keyframe is unknown: 100 m / 100 rad.
    kf.increment_covariance = first         ? Matrix6d::Identity()
                              : relocalised ? Matrix6d(1e4 * Matrix6d::Identity())
                                            : covariance_since_keyframe_;
    window_.addKeyframe(std::move(kf), map_);
    T_map_odom_relocalised_.reset();
  }
  // The earlier observations of a promoted candidate become factors in the window keyframes that
  // made them (this frame's is in kf when it is a keyframe).
  for (size_t p = 0; p < result.update.promoted.size(); ++p) {
    for (const CandidateObservation& o : result.update.promoted_history[p]) {
      if (o.frame_index != frame_index_)
        window_.addObservation(o.frame_index, {result.update.promoted[p], o.measurement});
    }
  }
  // The earlier observations of candidates that joined a landmark become its factors in the window
  // keyframes that made them (this frame's is in kf when it is a keyframe).
  for (const MapUpdate::Joined& joined : result.update.joined) {
    for (const CandidateObservation& o : joined.history) {
      if (o.frame_index != frame_index_)
        window_.addObservation(o.frame_index, {joined.landmark_id, o.measurement});
    }
  }
  if (keyframe) {
    const auto optimisation_start = std::chrono::steady_clock::now();
    result.window = window_.optimize(&map_);
    result.T_map_camera = window_.keyframes().back().T_map_camera;
    covariance_since_keyframe_.setZero();
    result.keyframe = true;
    result.optimisation_seconds = secondsSince(optimisation_start);
    // 5. The window's landmarks against the map: each surface once.
    const auto merge_start = std::chrono::steady_clock::now();
    const std::set<int> in_window = window_.landmarkIds();
    result.merges = mergeLandmarks(&in_window);
    result.merge_seconds = secondsSince(merge_start);
  } else {
    result.T_map_camera = T_map_predicted;
  }
  result.T_map_odom = result.T_map_camera * T_odom_camera.inverse();
  return result;
}

std::vector<LandmarkMerge> QuadricMapper::mergeLandmarks(const std::set<int>* subset) {
  std::vector<LandmarkMerge> merges;
  const LandmarkMerger& merger = map_.merger();
  if (localization_only_ || !merger.params().enabled)
    return merges;
  for (const DuplicatePair& pair : merger.findDuplicates(map_.landmarks(), subset)) {
    const auto a = map_.landmarks().find(pair.id_a), b = map_.landmarks().find(pair.id_b);
    if (a == map_.landmarks().end() || b == map_.landmarks().end())
      continue;  // one of them was merged earlier in this pass
    LandmarkMerge merge;
    const std::optional<QuadricLandmark> survivor =
        merger.mergePair(a->second, window_.landmarkFixed(pair.id_a), b->second,
                         window_.landmarkFixed(pair.id_b), &merge);
    if (!survivor)
      continue;  // changed by an earlier merge of this pass, or a loaded, trusted map
    merges.push_back(merge);
    window_.mergeLandmark(merge.merged_id, merge.survivor_id, survivor->quadric_map);
    map_.absorbLandmark(merge.merged_id, *survivor);
  }
  return merges;
}

std::vector<LandmarkMerge> QuadricMapper::mergeDuplicates() {
  std::vector<LandmarkMerge> all;
  for (;;) {
    const std::vector<LandmarkMerge> pass = mergeLandmarks(nullptr);
    if (pass.empty())
      return all;
    all.insert(all.end(), pass.begin(), pass.end());
  }
}

void QuadricMapper::reset() {
  map_.clear();
  window_.clear();
  has_frame_ = false;
  last_stamp_ = 0.0;
  T_odom_previous_ = Eigen::Isometry3d::Identity();
  T_map_odom_start_ = Eigen::Isometry3d::Identity();
  T_map_odom_relocalised_.reset();
  covariance_since_keyframe_.setZero();
}

void QuadricMapper::loadLandmarks(const std::vector<QuadricLandmark>& landmarks, bool fixed,
                                  const Eigen::Isometry3d& T_map_odom) {
  if (!isRigid(T_map_odom))
    throw std::invalid_argument("QuadricMapper::loadLandmarks: T_map_odom is not rigid");
  // Validate on a scratch map first, so that a bad list leaves the mapper as it was.
  LandmarkRegistry scratch(params_.map);
  for (const QuadricLandmark& landmark : landmarks)
    scratch.insertLandmark(landmark);
  reset();
  for (const QuadricLandmark& landmark : landmarks) {
    map_.insertLandmark(landmark);
    if (fixed)
      window_.setLandmarkFixed(landmark.id);
  }
  T_map_odom_start_ = T_map_odom;
}

void QuadricMapper::relocalise(const Eigen::Isometry3d& T_map_odom) {
  if (!isRigid(T_map_odom))
    throw std::invalid_argument("QuadricMapper::relocalise: T_map_odom is not rigid");
  T_map_odom_relocalised_ = T_map_odom;
}

MapUpdate QuadricMapper::promoteObservedCandidates(int min_observations) {
  if (localization_only_ || window_.keyframes().empty())
    return MapUpdate();
  MapUpdate update =
      map_.promoteObserved(min_observations, window_.keyframes().back().T_map_camera);
  for (std::size_t p = 0; p < update.promoted.size(); ++p)
    for (const CandidateObservation& o : update.promoted_history[p])
      window_.addObservation(o.frame_index, {update.promoted[p], o.measurement});
  return update;
}

void QuadricMapper::setLocalizationOnly(bool on) {
  localization_only_ = on;
  map_.setPromotion(!on);
  window_.setAllLandmarksFixed(on);
}

int addKeyframeToReconstruction(const FrameMeasurements& frame, const MapperFrameResult& result,
                                const LandmarkRegistry& map,
                                QuadricReconstruction* reconstruction) {
  int stored = 0;
  // result.update.measurements lists the accepted measurements in input order, the rejected left
  // out: walk the input alongside, skipping what process() refused.
  std::size_t input = 0;
  for (const MeasurementResult& fate : result.update.measurements) {
    while (input < frame.observations.size() &&
           !QuadricMapper::validateMeasurement(frame.observations[input]).empty())
      ++input;
    if (input >= frame.observations.size())
      break;
    const QuadricMeasurement& measurement = frame.observations[input++];
    if (fate.fate != MeasurementFate::kLandmark && fate.fate != MeasurementFate::kPromoted &&
        fate.fate != MeasurementFate::kJoined)
      continue;
    const auto merged = map.mergedInto().find(fate.id);
    const int id = merged == map.mergedInto().end() ? fate.id : merged->second;
    const auto landmark = map.landmarks().find(id);
    if (landmark != map.landmarks().end())
      stored += reconstruction->addPoints(id, landmark->second.quadric_map, result.T_map_camera,
                                          measurement.support_points, measurement.support_colours);
  }
  return stored;
}

std::vector<QuadricLandmark> QuadricMapper::landmarks() const {
  std::vector<QuadricLandmark> out;
  for (const auto& [id, landmark] : map_.landmarks())
    out.push_back(landmark);
  return out;
}

void applyMergesToReconstruction(const std::vector<LandmarkMerge>& merges,
                                 QuadricReconstruction* reconstruction) {
  for (const LandmarkMerge& merge : merges)
    reconstruction->moveLandmark(merge.merged_id, merge.survivor_id, merge.T_survivor_merged);
}

}  // namespace quadric_slam
