#include "quadric_slam/mapping/batch_recorder.h"

namespace quadric_slam {

void BatchRecorder::record(const MapperFrameResult& result, const QuadricMapper& mapper) {
  if (result.status != FrameStatus::kOk)
    return;
  const std::deque<Keyframe>& window = mapper.window().keyframes();
  if (result.keyframe && !window.empty()) {
    keyframe_of_frame_index_[window.back().frame_index] = keyframes_.size();
    keyframes_.push_back(window.back());
  }
  RecordedFrame frame;
  frame.stamp = result.stamp;
  frame.T_map_camera = result.T_map_camera;
  frame.T_odom_camera = result.T_map_odom.inverse() * result.T_map_camera;
  frame.increment_covariance = result.increment_covariance;
  frame.keyframe = static_cast<int>(keyframes_.size()) - 1;
  frame.is_keyframe = result.keyframe;
  frames_.push_back(frame);

  // The earlier observations of promoted candidates and of candidates that joined a landmark
  // (this frame's are in the keyframe copied above).
  const int this_frame = result.keyframe && !window.empty() ? window.back().frame_index : -1;
  recordPromotions(result.update, this_frame);

  // The window's latest estimates are the batch's starting point.
  for (const Keyframe& keyframe : window) {
    const auto it = keyframe_of_frame_index_.find(keyframe.frame_index);
    if (it != keyframe_of_frame_index_.end())
      keyframes_[it->second].T_map_camera = keyframe.T_map_camera;
  }
  recordMerges(result.merges);
}

void BatchRecorder::recordPromotions(const MapUpdate& update, int this_frame) {
  for (std::size_t p = 0; p < update.promoted.size() && p < update.promoted_history.size(); ++p)
    for (const CandidateObservation& o : update.promoted_history[p])
      if (o.frame_index != this_frame)
        addObservation(o.frame_index, {update.promoted[p], o.measurement});
  for (const MapUpdate::Joined& joined : update.joined)
    for (const CandidateObservation& o : joined.history)
      if (o.frame_index != this_frame)
        addObservation(o.frame_index, {joined.landmark_id, o.measurement});
}

void BatchRecorder::addObservation(int frame_index, const WindowObservation& observation) {
  const auto it = keyframe_of_frame_index_.find(frame_index);
  if (it == keyframe_of_frame_index_.end())
    return;  // made on a frame that is not a keyframe: no pose to hang it on (as in the window)
  // Keyframes are copied on their own frame, before any later frame's promotion could add to
  // them in the window: each such observation arrives here once.
  keyframes_[it->second].observations.push_back(observation);
}

void BatchRecorder::recordMerges(const std::vector<LandmarkMerge>& merges) {
  for (const LandmarkMerge& merge : merges)
    renameLandmark(merge.merged_id, merge.survivor_id);
}

void BatchRecorder::renameLandmark(int merged_id, int survivor_id) {
  if (merged_id == survivor_id)
    return;
  // The same measurements, now factors on the survivor (the observation factor compares
  // surfaces, not frames: mapping/factors.h).
  for (RecordedKeyframe& keyframe : keyframes_)
    for (WindowObservation& observation : keyframe.observations)
      if (observation.landmark_id == merged_id)
        observation.landmark_id = survivor_id;
}

void BatchRecorder::clear() {
  keyframes_.clear();
  keyframe_of_frame_index_.clear();
  frames_.clear();
}

std::size_t BatchRecorder::observations() const {
  std::size_t n = 0;
  for (const RecordedKeyframe& keyframe : keyframes_)
    n += keyframe.observations.size();
  return n;
}

}  // namespace quadric_slam
