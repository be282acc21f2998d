// Depth images of scenes made of bounded primitives (planes, spheres, finite cylinders, truncated
// cones) seen by a pinhole camera at the origin, with Kinect-like depth noise: ground truth for the
// segmenter's tests and benchmark. Ray casting, nearest hit per pixel, per-pixel primitive index.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/primitive_shape.h"

namespace quadric_slam {

// A primitive with bounds along its axis (camera frame): cylinders and cones keep the points
// whose coordinate along the axis (from shape.point) lies in [axis_min, axis_max]; planes keep
// points within `plane_half_size` of shape.point in every coordinate (infinite when <= 0);
// spheres are whole.
struct ScenePrimitive {
  PrimitiveShape shape;
  double axis_min = 0.0, axis_max = 1.0;
  double plane_half_size = 0.0;
};

struct PrimitiveRendering {
  cv::Mat depth;  // CV_32FC1 metres, NaN = no surface
  cv::Mat truth;  // CV_16UC1 primitive index + 1 per pixel, 0 = none
};

struct RenderParams {
  // Depth noise standard deviation sigma = noise_factor * z^2 (m), Khoshelham & Elberink's Kinect
  // model has about 1.4e-3 1/m; 0 = noise-free.
  double noise_factor = 1.5e-3;
  // Depth quantization step q = quantization_factor * z^2 (m), as Kinect disparity quantization
  // (0 = none).
  double quantization_factor = 0.0;
  double max_range = 8.0;  // beyond this: no data (m)
  unsigned int seed = 7;
};

PrimitiveRendering renderPrimitives(const std::vector<ScenePrimitive>& scene,
                               const CameraIntrinsics& intrinsics, const RenderParams& params);

}  // namespace quadric_slam
