// A segmenter detection as the front-end's measurement for the back-end (types/observation.h),
// through the geometry core: quadric_camera = detection.shape.quadric() (geometry/shapes.h), whose
// frame the detection's covariance (Table II minimal space, body-frame perturbation) and extent box
// already refer to.
#pragma once

#include <string>

#include "quadric_slam/types/observation.h"
#include "quadric_slam/frontend/quadric_segmenter.h"

namespace quadric_slam {

// Throws std::invalid_argument when the covariance is not k x k for the class's minimal dimension
// k (or empty, which is passed on as empty), or the shape is invalid (see PrimitiveShape::quadric).
QuadricMeasurement toMeasurement(const QuadricDetection& detection);

// All detections of one frame, in detection order.
FrameMeasurements toFrameMeasurements(const Segmentation& segmentation, double stamp,
                                      const std::string& frame_id);

// Fills each measurement's support_points with at most max_points of its labelled points (label
// image of `segmentation`, points of `cloud`, camera frame): every k-th point of the label in row
// order, k = ceil(count / max_points), so the subset covers the whole segment. This bounds what an
// observation carries to the mapper (12 bytes a point in the message) while the reconstruction's
// voxel grid fills in over frames. max_points 0 leaves them empty.
void attachSupportPoints(FrameMeasurements& frame, const Segmentation& segmentation,
                         const pcl::PointCloud<pcl::PointNormal>& cloud, int max_points);

}  // namespace quadric_slam
