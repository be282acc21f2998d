// The mapping back-end, ROS-free: per frame, odometry + the front-end's quadric measurements in,
// T_map_camera (hence T_map_odom) and the landmarks out.
//   1. Predict T_map_camera = T_map_kf (T_odom_kf^-1 T_odom_camera) from the latest keyframe's
//      optimised pose and the odometry since (the paper's "estimated previous pose concatenated
//      with the latest odometry measurement"), with the odometry covariance accumulated since.
//   2. Associate and count (mapping/landmark_registry.h, mapping/association.h).
//   3. Keyframe rule: a frame becomes a keyframe (a pose in the window, with factors) only when it
//      adds information: it is the first; the camera moved more than keyframe_translation or
//      turned more than keyframe_rotation since the last keyframe (odometry); or its view of the
//      map is new: at least keyframe_min_new_landmarks of the landmarks it sees have no factor in
//      the window (new landmarks, or old ones seen again: a loop), or fewer than
//      keyframe_min_overlap of them have one (the view has moved on to other surfaces). Every
//      other frame's observations still update the landmarks' evidence (association and
//      observation counts, stamps, extents, candidates and their promotion) without adding a
//      pose. A landmark promoted on such a frame gets factors from the window keyframes among the
//      frames that made it, else at the next keyframe that sees it.
//   4. On a keyframe, optimise the sliding window (mapping/window.h): bounded cost per frame.
//   5. After the solve, merge the landmarks of the window that are the same surface as another
//      landmark (mapping/landmark_merger.h): the merged landmark's window observations and folded
//      prior move to the survivor, whose estimate is the fusion of both; the merges are reported
//      (MapperFrameResult::merges) so that callers move what they keep per landmark (the
//      reconstruction: applyMergesToReconstruction). Candidates that are the same surface as a
//      landmark join it at promotion (mapping/landmark_registry.h); mergeDuplicates() checks the
//      whole map (before a map is saved). Not in localisation-only mode.
// The map frame is the first frame's odom pose (T_map_odom = identity until corrections), unless
// a saved map was loaded (loadLandmarks below: T_map_odom is then given).
//
// Starting from a saved map: loadLandmarks() seeds the map with landmarks (ids kept), optionally
// held fixed in the window; setLocalizationOnly(true) holds every landmark fixed and promotes no
// candidate, so the map's estimates stay as loaded while the poses are estimated against them.
//
// Bad input has a defined behaviour and never reaches the map:
//   - a stamp not finite or not after the previous accepted frame's: the frame is refused
//     (kRejectedStamp), nothing changes; a looping bag must call reset();
//   - a non-finite or non-rigid T_odom_camera, or an increment covariance that is not 6x6,
//     symmetric, positive definite: the frame is refused (kRejectedOdometry);
//   - a measurement with non-finite quadric parameters, or a covariance that is not k x k,
//     finite, symmetric and positive definite: that measurement is dropped and counted
//     (rejected_measurements), the rest of the frame is used.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/mapping/landmark_registry.h"
#include "quadric_slam/mapping/measurement_model_error.h"
#include "quadric_slam/mapping/reconstruction.h"
#include "quadric_slam/mapping/window.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

// The odometry of one frame.
struct OdometryInput {
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();
  // Covariance of the increment T_previous_this from the previous frame, in this frame's body
  // tangent [rho; phi] (m, rad), 6x6; empty: the Params noise model is used. (OdometryTracker's
  // covariance is cumulative since its start; pass the difference, or leave this empty.)
  Eigen::MatrixXd increment_covariance;
};

enum class FrameStatus { kOk, kRejectedStamp, kRejectedOdometry };

