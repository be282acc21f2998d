// One quadric surface seen in one depth frame, in the camera frame: what the front-end hands the
// back-end (the core twin of msg/QuadricObservation.msg; core types avoid the message names, which
// live in the same C++ namespace).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

// Pixel bounding box in the depth image (as sensor_msgs/RegionOfInterest).
struct ImageRoi {
  int x_offset = 0, y_offset = 0, width = 0, height = 0;
};

struct QuadricMeasurement {
  // The paper's measurement _C pi = (T_camera_quadric, S, sigma) with its class.
  QuadricModel quadric_camera;
  // Measurement covariance in the class's minimal space (Table II), k x k; see
  // msg/QuadricObservation.msg for the convention.
  Eigen::MatrixXd covariance;
  int num_points = 0;    // supporting depth points
  int label = 0;         // segment label in the label image (0 = none)
  ImageRoi image_roi;    // bounding box of the supporting pixels
  double fit_rms = 0.0;  // RMS distance of the supporting points to the surface (m)
  // Axis-aligned box of the supporting points in the quadric frame (m).
  Eigen::Vector3d extent_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d extent_max = Eigen::Vector3d::Zero();
  // A bounded subset of the supporting points (camera frame, m) for the reconstruction; may be
  // empty (frontend/detection_measurement.h: attachSupportPoints).
  std::vector<Eigen::Vector3f> support_points;
  // The RGB colour of each support point (frontend/support_colours.h), packed 0xAARRGGBB with
  // alpha 255 = sampled from the RGB image, 0 = no colour (outside the image); either empty (no RGB
  // image) or one per support point.
  std::vector<std::uint32_t> support_colours;
};

// All observations of one frame.
struct FrameMeasurements {
  double stamp = 0.0;    // s
  std::string frame_id;  // camera optical frame
  std::vector<QuadricMeasurement> observations;
};

}  // namespace quadric_slam
