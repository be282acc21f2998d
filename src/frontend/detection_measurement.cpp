#include "quadric_slam/frontend/detection_measurement.h"

#include <stdexcept>

namespace quadric_slam {

QuadricMeasurement toMeasurement(const QuadricDetection& detection) {
  QuadricMeasurement m;
  m.quadric_camera = detection.shape.quadric();
  const int k = minimalDimension(detection.shape.quadric_class);
  if (detection.covariance.size() != 0 &&
      (detection.covariance.rows() != k || detection.covariance.cols() != k))
    throw std::invalid_argument("toMeasurement: covariance must be " + std::to_string(k) + " x " +
                                std::to_string(k) + " for a " +
                                toString(detection.shape.quadric_class) + ", got " +
                                std::to_string(detection.covariance.rows()) + " x " +
                                std::to_string(detection.covariance.cols()));
  m.covariance = detection.covariance;
  m.num_points = detection.num_points;
  m.label = detection.label;
  m.image_roi = detection.roi;
  m.fit_rms = detection.fit_rms;
  m.extent_min = detection.extent_min;
  m.extent_max = detection.extent_max;
  return m;
}

FrameMeasurements toFrameMeasurements(const Segmentation& segmentation, double stamp,
                                      const std::string& frame_id) {
  FrameMeasurements frame;
  frame.stamp = stamp;
  frame.frame_id = frame_id;
  frame.observations.reserve(segmentation.detections.size());
  for (const QuadricDetection& d : segmentation.detections)
    frame.observations.push_back(toMeasurement(d));
  return frame;
}

}  // namespace quadric_slam
