// The map's bookkeeping: landmarks and candidates (the paper's experimental system: "we require a
// quadric to have been observed in 5 frames before it is added"). Each frame's measurements are
// associated (mapping/association.h) first against the landmarks, the rest against the candidates;
// a measurement matching neither starts a new candidate. A candidate seen in min_observations
// frames becomes a landmark with a fresh id (landmark ids are never reused), unless it is the same
// surface as a landmark (mapping/landmark_merger.h; the candidate's estimate has no marginal, so
// the merger's missing covariance stands for it): then it joins that landmark instead. A candidate
// not seen for candidate_timeout_frames frames expires, so spurious one-off detections never reach
// the map. A measurement (or a candidate at promotion) whose surface lies on a landmark of another
// class (a cone's band fitted as a cylinder, a patch as a sphere: association_cross_class.h) is
// counted on that landmark without a factor: one surface, one landmark, whichever class a frame's
// fit chose. Landmarks found to be one surface later are merged through absorbLandmark(), which
// keeps a record of the merged ids for subscribers (mergedInto()).
// Landmark estimates are refined elsewhere (mapping/window.h); here they are created and counted.
// (The map as published is the message quadric_slam/QuadricMap, ros/map_publisher.h.)
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <vector>

#include "quadric_slam/mapping/association.h"
#include "quadric_slam/mapping/landmark.h"
#include "quadric_slam/mapping/landmark_merger.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

// One frame's measurement of a candidate, kept so that a promoted landmark can receive the factors
// of the frames that made it.
struct CandidateObservation {
  int frame_index = 0;
  QuadricMeasurement measurement;
};

struct QuadricCandidate {
  int id = 0;                  // candidate id (own counter; never a landmark id)
  QuadricModel quadric_map;    // the latest measurement moved into the map at its predicted pose
  Eigen::MatrixXd covariance;  // that measurement's covariance (body tangents are invariant)
  ExtentBox extent;            // union of the observed boxes, in quadric_map's frame
  int observations = 0;        // frames that saw it
  int last_frame = 0;          // frame index of the latest
  double last_observed = 0.0;  // stamp of the latest (s)
  std::vector<CandidateObservation> history;  // the latest min_observations observations
};

// What happened to each measurement of a frame.
enum class MeasurementFate {
  kLandmark,      // associated with landmark `id`
  kCandidate,     // associated with candidate `id`
  kNewCandidate,  // started candidate `id`
  kPromoted,      // its candidate reached min_observations: now landmark `id`
  kJoined,        // its candidate reached min_observations and was the same surface as landmark
                  // `id` (landmark_merger.h): it joined it
};

struct MeasurementResult {
  MeasurementFate fate = MeasurementFate::kNewCandidate;
  int id = 0;
  Association landmark_association;  // the association against the landmarks
  // kLandmark through the cross-class surface test (association_cross_class.h): the measurement
  // is of another class than landmark `id`, so it counts on it but makes no factor.
  bool without_factor = false;
};

struct MapUpdate {
  std::vector<MeasurementResult> measurements;  // one per input measurement, same order
  // Landmarks created this frame, with the observations of the candidate they came from (this
  // frame's included).
  std::vector<int> promoted;
  std::vector<std::vector<CandidateObservation>> promoted_history;
  // Candidates that joined an existing landmark at promotion, with their observations (this
  // frame's included), to become that landmark's factors.
  struct Joined {
    int landmark_id = 0;
    std::vector<CandidateObservation> history;
  };
  std::vector<Joined> joined;
  int expired_candidates = 0;
};

class LandmarkRegistry {
 public:
  struct Params {
    // Frames a candidate must be seen in before it becomes a landmark (the paper's 5), [1, 1000].
    int min_observations = 5;
    // A candidate not seen for more than this many frames is dropped, [1, 100000].
    int candidate_timeout_frames = 15;
    QuadricAssociator::Params association;
    LandmarkMerger::Params merging;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  LandmarkRegistry() : LandmarkRegistry(Params{}) {}
  explicit LandmarkRegistry(const Params& params);

