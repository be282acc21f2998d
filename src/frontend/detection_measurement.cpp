#include "quadric_slam/frontend/detection_measurement.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

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

void attachSupportPoints(FrameMeasurements& frame, const Segmentation& segmentation,
                         const pcl::PointCloud<pcl::PointNormal>& cloud, int max_points) {
  const cv::Mat& labels = segmentation.labels;
  if (max_points <= 0 || frame.observations.empty() || labels.empty() ||
      labels.cols != static_cast<int>(cloud.width) || labels.rows != static_cast<int>(cloud.height))
    return;
  // label -> observation + 1 (0: none), a table over the 16-bit labels (a lookup per labelled
  // pixel, twice per frame); counts per label decide the stride.
  std::vector<std::size_t> observation_of_label(std::numeric_limits<std::uint16_t>::max() + 1, 0);
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    const int label = frame.observations[i].label;
    if (label > 0 && label <= std::numeric_limits<std::uint16_t>::max())
      observation_of_label[label] = i + 1;
  }
  std::vector<int> count(frame.observations.size(), 0);
  for (int v = 0; v < labels.rows; ++v) {
    const std::uint16_t* row = labels.ptr<std::uint16_t>(v);
    for (int u = 0; u < labels.cols; ++u)
      if (const std::size_t o = observation_of_label[row[u]]; o != 0)
        ++count[o - 1];
  }
  std::vector<int> stride(frame.observations.size(), 1);
  std::vector<int> until_next(frame.observations.size(), 1);  // the first pixel is taken
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    stride[i] = std::max(1, (count[i] + max_points - 1) / max_points);
    frame.observations[i].support_points.clear();
    frame.observations[i].support_points.reserve(std::min(count[i], max_points));
  }
  for (int v = 0; v < labels.rows; ++v) {
    const std::uint16_t* row = labels.ptr<std::uint16_t>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const std::size_t o = observation_of_label[row[u]];
      if (o == 0)
        continue;
      const std::size_t i = o - 1;
      QuadricMeasurement& m = frame.observations[i];
      // Every stride-th pixel of the observation (a countdown: no division per pixel).
      if (--until_next[i] > 0)
        continue;
      until_next[i] = stride[i];
      const Eigen::Vector3f p = cloud(u, v).getVector3fMap();
      if (p.allFinite() && static_cast<int>(m.support_points.size()) < max_points)
        m.support_points.push_back(p);
    }
  }
}

}  // namespace quadric_slam
