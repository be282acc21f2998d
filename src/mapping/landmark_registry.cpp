#include "quadric_slam/mapping/landmark_registry.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/symmetry.h"
#include "quadric_slam/mapping/association_cross_class.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {

namespace {

// The fit RMS of a candidate's latest measurement (the one its quadric_map is); 0 when unknown.
double latestFitRms(const QuadricCandidate& candidate) {
  return candidate.history.empty() ? 0.0 : candidate.history.back().measurement.fit_rms;
}

ExtentBox landmarkExtent(const QuadricLandmark& landmark) {
  return ExtentBox{landmark.extent_min, landmark.extent_max};
}

void setLandmarkExtent(QuadricLandmark* landmark, const ExtentBox& box) {
  landmark->extent_min = box.min;
  landmark->extent_max = box.max;
}

// A candidate's estimate as a new landmark (no covariance until the window solves for it).
QuadricLandmark landmarkFromCandidate(const QuadricCandidate& candidate, int id) {
  QuadricLandmark landmark;
  landmark.id = id;
  landmark.quadric_map = candidate.quadric_map;
  landmark.observations = candidate.observations;
  landmark.last_observed = candidate.last_observed;
  setLandmarkExtent(&landmark, candidate.extent);
  return landmark;
}

// The measurement's box moved into the frame of `quadric_map` through the predicted pose.
ExtentBox observedExtentIn(const QuadricMeasurement& measurement,
                           const Eigen::Isometry3d& T_map_camera, const QuadricModel& quadric_map) {
  const ExtentBox observed{measurement.extent_min, measurement.extent_max};
  return observed.transformed(quadric_map.pose().inverse() * T_map_camera *
                              measurement.quadric_camera.pose());
}

}  // namespace

void LandmarkRegistry::Params::validate() const {
  const ParamRangeCheck requireRange("LandmarkRegistry::Params");
  requireRange(min_observations >= 1 && min_observations <= 1000, "min_observations", "[1, 1000]");
  requireRange(candidate_timeout_frames >= 1 && candidate_timeout_frames <= 100000,
               "candidate_timeout_frames", "[1, 100000]");
  association.validate();
  merging.validate();
}

LandmarkRegistry::LandmarkRegistry(const Params& params)
    : params_(params), associator_(params.association), merger_(params.merging) {
  params_.validate();
}

