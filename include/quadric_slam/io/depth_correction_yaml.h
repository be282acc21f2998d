// The depth correction file (frontend/depth_correction.h), written by the calibrate_depth tool:
//   image_width, image_height: the image the grid spans (px)
//   focal_baseline: the sensor's focal length times its baseline (px m)
//   grid_cols, grid_rows: nodes of the grid
//   offsets: grid_cols x grid_rows disparity offsets (px), row-major
#pragma once

#include <string>

#include "quadric_slam/frontend/depth_correction.h"

namespace quadric_slam {

// Throws std::runtime_error naming the file when it cannot be written.
void writeDepthCorrectionYaml(const std::string& path, const DepthCorrection& correction,
                              const std::string& comment = "");

// Throws std::runtime_error naming the file and the problem (unreadable, a missing or malformed
// key, a grid that does not fit its offsets).
DepthCorrection readDepthCorrectionYaml(const std::string& path);

}  // namespace quadric_slam
