// What the map does after the odometry has lost track. The odometry starts again from its last
// pose once it has a new keyframe, but the camera may have moved meanwhile (a covered lens, a gap
// in a bag, a view of a blank wall): its pose in the map is then unknown, and surfaces seen from it
// would enter the map in the wrong place. So after a loss the mapper only localises: it associates
// the frame's surfaces with the landmarks it already has (nothing new is promoted, landmarks are
// held fixed) until enough of them agree, in enough consecutive frames, that the pose is anchored
// in the map again; then mapping resumes. With relocalisation enabled, frames count as anchoring
// only after the relocaliser has confirmed the pose (poseVerified()). With too few landmarks to
// anchor against, mapping resumes at once (there is nothing to put out of place). When the camera
// moved while the odometry was blind, the odometry's pose associates with nothing: then the frame's
// surfaces are matched against the map's landmarks with no pose prior (mapping/relocaliser.h,
// mapping/recovery_relocalisation.h), the odometry is re-anchored in the map at the relocalised
// pose (relocalised()), and the anchoring and confirmation above run from there. With
// relocalisation disabled, or when it finds nothing, it waits until the view returns, unless
// max_frames lets it give up.
#pragma once

#include "quadric_slam/mapping/landmark_registry.h"
#include "quadric_slam/mapping/relocaliser.h"

namespace quadric_slam {

// How many of a frame's measurements associated with map landmarks.
int landmarkAssociations(const MapUpdate& update);

class TrackingRecovery {
 public:
  struct Params {
    // A frame anchors the pose when at least this many of its observations associate with map
    // landmarks, [1, 100]. Default 3 (a pose has six degrees of freedom; a plane fixes three).
    int min_landmark_associations = 3;
    // Consecutive anchoring frames before mapping resumes, [1, 1000]. Default 3.
    int confirm_frames = 3;
    // Mapping resumes at once after a loss when the map holds fewer landmarks than this, [0, inf).
    int min_map_landmarks = 3;
    // Mapping resumes anyway after this many localising frames without an anchor, [0, inf); 0
    // (the default) waits until the view returns to mapped surfaces. Resuming without an anchor
    // lets the map continue from the odometry's pose, so surfaces seen again may be mapped twice.
    int max_frames = 0;
    // A loss before the map holds min_map_landmarks landmarks (the first frames of a run, before
    // any candidate was seen min_observations times) would leave nothing to find the camera
    // again: the map would go on from the odometry's restart pose, and everything before the loss
    // would stay apart from the rest. So at such a loss the candidates seen in at least this many
    // frames become landmarks (QuadricMapper::promoteObservedCandidates), and when that gives the
    // map min_map_landmarks the recovery runs as after any loss, [0, 1000]; 0: off. Default 3.
    int promote_on_loss_min_observations = 3;
    // After such a promotion the recovery gives up after this many localising frames without an
    // anchor (those few surfaces may never come into view again), and mapping goes on from the
    // odometry's pose as it would without them, [1, 100000]. Default 60 (2 s at 30 Hz).
    int promoted_max_frames = 60;
    // Relocalisation against the map while recovering (config/mapping.yaml relocalisation_*).
    Relocaliser::Params relocaliser;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  TrackingRecovery() : TrackingRecovery(Params{}) {}
  explicit TrackingRecovery(const Params& params);

  // The odometry lost track in this frame (nothing of the frame reaches the mapper).
  // promoted_at_loss: candidates were promoted because of this loss (promoted_max_frames applies).
  void trackingLost(int map_landmarks, bool promoted_at_loss = false);
  // A frame the mapper has processed (localisation only while recovering): how many of its
  // observations associated with landmarks.
  void frameMapped(int landmark_associations);
  // True while the pose is not anchored in the map again: the mapper must localise only.
  bool recovering() const { return recovering_; }
  // While recovering with relocalisation enabled: the relocaliser has found the pose since the
  // loss (at the odometry's pose, or re-anchored there); until then frames do not count as
  // anchoring, since a few associations of large planes (a floor, a wall) also come at a wrong
  // pose. Always true with relocalisation disabled.
  bool poseVerified() const { return verified_ || !params_.relocaliser.enabled; }
  // A relocalisation attempt of a recovering frame: whether it found the pose, and whether it
  // re-anchored the odometry there.
  void relocalisationAttempted(bool found, bool reanchored);
  // Losses since the start, recoveries completed, and recoveries given up after max_frames.
  int losses() const { return losses_; }
  int recoveries() const { return recoveries_; }
  int timeouts() const { return timeouts_; }
  // Relocalisation attempts since the start, and those that re-anchored the odometry in the map.
  int relocalisationAttempts() const { return relocalisation_attempts_; }
  int relocalisations() const { return relocalisations_; }
  void reset();

  const Params& params() const { return params_; }
  const Relocaliser& relocaliser() const { return relocaliser_; }

 private:
  Params params_;
  Relocaliser relocaliser_;
  bool recovering_ = false;
  bool verified_ = false;
  int anchored_frames_ = 0;
  int recovering_frames_ = 0;
  int max_frames_ = 0;  // of the current recovery: max_frames or promoted_max_frames
  int losses_ = 0, recoveries_ = 0, timeouts_ = 0;
  int relocalisation_attempts_ = 0, relocalisations_ = 0;
};

}  // namespace quadric_slam