MapUpdate LandmarkRegistry::integrate(int frame_index, double stamp,
                                      const std::vector<QuadricMeasurement>& measurements,
                                      const Eigen::Isometry3d& T_map_camera,
                                      const Matrix6d& pose_covariance) {
  MapUpdate update;
  update.measurements.resize(measurements.size());

  // 1. Against the landmarks.
  std::vector<AssociationTarget> targets;
  std::vector<int> target_ids;
  for (const auto& [id, landmark] : landmarks_) {
    // Landmarks far from the camera are not even copied (bounded per-frame work).
    const ExtentBox extent = landmarkExtent(landmark);
    if (!associator_.inRange(landmark.quadric_map, extent, T_map_camera))
      continue;
    targets.push_back({id, landmark.quadric_map, landmark.covariance, extent});
    target_ids.push_back(id);
  }
  const std::vector<Association> to_landmarks =
      associator_.associate(measurements, T_map_camera, pose_covariance, targets);
  std::vector<QuadricMeasurement> rest;
  std::vector<int> rest_index;
  for (size_t m = 0; m < measurements.size(); ++m) {
    update.measurements[m].landmark_association = to_landmarks[m];
    int landmark_id = 0;
    if (to_landmarks[m].outcome == AssociationOutcome::kMatched) {
      landmark_id = target_ids[to_landmarks[m].target_index];
    } else {
      // 1b. A surface fitted with another class than its landmark's (a cone's band as a
      // cylinder, a patch as a sphere ...): counted there, no factor.
      landmark_id =
          otherClassLandmark(measurements[m].quadric_camera.transformed(T_map_camera),
                             ExtentBox{measurements[m].extent_min, measurements[m].extent_max},
                             measurements[m].fit_rms, T_map_camera);
      update.measurements[m].without_factor = landmark_id != 0;
    }
    if (landmark_id == 0) {
      rest.push_back(measurements[m]);
      rest_index.push_back(static_cast<int>(m));
      continue;
    }
    QuadricLandmark& landmark = landmarks_.at(landmark_id);
    landmark.observations += 1;
    landmark.last_observed = stamp;
    setLandmarkExtent(&landmark, landmarkExtent(landmark).merged(observedExtentIn(
                                     measurements[m], T_map_camera, landmark.quadric_map)));
    update.measurements[m].fate = MeasurementFate::kLandmark;
    update.measurements[m].id = landmark.id;
  }

  // 2. The rest against the candidates; 3. what matches nothing starts a candidate.
  targets.clear();
  std::vector<int> candidate_index;
  for (size_t c = 0; c < candidates_.size(); ++c) {
    const QuadricCandidate& candidate = candidates_[c];
    if (!associator_.inRange(candidate.quadric_map, candidate.extent, T_map_camera))
      continue;
    targets.push_back(
        {candidate.id, candidate.quadric_map, candidate.covariance, candidate.extent});
    candidate_index.push_back(static_cast<int>(c));
  }
  const std::vector<Association> to_candidates =
      associator_.associate(rest, T_map_camera, pose_covariance, targets);
  for (size_t r = 0; r < rest.size(); ++r) {
    const QuadricMeasurement& measurement = rest[r];
    const QuadricModel moved = measurement.quadric_camera.transformed(T_map_camera);
    const ExtentBox observed = observedExtentIn(measurement, T_map_camera, moved);
    MeasurementResult& result = update.measurements[rest_index[r]];
    if (to_candidates[r].outcome == AssociationOutcome::kMatched) {
      QuadricCandidate& candidate = candidates_[candidate_index[to_candidates[r].target_index]];
      // The estimate follows the latest measurement, re-expressed by the member of its symmetry
      // orbit closest to the previous estimate (so the box frame barely turns); the covariance is
      // re-expressed with it (geometry/symmetry.h).
      const QuadricModel aligned = alignToReference(moved, candidate.quadric_map);
      const Eigen::MatrixXd M =
          minimalAdjoint(moved.quadricClass(), aligned.pose().inverse() * moved.pose());
      candidate.extent =
          candidate.extent.transformed(aligned.pose().inverse() * candidate.quadric_map.pose())
              .merged(observedExtentIn(measurement, T_map_camera, aligned));
      candidate.quadric_map = aligned;
      candidate.covariance = M * measurement.covariance * M.transpose();
      candidate.observations += 1;
      candidate.last_frame = frame_index;
      candidate.last_observed = stamp;
      candidate.history.push_back({frame_index, measurement});
      if (static_cast<int>(candidate.history.size()) > params_.min_observations)
        candidate.history.erase(candidate.history.begin());
      result.fate = MeasurementFate::kCandidate;
      result.id = candidate.id;
    } else {
      QuadricCandidate candidate;
      candidate.id = next_candidate_id_++;
      candidate.quadric_map = moved;
      candidate.covariance = measurement.covariance;
      candidate.extent = observed;
      candidate.observations = 1;
      candidate.last_frame = frame_index;
      candidate.last_observed = stamp;
      candidate.history.push_back({frame_index, measurement});
      candidates_.push_back(candidate);
      result.fate = MeasurementFate::kNewCandidate;
      result.id = candidate.id;
    }
  }

  // This frame's measurements of candidate `candidate_id` now belong to landmark `landmark_id`.
  auto relabel = [&update](int candidate_id, MeasurementFate fate, int landmark_id) {
    for (MeasurementResult& result : update.measurements) {
      if ((result.fate == MeasurementFate::kCandidate ||
           result.fate == MeasurementFate::kNewCandidate) &&
          result.id == candidate_id) {
        result.fate = fate;
        result.id = landmark_id;
      }
    }
  };
  // A candidate's observations and extent counted on the landmark of its surface.
  const auto countCandidateOn = [](const QuadricCandidate& candidate, QuadricLandmark* landmark) {
    landmark->observations += candidate.observations;
    landmark->last_observed = std::max(landmark->last_observed, candidate.last_observed);
    setLandmarkExtent(landmark,
                      landmarkExtent(*landmark).merged(candidate.extent.transformed(
                          landmark->quadric_map.pose().inverse() * candidate.quadric_map.pose())));
  };
  // 4. Promotion of candidates seen often enough (this frame's only: others were checked before),
  // or joining the landmark of their surface.
  std::vector<QuadricCandidate> kept;
  for (QuadricCandidate& candidate : candidates_) {
    if (promotion_ && candidate.last_frame == frame_index &&
        candidate.observations >= params_.min_observations) {
      const int absorbed = otherClassLandmark(candidate.quadric_map, candidate.extent,
                                              latestFitRms(candidate), T_map_camera);
      if (absorbed != 0) {
        // Its observations count on the landmark of the other class, without factors.
        countCandidateOn(candidate, &landmarks_.at(absorbed));
        for (MeasurementResult& result : update.measurements) {
          if ((result.fate == MeasurementFate::kCandidate ||
               result.fate == MeasurementFate::kNewCandidate) &&
              result.id == candidate.id) {
            result.fate = MeasurementFate::kLandmark;
            result.id = absorbed;
            result.without_factor = true;
          }
        }
        continue;
      }
      const int joined = sameSurfaceLandmark(candidate, T_map_camera);
      if (joined != 0) {
        countCandidateOn(candidate, &landmarks_.at(joined));
        relabel(candidate.id, MeasurementFate::kJoined, joined);
        update.joined.push_back({joined, candidate.history});
        continue;
      }
      const QuadricLandmark landmark = landmarkFromCandidate(candidate, next_landmark_id_++);
      relabel(candidate.id, MeasurementFate::kPromoted, landmark.id);
      update.promoted.push_back(landmark.id);
      update.promoted_history.push_back(candidate.history);
      landmarks_.emplace(landmark.id, landmark);
      continue;
    }
    // 5. Expiry.
    if (frame_index - candidate.last_frame > params_.candidate_timeout_frames) {
      ++update.expired_candidates;
      continue;
    }
    kept.push_back(std::move(candidate));
  }
  candidates_ = std::move(kept);
  return update;
}