struct MapperFrameResult {
  FrameStatus status = FrameStatus::kOk;
  std::string message;  // why a frame or measurements were refused (empty when all was fine)
  double stamp = 0.0;
  Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
  // Covariance of the odometry increment from the previous accepted frame as the mapper used it
  // (the input's, bounded by the camera's speed, or the Params noise model), this frame's body
  // tangent [rho; phi]; zero for a refused frame.
  Matrix6d increment_covariance = Matrix6d::Zero();
  bool keyframe = false;
  int rejected_measurements = 0;
  // Per accepted measurement, in input order with the rejected ones left out.
  MapUpdate update;
  // Window statistics of this frame's optimisation (zeros for non-keyframes).
  WindowStatistics window;
  // Landmarks merged after this frame's optimisation, in the order they were merged (ids in
  // `update` are those before the merges: map().mergedInto() resolves them).
  std::vector<LandmarkMerge> merges;
  double association_seconds = 0.0;   // wall time of association and bookkeeping
  double optimisation_seconds = 0.0;  // wall time of the window optimisation (keyframes)
  double merge_seconds = 0.0;         // wall time of the duplicate search and merges (keyframes)
};

class QuadricMapper {
 public:
  struct Params {
    LandmarkRegistry::Params map;
    SlidingWindow::Params window;
    // Keyframe rule (see above): m (> 0), rad (> 0), landmarks (int >= 1), fraction [0, 1].
    double keyframe_translation = 0.15;
    double keyframe_rotation = 0.17;
    int keyframe_min_new_landmarks = 2;
    double keyframe_min_overlap = 0.5;
    // Odometry noise model for frames without an increment covariance (1-sigma per increment):
    // sigma_t = translation_sigma + translation_fraction |dt|,
    // sigma_r = rotation_sigma + rotation_fraction |dtheta| + rotation_per_metre |dt|.
    // m, >= 0; >= 0; rad, >= 0; >= 0; rad/m, >= 0 (and sigma_t, sigma_r > 0 overall).
    double odometry_translation_sigma = 0.002;
    double odometry_translation_fraction = 0.05;
    double odometry_rotation_sigma = 0.002;
    double odometry_rotation_fraction = 0.05;
    double odometry_rotation_per_metre = 0.02;
    // The camera's speed bound (1-sigma): an increment covariance from the tracker over dt seconds
    // is clamped to (max_camera_speed dt)^2 in translation and (max_camera_angular_speed dt)^2 in
    // rotation along any direction (mapping/motion_bound.h). m/s, rad/s; > 0, or 0 for no bound.
    double max_camera_speed = 1.0;
    double max_camera_angular_speed = 2.0;
    // The depth camera's systematic error added to every measurement's covariance as it enters
    // the mapper (mapping/measurement_model_error.h), so that the association gate, the window's
    // weights and the merger see what a fragment of a surface really tells.
    MeasurementModelError::Params model_error;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  QuadricMapper() : QuadricMapper(Params{}) {}
  explicit QuadricMapper(const Params& params);

  MapperFrameResult process(const FrameMeasurements& frame, const OdometryInput& odometry);

  // Forgets everything but the id counters (landmark ids are never reused) and the localisation
  // mode.
  void reset();

  // Starts from a saved map: forgets the current state (as reset()), then inserts `landmarks`
  // with their ids, estimates, covariances (empty = unknown), extents (all-zero = unknown) and
  // counts; landmarks promoted later get larger ids. fixed: the loaded landmarks are constant in
  // the window (SlidingWindow::setLandmarkFixed): they correct the poses and are never changed.
  // T_map_odom places the odometry in the loaded map: the next frame's prediction is
  // T_map_odom T_odom_camera (identity: the odometry starts where the map's session started).
  // There is no global relocalisation: that prediction must be within the association gate of
  // the truth (about 10 cm / 3 deg with the default floors) for the landmarks to be recognised, and
  // the first keyframe after loading is held fixed as usual (the window's gauge).
  // Throws std::invalid_argument (id < 1 or repeated, covariance of the wrong size, T_map_odom not
  // rigid) and then leaves the mapper unchanged.
  void loadLandmarks(const std::vector<QuadricLandmark>& landmarks, bool fixed,
                     const Eigen::Isometry3d& T_map_odom = Eigen::Isometry3d::Identity());

