// The parameter key tables of the pipeline's core classes: the same keys are read by the nodelets
// (private ROS parameters) and by the offline tools (config/*.yaml). Each function reads the keys
// present, keeps defaults for the rest, logs the effective values and validates (throwing
// std::invalid_argument naming the bad field).
#pragma once

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/io/param_reader.h"
#include "quadric_slam/mapping/batch_refiner.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/reconstruction.h"
#include "quadric_slam/mapping/tracking_recovery.h"
#include "quadric_slam/odometry/odometry_tracker.h"

namespace quadric_slam {

// config/normal_estimation.yaml: decimation, min_range, max_range (back-projection) and
// normal_method, max_depth_change_factor, normal_smoothing_size, depth_dependent_smoothing,
// threads.
void readNormalEstimationParams(const ParamReader& reader, BackProjectionParams& back_projection,
                                NormalEstimator::Params& normals, ParamLog& log);

// config/odometry.yaml, the tracker and ICP keys: pyramid_levels, finest_stride, reference_stride,
// max_iterations, max_correspondence_distance, coarse_distance_factor, max_normal_angle,
// depth_noise_weighting, huber_delta, convergence_translation, convergence_rotation,
// min_correspondences, min_eigenvalue_ratio, noise_information_factor, noise_information_min_depth,
// degenerate_variance, max_translation_from_guess, max_rotation_from_guess, keyframe_translation,
// keyframe_rotation, keyframe_min_overlap, constant_velocity, velocity_hold_time,
// velocity_min_information, lost_frames_before_new_keyframe, the motion guess (guess_*) and the
// increment covariance's calibration (increment_covariance_scale, increment_translation_fraction,
// increment_rotation_per_metre), and the photometric refinement of degenerate alignments
// (photometric_refinement, photometric_information_scale, photometric_*).
void readOdometryParams(const ParamReader& reader, OdometryTracker::Params& params, ParamLog& log);

// config/mapping.yaml: the mapper (candidates, association gate, sliding window, keyframes,
// odometry noise model) and the reconstruction (reconstruction_*). Key names are listed, with
// meaning, unit and default, in config/mapping.yaml.
void readMappingParams(const ParamReader& reader, QuadricMapper::Params& mapper,
                       QuadricReconstruction::Params& reconstruction, ParamLog& log);

// config/mapping.yaml, what the map does after a loss of tracking (mapping/tracking_recovery.h):
// recovery_min_landmark_associations, recovery_confirm_frames, recovery_min_map_landmarks,
// recovery_max_frames; and the relocalisation against the map while recovering
// (mapping/relocaliser.h): relocalisation_enabled, relocalisation_min_supporting_surfaces,
// relocalisation_max_ambiguity, relocalisation_extent_margin, relocalisation_min_plane_points,
// relocalisation_max_angle_difference, relocalisation_max_offset_difference.
void readTrackingRecoveryParams(const ParamReader& reader, TrackingRecovery::Params& params,
                                ParamLog& log);

// config/mapping.yaml, the offline batch refinement at the end of run_bag (never read by the
// nodelets): batch_refinement (on/off), batch_max_iterations, batch_max_keyframes,
// batch_compute_covariance, batch_noise_rounds, batch_noise_tolerance,
// batch_merge_rounds.
void readBatchRefinementParams(const ParamReader& reader, bool& enabled,
                               BatchRefiner::Params& params, ParamLog& log);

// config/mapping.yaml odometry_increment_covariance: whether the mapper's odometry factors carry
// the tracker's increment covariance (true) or the mapper's fixed odometry_* model (false). Read
// by QuadricSlam and the mapping nodelet.
void readOdometryIncrementParams(const ParamReader& reader, bool& use_increment_covariance,
                                 ParamLog& log);

}  // namespace quadric_slam
