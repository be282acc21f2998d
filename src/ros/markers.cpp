#include "quadric_slam/ros/markers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/ros/conversions.h"

namespace quadric_slam {
namespace {

// The landmark's extent box in its quadric frame, or a cube of `size` around the origin when it has
// none (an empty or inverted box).
void extentOrDefault(const QuadricLandmark& landmark, double size, Eigen::Vector3d& lower,
                     Eigen::Vector3d& upper) {
  lower = landmark.extent_min;
  upper = landmark.extent_max;
  const bool valid = lower.allFinite() && upper.allFinite() && (upper - lower).minCoeff() >= 0.0 &&
                     (upper - lower).maxCoeff() > 0.0;
  if (!valid) {
    lower = Eigen::Vector3d::Constant(-size / 2);
    upper = Eigen::Vector3d::Constant(size / 2);
  }
}

visualization_msgs::Marker baseMarker(const QuadricLandmark& landmark,
                                      const std_msgs::Header& header, const MarkerStyle& style) {
  visualization_msgs::Marker marker;
  marker.header = header;
  marker.ns = toString(landmark.quadric_map.quadricClass());
  marker.id = landmark.id;
  marker.action = visualization_msgs::Marker::ADD;
  marker.color = landmarkColour(landmark.id, style.alpha);
  marker.pose = toPoseMsg(landmark.quadric_map.pose());
  marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
  return marker;
}

// Ring of the cone surface at height z of the quadric frame.
Eigen::Vector3d conePoint(double z, double tan_half_angle, double angle) {
  const double radius = std::abs(z) * tan_half_angle;
  return Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), z);
}

void addConeMesh(double z0, double z1, double tan_half_angle, int segments,
                 visualization_msgs::Marker& marker) {
  for (int i = 0; i < segments; ++i) {
    const double a0 = 2.0 * M_PI * i / segments, a1 = 2.0 * M_PI * (i + 1) / segments;
    const Eigen::Vector3d p00 = conePoint(z0, tan_half_angle, a0),
                          p01 = conePoint(z0, tan_half_angle, a1),
                          p10 = conePoint(z1, tan_half_angle, a0),
                          p11 = conePoint(z1, tan_half_angle, a1);
    for (const Eigen::Vector3d& p : {p00, p10, p11, p00, p11, p01})
      marker.points.push_back(toPointMsg(p));
  }
}

// The shape marker of a landmark, and the centre of what it draws (map frame); false when the class
// has no closed marker shape.
bool shapeMarker(const QuadricLandmark& landmark, const std_msgs::Header& header,
                 const MarkerStyle& style, visualization_msgs::Marker& marker,
                 Eigen::Vector3d& centre_map) {
  const QuadricModel& quadric = landmark.quadric_map;
  const Eigen::Isometry3d& T_map_quadric = quadric.pose();
  Eigen::Vector3d lower, upper;
  extentOrDefault(landmark, style.default_extent, lower, upper);
  const Eigen::Vector3d size = (upper - lower).cwiseMax(1e-3);
  marker = baseMarker(landmark, header, style);
  Eigen::Vector3d centre_quadric = Eigen::Vector3d::Zero();
  switch (quadric.quadricClass()) {
    case QuadricClass::kPlane:
      // The plane is x = 0 of its quadric frame.
      marker.type = visualization_msgs::Marker::CUBE;
      centre_quadric =
          Eigen::Vector3d(0.0, (lower.y() + upper.y()) / 2, (lower.z() + upper.z()) / 2);
      marker.scale.x = style.plane_thickness;
      marker.scale.y = size.y();
      marker.scale.z = size.z();
      break;
    case QuadricClass::kSphere:
      marker.type = visualization_msgs::Marker::SPHERE;
      marker.scale.x = marker.scale.y = marker.scale.z = 2.0 * sphereShape(quadric).radius;
      break;
    case QuadricClass::kCylinder:
      // A CYLINDER marker's axis is its z, as the quadric's.
      marker.type = visualization_msgs::Marker::CYLINDER;
      centre_quadric = Eigen::Vector3d(0.0, 0.0, (lower.z() + upper.z()) / 2);
      marker.scale.x = marker.scale.y = 2.0 * cylinderShape(quadric).radius;
      marker.scale.z = size.z();
      break;
    case QuadricClass::kCone: {
      marker.type = visualization_msgs::Marker::TRIANGLE_LIST;
      const double tan_half_angle = std::tan(coneShape(quadric).half_angle);
      const double z0 = lower.z(), z1 = std::max(upper.z(), lower.z() + 1e-3);
      // Across the apex the double cone is two surfaces meeting in a point.
      if (z0 < 0.0 && z1 > 0.0) {
        addConeMesh(z0, 0.0, tan_half_angle, style.cone_segments, marker);
        addConeMesh(0.0, z1, tan_half_angle, style.cone_segments, marker);
      } else {
        addConeMesh(z0, z1, tan_half_angle, style.cone_segments, marker);
      }
      centre_quadric = Eigen::Vector3d(0.0, 0.0, (z0 + z1) / 2);
      centre_map = T_map_quadric * centre_quadric;
      return true;  // the mesh is in the quadric frame: the pose stays T_map_quadric
    }
    case QuadricClass::kGeneral:
      if (quadric.signature() != Eigen::Vector4d(1, 1, 1, -1)) {
        centre_map = T_map_quadric.translation();
        return false;
      }
      marker.type = visualization_msgs::Marker::SPHERE;  // an ellipsoid: semi-axes 1 / scale
      marker.scale.x = 2.0 / quadric.scale().x();
      marker.scale.y = 2.0 / quadric.scale().y();
      marker.scale.z = 2.0 / quadric.scale().z();
      break;
  }
  centre_map = T_map_quadric * centre_quadric;
  Eigen::Isometry3d T_map_marker = T_map_quadric;
  T_map_marker.translation() = centre_map;
  marker.pose = toPoseMsg(T_map_marker);
  return true;
}

}  // namespace

