// Core types <-> quadric_slam messages. Pure functions, no master needed. (Core types are named
// apart from the messages, which share the quadric_slam C++ namespace: QuadricModel vs Quadric,
// QuadricMeasurement vs QuadricObservation, QuadricLandmark vs Quadric.)
#pragma once

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <quadric_slam/Quadric.h>
#include <quadric_slam/QuadricObservation.h>
#include <quadric_slam/QuadricObservationArray.h>
#include <quadric_slam/QuadricSurface.h>

#include <Eigen/Geometry>
#include <vector>

#include "quadric_slam/types/observation.h"
#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/mapping/landmark.h"

namespace quadric_slam {

geometry_msgs::Point toPointMsg(const Eigen::Vector3d& p);
geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose);
// Throws std::invalid_argument for a non-finite pose or a quaternion far from unit length.
Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& msg);

// The surface with the extent box in the quadric frame (m); shape filled per class.
QuadricSurface toSurfaceMsg(const QuadricModel& quadric, const Eigen::Vector3d& extent_min,
                            const Eigen::Vector3d& extent_max);
// Throws std::invalid_argument (naming the problem) for an unknown class, a bad pose or scale,
// or a signature that does not fit the class.
QuadricModel fromSurfaceMsg(const QuadricSurface& msg);

// Row-major k x k <-> Eigen; fromCovarianceMsg throws std::invalid_argument when the size is not
// dimension^2 (an empty vector gives an empty matrix).
std::vector<double> toCovarianceMsg(const Eigen::MatrixXd& covariance);
Eigen::MatrixXd fromCovarianceMsg(const std::vector<double>& values, int dimension);

QuadricObservation toObservationMsg(const QuadricMeasurement& measurement);
// Throws std::invalid_argument naming the problem (bad surface, covariance of the wrong size).
QuadricMeasurement fromObservationMsg(const QuadricObservation& msg);

// Both ways the frame id loses a leading '/' (ros/frame_ids.h).
QuadricObservationArray toObservationArrayMsg(const FrameMeasurements& frame);
// Observations that fail to convert are skipped and counted in *rejected (when given).
FrameMeasurements fromObservationArrayMsg(const QuadricObservationArray& msg,
                                          int* rejected = nullptr);

Quadric toLandmarkMsg(const QuadricLandmark& landmark);
QuadricLandmark fromLandmarkMsg(const Quadric& msg);

}  // namespace quadric_slam
