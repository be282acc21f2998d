#include "quadric_slam/ros/conversions.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/ros/frame_ids.h"

namespace quadric_slam {
namespace {

Eigen::Vector3d fromPointMsg(const geometry_msgs::Point& msg) {
  return {msg.x, msg.y, msg.z};
}

}  // namespace

geometry_msgs::Point toPointMsg(const Eigen::Vector3d& p) {
  geometry_msgs::Point msg;
  msg.x = p.x();
  msg.y = p.y();
  msg.z = p.z();
  return msg;
}

geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose) {
  geometry_msgs::Pose msg;
  msg.position = toPointMsg(pose.translation());
  const Eigen::Quaterniond q(pose.rotation());
  msg.orientation.x = q.x();
  msg.orientation.y = q.y();
  msg.orientation.z = q.z();
  msg.orientation.w = q.w();
  return msg;
}

Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& msg) {
  const Eigen::Vector3d t = fromPointMsg(msg.position);
  const Eigen::Quaterniond q(msg.orientation.w, msg.orientation.x, msg.orientation.y,
                             msg.orientation.z);
  if (!t.allFinite() || !q.coeffs().allFinite()) {
    throw std::invalid_argument("pose is not finite");
  }
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    throw std::invalid_argument("pose orientation is not a unit quaternion (norm " +
                                std::to_string(q.norm()) + ")");
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = t;
  return pose;
}

QuadricSurface toSurfaceMsg(const QuadricModel& quadric, const Eigen::Vector3d& extent_min,
                            const Eigen::Vector3d& extent_max) {
  QuadricSurface msg;
  msg.quadric_class = static_cast<std::uint8_t>(quadric.quadricClass());
  for (int i = 0; i < 4; ++i) {
    msg.signature[i] = static_cast<std::int8_t>(std::lround(quadric.signature()[i]));
  }
  msg.pose = toPoseMsg(quadric.pose());
  for (int i = 0; i < 3; ++i)
    msg.scale[i] = quadric.scale()[i];
  msg.shape = shapeVector(quadric);
  msg.extent_min = toPointMsg(extent_min);
  msg.extent_max = toPointMsg(extent_max);
  return msg;
}

QuadricModel fromSurfaceMsg(const QuadricSurface& msg) {
  const QuadricClass quadric_class = quadricClassFromInt(msg.quadric_class);
  const Eigen::Vector4d signature(msg.signature[0], msg.signature[1], msg.signature[2],
                                  msg.signature[3]);
  const Eigen::Vector3d scale(msg.scale[0], msg.scale[1], msg.scale[2]);
  return QuadricModel(quadric_class, fromPoseMsg(msg.pose), scale, signature);
}

std::vector<double> toCovarianceMsg(const Eigen::MatrixXd& covariance) {
  std::vector<double> values;
  values.reserve(covariance.size());
  for (int r = 0; r < covariance.rows(); ++r) {
    for (int c = 0; c < covariance.cols(); ++c)
      values.push_back(covariance(r, c));
  }
  return values;
}

Eigen::MatrixXd fromCovarianceMsg(const std::vector<double>& values, int dimension) {
  if (values.empty())
    return Eigen::MatrixXd();
  if (static_cast<int>(values.size()) != dimension * dimension) {
    throw std::invalid_argument("covariance has " + std::to_string(values.size()) +
                                " entries, expected " + std::to_string(dimension) + " x " +
                                std::to_string(dimension));
  }
  Eigen::MatrixXd covariance(dimension, dimension);
  for (int r = 0; r < dimension; ++r) {
    for (int c = 0; c < dimension; ++c)
      covariance(r, c) = values[r * dimension + c];
  }
  return covariance;
}

QuadricObservation toObservationMsg(const QuadricMeasurement& measurement) {
  QuadricObservation msg;
  msg.surface =
      toSurfaceMsg(measurement.quadric_camera, measurement.extent_min, measurement.extent_max);
  msg.minimal_dimension =
      static_cast<std::uint8_t>(minimalDimension(measurement.quadric_camera.quadricClass()));
  msg.covariance = toCovarianceMsg(measurement.covariance);
  msg.num_points = static_cast<std::uint32_t>(measurement.num_points);
  msg.label = static_cast<std::uint16_t>(measurement.label);
  msg.image_roi.x_offset = measurement.image_roi.x_offset;
  msg.image_roi.y_offset = measurement.image_roi.y_offset;
  msg.image_roi.width = measurement.image_roi.width;
  msg.image_roi.height = measurement.image_roi.height;
  msg.fit_rms = static_cast<float>(measurement.fit_rms);
  msg.support_points.resize(measurement.support_points.size());
  for (std::size_t i = 0; i < measurement.support_points.size(); ++i) {
    msg.support_points[i].x = measurement.support_points[i].x();
    msg.support_points[i].y = measurement.support_points[i].y();
    msg.support_points[i].z = measurement.support_points[i].z();
  }
  return msg;
}

