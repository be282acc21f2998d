#include "quadric_slam/mapping/tracking_recovery.h"

#include <stdexcept>
#include <string>

namespace quadric_slam {

int landmarkAssociations(const MapUpdate& update) {
  int count = 0;
  for (const MeasurementResult& m : update.measurements)
    count += m.fate == MeasurementFate::kLandmark ? 1 : 0;
  return count;
}

void TrackingRecovery::Params::validate() const {
  const auto check = [](bool ok, const std::string& what) {
    if (!ok)
      throw std::invalid_argument("TrackingRecovery: " + what);
  };
  check(min_landmark_associations >= 1 && min_landmark_associations <= 100,
        "min_landmark_associations must be in [1, 100], got " +
            std::to_string(min_landmark_associations));
  check(confirm_frames >= 1 && confirm_frames <= 1000,
        "confirm_frames must be in [1, 1000], got " + std::to_string(confirm_frames));
  check(min_map_landmarks >= 0,
        "min_map_landmarks must be >= 0, got " + std::to_string(min_map_landmarks));
  check(max_frames >= 0, "max_frames must be >= 0, got " + std::to_string(max_frames));
  check(promote_on_loss_min_observations >= 0 && promote_on_loss_min_observations <= 1000,
        "promote_on_loss_min_observations must be in [0, 1000], got " +
            std::to_string(promote_on_loss_min_observations));
  check(promoted_max_frames >= 1 && promoted_max_frames <= 100000,
        "promoted_max_frames must be in [1, 100000], got " + std::to_string(promoted_max_frames));
  relocaliser.validate();
}

TrackingRecovery::TrackingRecovery(const Params& params)
    : params_((params.validate(), params)), relocaliser_(params.relocaliser) {}

void TrackingRecovery::trackingLost(int map_landmarks, bool promoted_at_loss) {
  anchored_frames_ = 0;
  verified_ = false;
  recovering_frames_ = 0;
  if (map_landmarks < params_.min_map_landmarks)
    return;  // nothing to anchor against, nothing to put out of place
  if (!recovering_) {
    ++losses_;
    max_frames_ = promoted_at_loss ? params_.promoted_max_frames : params_.max_frames;
  }
  recovering_ = true;
}

void TrackingRecovery::frameMapped(int landmark_associations) {
  if (!recovering_)
    return;
  anchored_frames_ = landmark_associations >= params_.min_landmark_associations && poseVerified()
                         ? anchored_frames_ + 1
                         : 0;
  ++recovering_frames_;
  if (anchored_frames_ >= params_.confirm_frames) {
    recovering_ = false;
    ++recoveries_;
  } else if (max_frames_ > 0 && recovering_frames_ >= max_frames_) {
    recovering_ = false;
    ++timeouts_;
  }
  if (!recovering_)
    anchored_frames_ = recovering_frames_ = 0;
}

void TrackingRecovery::relocalisationAttempted(bool found, bool reanchored) {
  ++relocalisation_attempts_;
  verified_ = verified_ || found;
  if (reanchored) {
    ++relocalisations_;
    anchored_frames_ = 0;  // the anchoring frames count from the new pose
  }
}

void TrackingRecovery::reset() {
  recovering_ = false;
  verified_ = false;
  anchored_frames_ = recovering_frames_ = 0;
}

}  // namespace quadric_slam