MapUpdate LandmarkRegistry::promoteObserved(int min_observations,
                                            const Eigen::Isometry3d& T_map_camera) {
  if (min_observations < 1)
    throw std::invalid_argument(
        "LandmarkRegistry::promoteObserved: min_observations must be >= 1, got " +
        std::to_string(min_observations));
  MapUpdate update;
  std::vector<QuadricCandidate> kept;
  for (QuadricCandidate& candidate : candidates_) {
    if (candidate.observations < min_observations ||
        otherClassLandmark(candidate.quadric_map, candidate.extent, latestFitRms(candidate),
                           T_map_camera) != 0 ||
        sameSurfaceLandmark(candidate, T_map_camera) != 0) {
      kept.push_back(std::move(candidate));
      continue;
    }
    const QuadricLandmark landmark = landmarkFromCandidate(candidate, next_landmark_id_++);
    update.promoted.push_back(landmark.id);
    update.promoted_history.push_back(std::move(candidate.history));
    landmarks_.emplace(landmark.id, landmark);
  }
  candidates_ = std::move(kept);
  return update;
}

void LandmarkRegistry::setEstimate(int id, const QuadricModel& quadric_map,
                                   const Eigen::MatrixXd& covariance) {
  QuadricLandmark& landmark = landmarks_.at(id);
  setLandmarkExtent(&landmark, landmarkExtent(landmark).transformed(quadric_map.pose().inverse() *
                                                                    landmark.quadric_map.pose()));
  landmark.quadric_map = quadric_map;
  landmark.covariance = covariance;
}

