// The whole SLAM system for one depth camera, ROS-free: one frame in; normals, quadric
// segmentation, odometry, mapping and reconstruction out (the paper's Section IV, Fig. 2).
// The offline runner (scripts/run_bag) is a thin shell over this class; each nodelet wraps one of
// the same stage classes with the same parameters (config/*.yaml, pipeline/pipeline_params.h).
//
// Per frame:
//   1. time rule: a stamp not after the previous frame's (a looping bag, a restarted player)
//      resets odometry, map and reconstruction before the frame is used (SlamFrameResult::reset);
//   2. the depth image must fit its intrinsics, else the frame is skipped (processed = false);
//   3. back-projection + normals (frontend/normal_estimator.h);
//   4. quadric segmentation (frontend/quadric_segmenter.h), unless odometry only;
//   5. odometry (odometry/odometry_tracker.h);
//   6. mapping (mapping/quadric_mapper.h) once odometry is initialised, and on keyframes the
//      supporting points of the landmark observations into the reconstruction (after moving the
//      points of landmarks the mapper merged), coloured from frame.rgb when the frame has one
//      (frontend/support_colours.h: RGB registered to depth). A frame whose odometry is lost
//      reaches no mapper; after a loss the mapper localises only until the surfaces anchor the
//      pose in the map again (mapping/tracking_recovery.h); while it waits, a frame that does not
//      anchor is first relocalised against the map's landmarks, and the odometry re-anchored in
//      the map where it was found (mapping/recovery_relocalisation.h).
// Every stage is timed under its name (timer()): normals, segmentation, odometry, relocalisation
// (only frames that tried), mapping, reconstruction.
// With batch_refinement (offline only: run_bag) every mapped frame and keyframe is also recorded
// (mapping/batch_recorder.h; memory grows with the run) so that refineBatch() can solve the whole
// run at the end (mapping/batch_refiner.h).
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <map>
#include <string>
#include <vector>

#include "quadric_slam/eval/stage_timing.h"
#include "quadric_slam/frontend/depth_correction.h"
#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/param_reader.h"
#include "quadric_slam/mapping/batch_recorder.h"
#include "quadric_slam/mapping/batch_refiner.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/reconstruction.h"
#include "quadric_slam/mapping/recovery_relocalisation.h"
#include "quadric_slam/mapping/tracking_recovery.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

struct SlamParams {
  BackProjectionParams back_projection;
  // The sensor's fixed depth distortion, undone on every frame before the normals (empty: none;
  // frontend/depth_correction.h, estimated by the calibrate_depth tool). It must span the depth
  // images' size, else the frames are skipped with the problem named.
  DepthCorrection depth_correction;
  NormalEstimator::Params normals;
  QuadricSegmenter::Params segmentation;
  OdometryTracker::Params odometry;
  QuadricMapper::Params mapping;
  QuadricReconstruction::Params reconstruction;
  TrackingRecovery::Params recovery;
  // Supporting points each observation carries to the mapper (segmentation.yaml
  // max_support_points; frontend/detection_measurement.h), >= 0.
  int max_support_points = 1000;
  // false: normals and odometry only (no segmentation, no map).
  bool mapping_enabled = true;
  // Record the run for the offline batch refinement (mapping.yaml batch_refinement; run_bag only,
  // the nodelets never read it: the recording grows with the run) and its solver parameters.
  bool batch_refinement = false;
  BatchRefiner::Params batch;
  // mapping.yaml odometry_increment_covariance: the mapper's odometry factors carry the tracker's
  // increment covariance (OdometryTracker::Result::increment_covariance, the increments of frames
  // the mapper did not take composed into the next one; across a loss of tracking the mapper's
  // own model); false: the mapper's fixed odometry_* noise model.
  bool odometry_increment_covariance = false;

  // Throws std::invalid_argument naming the bad field (of whichever stage) and its range.
  void validate() const;
};

// Reads config_dir/{normal_estimation,segmentation,odometry,mapping}.yaml through the key tables
// the nodelets use (and mapping.yaml's batch_* keys, which only the offline runner uses); absent
// files keep the defaults of their stage. The effective values go to *log when given. Throws
// std::runtime_error (unreadable file) or std::invalid_argument (bad value).
// profile_dir (optional, e.g. config/profiles/qvga): files of the same names whose keys replace
// those of config_dir's files (a profile holds only the keys it changes; absent files change
// nothing), as the launch files' `profile` argument loads them after config/*.yaml.
SlamParams loadSlamParams(const std::string& config_dir, ParamLog* log = nullptr,
                          const std::string& profile_dir = "");
// The directory of a profile: NAME (no '/') is config_dir/profiles/NAME, anything else a path.
std::string profileDirectory(const std::string& config_dir, const std::string& profile);

struct SlamFrameResult {
  double stamp = 0.0;
  bool reset = false;      // time went backwards: everything was reset before this frame
  bool processed = false;  // false: skipped (message says why), nothing changed
  std::string message;     // why the frame was skipped, or what a stage refused
  OdometryTracker::Result odometry;
  bool tracking = false;           // odometry is initialised (odometry.T_odom_camera is meaningful)
  FrameMeasurements measurements;  // the segmentation's observations (camera frame)
  bool mapped = false;             // the mapper accepted the frame (mapping is meaningful)
  // The mapper localised only (after a loss of tracking; nothing was added to the map). Also true
  // for a lost frame while the map still waits to be anchored.
  bool recovering = false;
  // The relocalisation attempt of a recovering frame (attempted = false when none was needed).
  RecoveryRelocalisation relocalisation;
  MapperFrameResult mapping;
  double odometry_ms = 0.0, mapping_ms = 0.0;  // wall time of the two stages (0: not run)
};

