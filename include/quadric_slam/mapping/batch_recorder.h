// What the offline batch refinement (mapping/batch_refiner.h) needs, recorded as the online mapper
// runs: every keyframe (stamp, latest online estimate, odometry from the previous keyframe with
// its covariance, its validated landmark observations with their covariances) and every mapped
// frame (stamp, odometry pose, the keyframe it hangs from).
//
// Observations follow the mapper's merges: the observations of a merged landmark are renamed to
// its survivor as the merges are reported (MapperFrameResult::merges, and those of
// QuadricMapper::mergeDuplicates through recordMerges), so the batch sees surviving landmarks
// only, as the window does (SlidingWindow::mergeLandmark).
//
// The observations of a promoted candidate (or of one that joined a landmark) made on keyframes
// become that landmark's factors here whether or not the keyframe is still in the window (the
// window can only add those of its own keyframes): the batch has every keyframe.
//
// Memory grows with the keyframes and frames of the run (a few KB per keyframe, 100 bytes per
// frame): for offline use only (run_bag), never in the live nodelet.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/window.h"

namespace quadric_slam {

// A keyframe as the batch sees it: the window's Keyframe (frame index, stamp, estimate, odometry
// pose, odometry from the previous recorded keyframe and its covariance, observations).
using RecordedKeyframe = Keyframe;

// A mapped frame: its odometry pose and the keyframe it is re-attached to (the latest keyframe at
// or before it, as the mapper predicted it).
struct RecordedFrame {
  double stamp = 0.0;                                               // s
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();  // odometry
  Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();   // online estimate
  // Covariance of the odometry increment from the previous recorded frame (body tangent of this
  // frame, [rho; phi]; MapperFrameResult::increment_covariance).
  Matrix6d increment_covariance = Matrix6d::Zero();
  int keyframe = -1;  // index into BatchRecorder::keyframes(); -1 before the first keyframe
  bool is_keyframe = false;
};

class BatchRecorder {
 public:
  // After each QuadricMapper::process(): an accepted frame is recorded (a refused one is not);
  // on a keyframe the mapper's newest window keyframe is copied; the observations of promoted or
  // joined candidates go to the recorded keyframes that made them; the estimates of the window's
  // keyframes are refreshed; then result.merges are applied.
  void record(const MapperFrameResult& result, const QuadricMapper& mapper);
  // The observations of landmarks promoted (or joined) outside process()
  // (QuadricMapper::promoteObservedCandidates), except those of frame index this_frame.
  void recordPromotions(const MapUpdate& update, int this_frame = -1);
  // Merges made outside process() (QuadricMapper::mergeDuplicates), in their order.
  void recordMerges(const std::vector<LandmarkMerge>& merges);
  // Forgets everything (the mapper was reset).
  void clear();

  const std::vector<RecordedKeyframe>& keyframes() const { return keyframes_; }
  const std::vector<RecordedFrame>& frames() const { return frames_; }
  // Observations recorded over all keyframes.
  std::size_t observations() const;

 private:
  void addObservation(int frame_index, const WindowObservation& observation);
  void renameLandmark(int merged_id, int survivor_id);

  std::vector<RecordedKeyframe> keyframes_;
  std::map<int, std::size_t> keyframe_of_frame_index_;  // mapper frame index -> keyframes_ index
  std::vector<RecordedFrame> frames_;
};

}  // namespace quadric_slam
