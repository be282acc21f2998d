// The parameter key tables of the pipeline's core classes: the same keys are read by the nodelets
// (private ROS parameters) and by the offline tools (config/*.yaml). Each function reads the keys
// present, keeps defaults for the rest, logs the effective values and validates (throwing
// std::invalid_argument naming the bad field).
#pragma once

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/io/param_reader.h"

namespace quadric_slam {

// config/normal_estimation.yaml: decimation, min_range, max_range (back-projection) and
// normal_method, max_depth_change_factor, normal_smoothing_size, depth_dependent_smoothing,
// threads.
void readNormalEstimationParams(const ParamReader& reader, BackProjectionParams& back_projection,
                                NormalEstimator::Params& normals, ParamLog& log);

}  // namespace quadric_slam