  // Localisation only: every landmark is constant in the window and no candidate is promoted, so
  // the landmarks' estimates never change (their observation counts, stamps and extents still do)
  // while the poses are estimated against them. A mode: kept by reset() and loadLandmarks(); off
  // by default.
  void setLocalizationOnly(bool on);
  bool localizationOnly() const { return localization_only_; }

  // The camera was relocalised in the map after a loss of tracking (mapping/relocaliser.h): the
  // odometry since the latest keyframe does not hold across the loss, so the next accepted frame
  // is predicted at T_map_odom T_odom_camera, becomes a keyframe, and its odometry factor to the
  // previous keyframe carries no information (the motion across the loss is unknown). Throws
  // std::invalid_argument when T_map_odom is not rigid.
  void relocalise(const Eigen::Isometry3d& T_map_odom);

  // Tracking was lost before the map held landmarks enough to find the camera again
  // (mapping/tracking_recovery.h): candidates seen in at least min_observations frames (>= 1)
  // become landmarks now, their observations factors in the window keyframes that made them, so
  // that the frames before the loss can be found again. Returns the update (new landmarks and
  // their observations, for a BatchRecorder); empty in localisation-only mode or before the first
  // keyframe.
  MapUpdate promoteObservedCandidates(int min_observations);

  // Merges every pair of landmarks of the map that are the same surface, repeatedly until none
  // is left (call it before saving a map). Returns the merges in order; none in localisation-only
  // mode or with merging disabled.
  std::vector<LandmarkMerge> mergeDuplicates();

  const LandmarkRegistry& map() const { return map_; }
  const SlidingWindow& window() const { return window_; }
  // The landmarks as a list (id order).
  std::vector<QuadricLandmark> landmarks() const;
  const Params& params() const { return params_; }

  // Why a measurement is unusable, or empty when it is fine.
  static std::string validateMeasurement(const QuadricMeasurement& measurement);

 private:
  Matrix6d incrementCovariance(const Eigen::Isometry3d& T_previous_this) const;
  // One pass over the duplicate pairs with a member in `subset` (all landmarks when null).
  std::vector<LandmarkMerge> mergeLandmarks(const std::set<int>* subset);

  Params params_;
  LandmarkRegistry map_;
  SlidingWindow window_;
  int frame_index_ = 0;
  bool has_frame_ = false;
  bool localization_only_ = false;
  // Where the first frame after a reset or a load is placed: T_map_predicted = this T_odom_camera.
  Eigen::Isometry3d T_map_odom_start_ = Eigen::Isometry3d::Identity();
  // Set by relocalise() until the next keyframe uses it.
  std::optional<Eigen::Isometry3d> T_map_odom_relocalised_;
  double last_stamp_ = 0.0;
  Eigen::Isometry3d T_odom_previous_ = Eigen::Isometry3d::Identity();
  Matrix6d covariance_since_keyframe_ = Matrix6d::Zero();  // body tangent of the latest frame
};

// The reconstruction's share of a keyframe, as QuadricSlam and the mapping nodelet compute it: the
// supporting points of the frame's measurements that went to a landmark (fates kLandmark,
// kPromoted and kJoined; a landmark merged since is followed to its survivor), seen from
// result.T_map_camera, added at their landmarks' current estimates in `map`.
// `frame` holds the measurements given to process() (result.update lists only the accepted ones,
// in input order). Call it for keyframes. Returns the number of points stored.
int addKeyframeToReconstruction(const FrameMeasurements& frame, const MapperFrameResult& result,
                                const LandmarkRegistry& map, QuadricReconstruction* reconstruction);

// Moves the reconstruction points of each merged landmark to its survivor, in the order of
// `merges` (QuadricReconstruction::moveLandmark).
void applyMergesToReconstruction(const std::vector<LandmarkMerge>& merges,
                                 QuadricReconstruction* reconstruction);

}  // namespace quadric_slam
