#include "quadric_slam/io/pipeline_params.h"

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
  readParam(reader, "degenerate_variance", icp.degenerate_variance, log);
  readParam(reader, "max_translation_from_guess", icp.max_translation_from_guess, log);
  readParam(reader, "max_rotation_from_guess", icp.max_rotation_from_guess, log);
  readParam(reader, "keyframe_translation", params.keyframe_translation, log);
  readParam(reader, "keyframe_rotation", params.keyframe_rotation, log);
  readParam(reader, "keyframe_min_overlap", params.keyframe_min_overlap, log);
  readParam(reader, "constant_velocity", params.constant_velocity, log);
  readParam(reader, "lost_frames_before_new_keyframe", params.lost_frames_before_new_keyframe, log);
  params.validate();
}

}  // namespace quadric_slam