  // Associates a frame's (valid) measurements at the predicted pose T_map_camera with prediction
  // covariance pose_covariance (6x6, body tangent), updates counts, stamps and extents, starts,
  // promotes and expires candidates. frame_index must increase from call to call.
  MapUpdate integrate(int frame_index, double stamp,
                      const std::vector<QuadricMeasurement>& measurements,
                      const Eigen::Isometry3d& T_map_camera, const Matrix6d& pose_covariance);

  const std::map<int, QuadricLandmark>& landmarks() const { return landmarks_; }
  // Throws std::out_of_range for an unknown id.
  const QuadricLandmark& landmark(int id) const { return landmarks_.at(id); }
  // The refiner's write access to an estimate (quadric and covariance); the extent is re-expressed
  // in the new quadric frame. Throws std::out_of_range for an unknown id.
  void setEstimate(int id, const QuadricModel& quadric_map, const Eigen::MatrixXd& covariance);
  const std::vector<QuadricCandidate>& candidates() const { return candidates_; }
  // Promotes at once every candidate seen in at least min_observations frames (>= 1) that is not
  // a surface the map holds already (same class, or another class's landmark it lies on, in range
  // of T_map_camera): the map's start after a loss of tracking that came before min_observations
  // (mapping/tracking_recovery.h). Ignores promotion(); the update lists the new landmarks with the
  // observations they came from (measurements is empty). Throws std::invalid_argument for
  // min_observations < 1.
  MapUpdate promoteObserved(int min_observations, const Eigen::Isometry3d& T_map_camera);

  // Adds a landmark known from elsewhere (a saved map) under its own id; landmarks promoted later
  // get larger ids. Throws std::invalid_argument when the id is < 1 or already in use, or the
  // covariance is neither empty nor k x k for the landmark's class.
  void insertLandmark(const QuadricLandmark& landmark);
  // false: candidates are still associated, counted and expired but never become landmarks
  // (localisation against a fixed map). A mode, kept by clear(); default true.
  void setPromotion(bool enabled) { promotion_ = enabled; }
  bool promotion() const { return promotion_; }

  // Replaces landmark survivor.id by `survivor` (LandmarkMerger::fused) and removes landmark
  // merged_id, recording merged_id -> survivor.id (and re-pointing earlier records that named
  // merged_id). Throws std::out_of_range for unknown ids, std::invalid_argument when they are
  // equal.
  void absorbLandmark(int merged_id, const QuadricLandmark& survivor);
  // Every landmark merged away since the last clear(), with the landmark that holds its surface
  // now (chains resolved: always a landmark of the map).
  const std::map<int, int>& mergedInto() const { return merged_into_; }

  // Forgets landmarks, candidates and the merge record; ids keep counting (never reused).
  void clear();

  const Params& params() const { return params_; }
  const QuadricAssociator& associator() const { return associator_; }
  const LandmarkMerger& merger() const { return merger_; }

 private:
  // The landmark (in range of the camera) that `candidate` is the same surface as, or 0.
  int sameSurfaceLandmark(const QuadricCandidate& candidate,
                          const Eigen::Isometry3d& T_map_camera) const;
  // The landmark of another class (association_cross_class.h: in range of the camera, extents
  // overlapping) whose surface lies nearest to `observed` over the box `observed_box` (in
  // observed's frame), within the association's cross-class gate for a fit of RMS fit_rms
  // (QuadricAssociator::Params::crossClassGate); 0 when none.
  int otherClassLandmark(const QuadricModel& observed, const ExtentBox& observed_box,
                         double fit_rms, const Eigen::Isometry3d& T_map_camera) const;

  Params params_;
  QuadricAssociator associator_;
  LandmarkMerger merger_;
  std::map<int, QuadricLandmark> landmarks_;
  std::map<int, int> merged_into_;
  std::vector<QuadricCandidate> candidates_;
  int next_landmark_id_ = 1;
  int next_candidate_id_ = 1;
  bool promotion_ = true;
};

}  // namespace quadric_slam