int LandmarkRegistry::sameSurfaceLandmark(const QuadricCandidate& candidate,
                                          const Eigen::Isometry3d& T_map_camera) const {
  if (!merger_.params().enabled)
    return 0;
  QuadricLandmark as_landmark;  // no covariance: the merger's missing one stands for it
  as_landmark.quadric_map = candidate.quadric_map;
  as_landmark.extent_min = candidate.extent.min;
  as_landmark.extent_max = candidate.extent.max;
  int best = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (const auto& [id, landmark] : landmarks_) {
    if (!sameKind(landmark.quadric_map, candidate.quadric_map) ||
        !associator_.inRange(landmark.quadric_map, landmarkExtent(landmark), T_map_camera))
      continue;
    const LandmarkMerger::Comparison c = merger_.compare(landmark, as_landmark);
    if (c.sameSurface() && c.squared_distance < best_d2) {
      best = id;
      best_d2 = c.squared_distance;
    }
  }
  return best;
}

int LandmarkRegistry::otherClassLandmark(const QuadricModel& observed,
                                         const ExtentBox& observed_box, double fit_rms,
                                         const Eigen::Isometry3d& T_map_camera) const {
  const QuadricAssociator::Params& p = associator_.params();
  if (p.cross_class_distance <= 0.0)
    return 0;
  int best = 0;
  double best_distance = p.crossClassGate(fit_rms);
  for (const auto& [id, landmark] : landmarks_) {
    if (!surfaceTestApplies(observed, landmark.quadric_map) ||
        !associator_.inRange(landmark.quadric_map, landmarkExtent(landmark), T_map_camera))
      continue;
    const ExtentBox moved =
        observed_box.transformed(landmark.quadric_map.pose().inverse() * observed.pose());
    if (p.check_extent && !moved.overlaps(landmarkExtent(landmark), p.extent_margin))
      continue;
    const double distance = crossClassDistance(observed, observed_box, landmark.quadric_map);
    if (distance <= best_distance) {
      best = id;
      best_distance = distance;
    }
  }
  return best;
}

void LandmarkRegistry::absorbLandmark(int merged_id, const QuadricLandmark& survivor) {
  if (merged_id == survivor.id)
    throw std::invalid_argument("LandmarkRegistry::absorbLandmark: landmark " +
                                std::to_string(merged_id) + " cannot absorb itself");
  landmarks_.at(merged_id);  // both must exist (std::out_of_range) before anything changes
  landmarks_.at(survivor.id) = survivor;
  landmarks_.erase(merged_id);
  recordMerge(merged_id, survivor.id, &merged_into_);
}

void LandmarkRegistry::insertLandmark(const QuadricLandmark& landmark) {
  if (landmark.id < 1)
    throw std::invalid_argument("LandmarkRegistry::insertLandmark: id " +
                                std::to_string(landmark.id) + " must be >= 1");
  if (landmarks_.count(landmark.id) != 0)
    throw std::invalid_argument("LandmarkRegistry::insertLandmark: id " +
                                std::to_string(landmark.id) + " is already in use");
  const int k = minimalDimension(landmark.quadric_map.quadricClass());
  if (landmark.covariance.size() != 0 &&
      (landmark.covariance.rows() != k || landmark.covariance.cols() != k))
    throw std::invalid_argument("LandmarkRegistry::insertLandmark: landmark " +
                                std::to_string(landmark.id) + ": covariance is not " +
                                std::to_string(k) + "x" + std::to_string(k) + " for a " +
                                toString(landmark.quadric_map.quadricClass()));
  landmarks_.emplace(landmark.id, landmark);
  next_landmark_id_ = std::max(next_landmark_id_, landmark.id + 1);
}

void LandmarkRegistry::clear() {
  landmarks_.clear();
  candidates_.clear();
  merged_into_.clear();
}

}  // namespace quadric_slam
