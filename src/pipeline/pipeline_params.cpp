#include "quadric_slam/pipeline/pipeline_params.h"

namespace quadric_slam {

void readNormalEstimationParams(const ParamReader& reader, BackProjectionParams& back_projection,
                                NormalEstimator::Params& normals, ParamLog& log) {
  readParam(reader, "decimation", back_projection.decimation, log);
  readParam(reader, "min_range", back_projection.min_range, log);
  readParam(reader, "max_range", back_projection.max_range, log);
  readParam(reader, "normal_method", normals.method, log);
  readParam(reader, "max_depth_change_factor", normals.max_depth_change_factor, log);
  readParam(reader, "normal_smoothing_size", normals.normal_smoothing_size, log);
  readParam(reader, "depth_dependent_smoothing", normals.depth_dependent_smoothing, log);
  readParam(reader, "threads", normals.threads, log);
  readParam(reader, "normal_stride", normals.normal_stride, log);
  back_projection.validate();
  normals.validate();
}

void readOdometryParams(const ParamReader& reader, OdometryTracker::Params& params, ParamLog& log) {
  PointToPlaneIcp::Params& icp = params.icp;
  readParam(reader, "pyramid_levels", icp.pyramid_levels, log);
  readParam(reader, "finest_stride", icp.finest_stride, log);
  readParam(reader, "reference_stride", icp.reference_stride, log);
  readParam(reader, "max_iterations", icp.max_iterations, log);
  readParam(reader, "max_correspondence_distance", icp.max_correspondence_distance, log);
  readParam(reader, "coarse_distance_factor", icp.coarse_distance_factor, log);
  readParam(reader, "max_normal_angle", icp.max_normal_angle, log);
  readParam(reader, "depth_noise_weighting", icp.depth_noise_weighting, log);
  readParam(reader, "huber_delta", icp.huber_delta, log);
  readParam(reader, "convergence_translation", icp.convergence_translation, log);
  readParam(reader, "convergence_rotation", icp.convergence_rotation, log);
  readParam(reader, "min_correspondences", icp.min_correspondences, log);
  readParam(reader, "min_eigenvalue_ratio", icp.min_eigenvalue_ratio, log);
  readParam(reader, "noise_information_factor", icp.noise_information_factor, log);
  readParam(reader, "noise_information_min_depth", icp.noise_information_min_depth, log);
  readParam(reader, "degenerate_variance", icp.degenerate_variance, log);
  readParam(reader, "max_translation_from_guess", icp.max_translation_from_guess, log);
  readParam(reader, "max_rotation_from_guess", icp.max_rotation_from_guess, log);
  readParam(reader, "min_overlap_inlier_fraction", icp.min_overlap_inlier_fraction, log);
  readParam(reader, "max_rms_residual", icp.max_rms_residual, log);
  readParam(reader, "gate_growth_depth", icp.gate_growth_depth, log);
  readParam(reader, "keyframe_translation", params.keyframe_translation, log);
  readParam(reader, "keyframe_rotation", params.keyframe_rotation, log);
  readParam(reader, "keyframe_min_overlap", params.keyframe_min_overlap, log);
  readParam(reader, "constant_velocity", params.constant_velocity, log);
  readParam(reader, "zero_motion_start", params.zero_motion_start, log);
  readParam(reader, "velocity_hold_time", params.velocity_hold_time, log);
  readParam(reader, "velocity_min_information", params.velocity_min_information, log);
  readParam(reader, "lost_frames_before_new_keyframe", params.lost_frames_before_new_keyframe, log);
  readParam(reader, "quadric_motion_guess", params.quadric_motion_guess, log);
  readParam(reader, "guess_min_translation", params.guess_min_translation, log);
  readParam(reader, "guess_skip_inlier_fraction", params.guess_skip_inlier_fraction, log);
  readParam(reader, "guess_min_rotation", params.guess_min_rotation, log);
  SurfaceNormalParams& surface_normals = params.surface_normals;
  readParam(reader, "surface_normals", surface_normals.enabled, log);
  readParam(reader, "surface_normal_max_distance_rms", surface_normals.max_distance_rms, log);
  readParam(reader, "surface_normal_min_max_distance", surface_normals.min_max_distance, log);
  readParam(reader, "surface_normal_max_angle", surface_normals.max_angle, log);
  readParam(reader, "surface_normal_min_depth", surface_normals.min_depth, log);
  QuadricMotionGuesser::Params& guess = params.guess;
  readParam(reader, "guess_max_angle_difference", guess.max_angle_difference, log);
  readParam(reader, "guess_max_offset_difference", guess.max_offset_difference, log);
  readParam(reader, "guess_max_radius_fraction", guess.max_radius_fraction, log);
  readParam(reader, "guess_min_pair_angle", guess.min_pair_angle, log);
  readParam(reader, "guess_min_plane_points", guess.min_plane_points, log);
  readParam(reader, "guess_max_direction_features", guess.max_direction_features, log);
  readParam(reader, "guess_max_rotation_from_prior", guess.max_rotation_from_prior, log);
  readParam(reader, "guess_max_translation_from_prior", guess.max_translation_from_prior, log);
  readParam(reader, "guess_min_supporting_surfaces", guess.min_supporting_surfaces, log);
  readParam(reader, "feature_motion_guess", params.feature_motion_guess, log);
  FeatureMotionGuesser::Params& features = params.features;
  readParam(reader, "feature_max_features", features.max_features, log);
  readParam(reader, "feature_fast_threshold", features.fast_threshold, log);
  readParam(reader, "feature_pyramid_levels", features.pyramid_levels, log);
  readParam(reader, "feature_match_ratio", features.match_ratio, log);
  readParam(reader, "feature_min_depth", features.min_depth, log);
  readParam(reader, "feature_max_depth", features.max_depth, log);
  readParam(reader, "feature_inlier_pixels", features.inlier_pixels, log);
  readParam(reader, "feature_inlier_distance", features.inlier_distance, log);
  readParam(reader, "feature_inlier_distance_per_z2", features.inlier_distance_per_z2, log);
  readParam(reader, "feature_ransac_iterations", features.ransac_iterations, log);
  readParam(reader, "feature_min_inliers", features.min_inliers, log);
  readParam(reader, "feature_min_inlier_fraction", features.min_inlier_fraction, log);
  readParam(reader, "feature_min_spread", features.min_spread, log);
  readParam(reader, "feature_min_interval", params.feature_min_interval, log);
  readParam(reader, "feature_history_keyframes", params.feature_history_keyframes, log);
  readParam(reader, "feature_pose_sigma_translation", params.feature_pose_sigma_translation, log);
  readParam(reader, "feature_pose_sigma_rotation", params.feature_pose_sigma_rotation, log);
  readParam(reader, "feature_max_speed", params.feature_max_speed, log);
  readParam(reader, "feature_max_turn_rate", params.feature_max_turn_rate, log);
  readParam(reader, "feature_fusion_icp_bias_per_z2", params.feature_fusion_icp_bias_per_z2, log);
  readParam(reader, "feature_fusion_corner_floor", params.feature_fusion_corner_floor, log);
  readParam(reader, "increment_covariance_scale", params.increment_covariance_scale, log);
  readParam(reader, "increment_translation_fraction", params.increment_translation_fraction, log);
  readParam(reader, "increment_rotation_per_metre", params.increment_rotation_per_metre, log);
  readParam(reader, "photometric_refinement", params.photometric_refinement, log);
  readParam(reader, "photometric_information_scale", params.photometric_information_scale, log);
  readParam(reader, "photometric_depth_floor_translation",
            params.photometric_depth_floor_translation, log);
  readParam(reader, "photometric_depth_floor_rotation", params.photometric_depth_floor_rotation,
            log);
  PhotometricRefinement::Params& photometric = params.photometric;
  readParam(reader, "photometric_levels", photometric.levels, log);
  readParam(reader, "photometric_max_iterations", photometric.max_iterations, log);
  readParam(reader, "photometric_max_points", photometric.max_points, log);
  readParam(reader, "photometric_min_gradient", photometric.min_gradient, log);
  readParam(reader, "photometric_huber", photometric.huber, log);
  readParam(reader, "photometric_min_points", photometric.min_points, log);
  readParam(reader, "photometric_max_translation", photometric.max_translation, log);
  readParam(reader, "photometric_max_rotation", photometric.max_rotation, log);
  params.validate();
}

void readMappingParams(const ParamReader& reader, QuadricMapper::Params& mapper,
                       QuadricReconstruction::Params& reconstruction, ParamLog& log) {
  LandmarkRegistry::Params& map = mapper.map;
  readParam(reader, "min_observations", map.min_observations, log);
  readParam(reader, "candidate_timeout_frames", map.candidate_timeout_frames, log);
  QuadricAssociator::Params& association = map.association;
  readParam(reader, "gate_probability", association.gate_probability, log);
  readParam(reader, "floor_translation_sigma", association.floor_translation_sigma, log);
  readParam(reader, "floor_rotation_sigma", association.floor_rotation_sigma, log);
  readParam(reader, "floor_scale_fraction", association.floor_scale_fraction, log);
  readParam(reader, "pose_translation_sigma", association.pose_translation_sigma, log);
  readParam(reader, "pose_rotation_sigma", association.pose_rotation_sigma, log);
  readParam(reader, "correlated_noise_fraction", association.correlated_noise_fraction, log);
  readParam(reader, "noise_correlation_angle", association.noise_correlation_angle, log);
  readParam(reader, "check_extent", association.check_extent, log);
  readParam(reader, "extent_margin", association.extent_margin, log);
  readParam(reader, "association_max_range", association.max_range, log);
  readParam(reader, "cross_class_distance", association.cross_class_distance, log);
  readParam(reader, "cross_class_rms_factor", association.cross_class_rms_factor, log);
  LandmarkMerger::Params& merging = map.merging;
  readParam(reader, "merge_landmarks", merging.enabled, log);
  readParam(reader, "merge_gate_probability", merging.gate_probability, log);
  readParam(reader, "merge_floor_translation_sigma", merging.floor_translation_sigma, log);
  readParam(reader, "merge_floor_rotation_sigma", merging.floor_rotation_sigma, log);
  readParam(reader, "merge_floor_scale_fraction", merging.floor_scale_fraction, log);
  readParam(reader, "merge_missing_translation_sigma", merging.missing_translation_sigma, log);
  readParam(reader, "merge_missing_rotation_sigma", merging.missing_rotation_sigma, log);
  readParam(reader, "merge_missing_scale_fraction", merging.missing_scale_fraction, log);
  readParam(reader, "merge_extent_margin", merging.extent_margin, log);
  SlidingWindow::Params& window = mapper.window;
  readParam(reader, "window_size", window.size, log);
  readParam(reader, "max_iterations", window.max_iterations, log);
  readParam(reader, "observation_huber", window.observation_huber, log);
  readParam(reader, "schur_marginalization", window.schur_marginalization, log);
  readParam(reader, "oldest_pose_translation_sigma", window.oldest_pose_translation_sigma, log);
  readParam(reader, "oldest_pose_rotation_sigma", window.oldest_pose_rotation_sigma, log);
  readParam(reader, "landmark_prior_inflation", window.landmark_prior_inflation, log);
  readParam(reader, "compute_covariance", window.compute_covariance, log);
  readParam(reader, "keyframe_translation", mapper.keyframe_translation, log);
  readParam(reader, "keyframe_rotation", mapper.keyframe_rotation, log);
  readParam(reader, "keyframe_min_new_landmarks", mapper.keyframe_min_new_landmarks, log);
  readParam(reader, "keyframe_min_overlap", mapper.keyframe_min_overlap, log);
  readParam(reader, "odometry_translation_sigma", mapper.odometry_translation_sigma, log);
  readParam(reader, "odometry_translation_fraction", mapper.odometry_translation_fraction, log);
  readParam(reader, "odometry_rotation_sigma", mapper.odometry_rotation_sigma, log);
  readParam(reader, "odometry_rotation_fraction", mapper.odometry_rotation_fraction, log);
  readParam(reader, "odometry_rotation_per_metre", mapper.odometry_rotation_per_metre, log);
  readParam(reader, "max_camera_speed", mapper.max_camera_speed, log);
  readParam(reader, "max_camera_angular_speed", mapper.max_camera_angular_speed, log);
  readParam(reader, "model_error_sigma", mapper.model_error.sigma, log);
  readParam(reader, "model_error_correlation_angle", mapper.model_error.correlation_angle, log);
  readParam(reader, "reconstruction_voxel_size", reconstruction.voxel_size, log);
  readParam(reader, "reconstruction_max_points_per_landmark",
            reconstruction.max_points_per_landmark, log);
  readParam(reader, "reconstruction_max_points", reconstruction.max_points, log);
  readParam(reader, "reconstruction_max_surface_distance", reconstruction.max_surface_distance,
            log);
  mapper.validate();
  reconstruction.validate();
}

void readTrackingRecoveryParams(const ParamReader& reader, TrackingRecovery::Params& params,
                                ParamLog& log) {
  readParam(reader, "recovery_min_landmark_associations", params.min_landmark_associations, log);
  readParam(reader, "recovery_confirm_frames", params.confirm_frames, log);
  readParam(reader, "recovery_min_map_landmarks", params.min_map_landmarks, log);
  readParam(reader, "recovery_max_frames", params.max_frames, log);
  readParam(reader, "recovery_promote_on_loss_min_observations",
            params.promote_on_loss_min_observations, log);
  readParam(reader, "recovery_promoted_max_frames", params.promoted_max_frames, log);
  Relocaliser::Params& relocaliser = params.relocaliser;
  readParam(reader, "relocalisation_enabled", relocaliser.enabled, log);
  readParam(reader, "relocalisation_min_supporting_surfaces", relocaliser.min_supporting_surfaces,
            log);
  readParam(reader, "relocalisation_max_ambiguity", relocaliser.max_ambiguity, log);
  readParam(reader, "relocalisation_extent_margin", relocaliser.extent_margin, log);
  readParam(reader, "relocalisation_min_plane_points", relocaliser.min_plane_points, log);
  readParam(reader, "relocalisation_max_angle_difference", relocaliser.matcher.max_angle_difference,
            log);
  readParam(reader, "relocalisation_max_offset_difference",
            relocaliser.matcher.max_offset_difference, log);
  params.validate();
}

void readBatchRefinementParams(const ParamReader& reader, bool& enabled,
                               BatchRefiner::Params& params, ParamLog& log) {
  readParam(reader, "batch_refinement", enabled, log);
  readParam(reader, "batch_max_iterations", params.max_iterations, log);
  readParam(reader, "batch_max_keyframes", params.max_keyframes, log);
  readParam(reader, "batch_compute_covariance", params.compute_covariance, log);
  readParam(reader, "batch_noise_rounds", params.noise_rounds, log);
  readParam(reader, "batch_noise_tolerance", params.noise_tolerance, log);
  readParam(reader, "batch_merge_rounds", params.merge_rounds, log);
  params.validate();
}

void readOdometryIncrementParams(const ParamReader& reader, bool& use_increment_covariance,
                                 ParamLog& log) {
  readParam(reader, "odometry_increment_covariance", use_increment_covariance, log);
}

}  // namespace quadric_slam