void MarkerStyle::validate() const {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("MarkerStyle::" + what);
  };
  if (!(alpha >= 0.0 && alpha <= 1.0))
    fail("alpha must be in [0, 1], got " + std::to_string(alpha));
  if (!(plane_thickness > 0.0))
    fail("plane_thickness must be > 0 (m), got " + std::to_string(plane_thickness));
  if (!(default_extent > 0.0))
    fail("default_extent must be > 0 (m), got " + std::to_string(default_extent));
  if (cone_segments < 3)
    fail("cone_segments must be >= 3, got " + std::to_string(cone_segments));
  if (!(label_height > 0.0))
    fail("label_height must be > 0 (m), got " + std::to_string(label_height));
}

std_msgs::ColorRGBA landmarkColour(int id, double alpha) {
  // HSV with s = v = 1; hue stepped by the golden ratio conjugate.
  const double hue = std::fmod(0.13 + 0.618033988749895 * std::abs(id), 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(hue)) {
    case 0:
      r = 1, g = x;
      break;
    case 1:
      r = x, g = 1;
      break;
    case 2:
      g = 1, b = x;
      break;
    case 3:
      g = x, b = 1;
      break;
    case 4:
      r = x, b = 1;
      break;
    default:
      r = 1, b = x;
      break;
  }
  std_msgs::ColorRGBA colour;
  colour.r = static_cast<float>(r);
  colour.g = static_cast<float>(g);
  colour.b = static_cast<float>(b);
  colour.a = static_cast<float>(std::clamp(alpha, 0.0, 1.0));
  return colour;
}

visualization_msgs::MarkerArray quadricMarkers(const std::vector<QuadricLandmark>& landmarks,
                                               const std_msgs::Header& header,
                                               const MarkerStyle& style) {
  style.validate();
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker clear;
  clear.header = header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(clear);
  for (const QuadricLandmark& landmark : landmarks) {
    visualization_msgs::Marker shape;
    Eigen::Vector3d centre_map;
    if (shapeMarker(landmark, header, style, shape, centre_map))
      array.markers.push_back(shape);
    if (!style.labels)
      continue;
    visualization_msgs::Marker label;
    label.header = header;
    label.ns = "labels";
    label.id = landmark.id;
    label.action = visualization_msgs::Marker::ADD;
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.text = toString(landmark.quadric_map.quadricClass()) + " " + std::to_string(landmark.id);
    label.pose.position = toPointMsg(centre_map);
    label.pose.orientation.w = 1.0;
    label.scale.z = style.label_height;
    label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
    array.markers.push_back(label);
  }
  return array;
}

}  // namespace quadric_slam