QuadricMeasurement fromObservationMsg(const QuadricObservation& msg) {
  QuadricMeasurement measurement;
  measurement.quadric_camera = fromSurfaceMsg(msg.surface);
  const int dimension = minimalDimension(measurement.quadric_camera.quadricClass());
  if (msg.minimal_dimension != dimension) {
    throw std::invalid_argument("minimal_dimension " + std::to_string(msg.minimal_dimension) +
                                " does not match the class (" + std::to_string(dimension) + ")");
  }
  measurement.covariance = fromCovarianceMsg(msg.covariance, dimension);
  measurement.num_points = static_cast<int>(msg.num_points);
  measurement.label = msg.label;
  measurement.image_roi = {
      static_cast<int>(msg.image_roi.x_offset), static_cast<int>(msg.image_roi.y_offset),
      static_cast<int>(msg.image_roi.width), static_cast<int>(msg.image_roi.height)};
  measurement.fit_rms = msg.fit_rms;
  measurement.extent_min = fromPointMsg(msg.surface.extent_min);
  measurement.extent_max = fromPointMsg(msg.surface.extent_max);
  // Non-finite points are left out (the reconstruction would skip them anyway).
  measurement.support_points.reserve(msg.support_points.size());
  for (const geometry_msgs::Point32& p : msg.support_points) {
    const Eigen::Vector3f point(p.x, p.y, p.z);
    if (point.allFinite())
      measurement.support_points.push_back(point);
  }
  return measurement;
}

QuadricObservationArray toObservationArrayMsg(const FrameMeasurements& frame) {
  QuadricObservationArray msg;
  msg.header.stamp = ros::Time(frame.stamp);
  msg.header.frame_id = withoutLeadingSlash(frame.frame_id);
  msg.observations.reserve(frame.observations.size());
  for (const QuadricMeasurement& m : frame.observations) {
    msg.observations.push_back(toObservationMsg(m));
  }
  return msg;
}

FrameMeasurements fromObservationArrayMsg(const QuadricObservationArray& msg, int* rejected) {
  FrameMeasurements frame;
  frame.stamp = msg.header.stamp.toSec();
  frame.frame_id = withoutLeadingSlash(msg.header.frame_id);
  int bad = 0;
  for (const QuadricObservation& observation : msg.observations) {
    try {
      frame.observations.push_back(fromObservationMsg(observation));
    } catch (const std::invalid_argument&) {
      ++bad;
    }
  }
  if (rejected != nullptr)
    *rejected = bad;
  return frame;
}

Quadric toLandmarkMsg(const QuadricLandmark& landmark) {
  Quadric msg;
  msg.id = static_cast<std::uint32_t>(landmark.id);
  msg.surface = toSurfaceMsg(landmark.quadric_map, landmark.extent_min, landmark.extent_max);
  msg.observations = static_cast<std::uint32_t>(landmark.observations);
  msg.minimal_dimension =
      static_cast<std::uint8_t>(minimalDimension(landmark.quadric_map.quadricClass()));
  msg.covariance = toCovarianceMsg(landmark.covariance);
  msg.last_observed = ros::Time(landmark.last_observed);
  return msg;
}

QuadricLandmark fromLandmarkMsg(const Quadric& msg) {
  QuadricLandmark landmark;
  landmark.id = static_cast<int>(msg.id);
  landmark.quadric_map = fromSurfaceMsg(msg.surface);
  landmark.observations = static_cast<int>(msg.observations);
  landmark.covariance =
      fromCovarianceMsg(msg.covariance, minimalDimension(landmark.quadric_map.quadricClass()));
  landmark.last_observed = msg.last_observed.toSec();
  landmark.extent_min = fromPointMsg(msg.surface.extent_min);
  landmark.extent_max = fromPointMsg(msg.surface.extent_max);
  return landmark;
}

}  // namespace quadric_slam