// What the front end (steps 2-4: checks, normals, segmentation) makes of one frame. It depends on
// the frame alone, never on the odometry or the map, so the front end of the next frame may run on
// another thread while the back end (steps 1, 5, 6) works on this one (scripts/run_bag
// --pipelined). The storage is reused when the same object is filled again.
struct FrontEndFrame {
  double stamp = 0.0;
  std::string frame_id;
  CameraIntrinsics intrinsics;
  std::string problem;  // not empty: the frame cannot be used (the back end skips it, saying why)
  std::string colour_problem;  // not empty: the RGB image could not colour the supporting points
  pcl::PointCloud<pcl::PointNormal> cloud;  // organized, with normals (camera frame)
  cv::Mat rgb;  // the frame's RGB image (shared, not copied), or empty: the odometry's intensities
  Segmentation segmentation;
  FrameMeasurements measurements;
  double normals_ms = 0.0, segmentation_ms = 0.0;  // timed stages (segmentation 0 when not run)
};

class QuadricSlam {
 public:
  explicit QuadricSlam(const SlamParams& params);

  // backEnd(frontEnd(frame)), on this thread.
  SlamFrameResult process(const RgbdFrame& frame);

  // The front end: fills *out from the frame alone. It touches only the normal estimator and the
  // segmenter (both const), so one thread may run it while another runs backEnd() on an earlier
  // frame; two threads must not run frontEnd() at once on the same *out.
  void frontEnd(const RgbdFrame& frame, FrontEndFrame* out) const;
  // The back end, in frame order: the time rule, odometry, mapping, reconstruction, and the stage
  // timings of the front end. Takes the frame's cloud and segmentation (cloud(), segmentation());
  // *front is left holding the previous frame's storage, for reuse.
  SlamFrameResult backEnd(FrontEndFrame* front);

  // Forgets odometry, map and reconstruction (landmark ids keep counting).
  void reset();
  // Merges every pair of landmarks that are the same surface (QuadricMapper::mergeDuplicates) and
  // moves their reconstruction points to the survivors; call it before saving the map.
  std::vector<LandmarkMerge> mergeDuplicateLandmarks();
  // With params().batch_refinement: one global solve over every keyframe and landmark since the
  // last reset (mapping/batch_refiner.h), the mapped frames re-attached to the refined keyframes
  // (mapping/frame_reattachment.h). Leaves the online state as it is. A run of more than
  // batch.max_keyframes keyframes is neither recorded nor solved (the solution is then empty and
  // not usable, its report says why). Throws std::logic_error when batch_refinement is off.
  BatchSolution refineBatch() const;
  const BatchRecorder& batchRecorder() const { return batch_recorder_; }

  const SlamParams& params() const { return params_; }
  const QuadricMapper& mapper() const { return mapper_; }
  const OdometryTracker& odometry() const { return odometry_; }
  const QuadricReconstruction& reconstruction() const { return reconstruction_; }
  const TrackingRecovery& recovery() const { return recovery_; }
  // The landmarks' points on their current surfaces, label = landmark id, rgba = the colour of the
  // pixel the point came from when the frames had RGB (alpha 0: uncoloured).
  pcl::PointCloud<pcl::PointXYZRGBL> reconstructionCloud() const;
  // The latest frame's organized cloud with normals, and its segmentation (labels per point).
  const pcl::PointCloud<pcl::PointNormal>& cloud() const { return cloud_; }
  const Segmentation& segmentation() const { return segmentation_; }
  const StageTimer& timer() const { return timer_; }

 private:
  void addToReconstruction(const FrameMeasurements& measurements, const MapperFrameResult& mapped);

  SlamParams params_;
  NormalEstimator normals_;
  QuadricSegmenter segmenter_;
  OdometryTracker odometry_;
  QuadricMapper mapper_;
  QuadricReconstruction reconstruction_;
  TrackingRecovery recovery_;
  BatchRecorder batch_recorder_;  // empty unless params_.batch_refinement
  bool batch_overflow_ = false;   // more than batch.max_keyframes: recording stopped
  StageTimer timer_;
  bool has_stamp_ = false;
  double last_stamp_ = 0.0;
  // The tracker's increments since the last frame the mapper took, composed (right perturbation
  // in the latest frame's body tangent); valid once the mapper has taken a frame since the
  // tracker (re)started, before that the mapper's own model is used.
  Matrix6d increment_covariance_since_mapped_ = Matrix6d::Zero();
  bool increment_since_mapped_valid_ = false;
  // The mapper's latest map->odom correction (of the latest mapped frame).
  Eigen::Isometry3d T_map_odom_ = Eigen::Isometry3d::Identity();
  pcl::PointCloud<pcl::PointNormal> cloud_;  // the latest frame's
  // process(): the storage of the frame before, which the next front end fills (no allocation of
  // a cloud per frame).
  pcl::PointCloud<pcl::PointNormal> spare_cloud_;
  Segmentation segmentation_;
};

}  // namespace quadric_slam
