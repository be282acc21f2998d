// RViz markers of the quadric map (visualization_msgs/MarkerArray): one shape marker per landmark
// in a namespace per class, with the landmark id as marker id, a colour per landmark (as the
// paper's figures: a distinct colour per quadric), and an optional text label. The array starts
// with a DELETEALL marker, so landmarks that left the map disappear from rviz.
//
// Shapes, drawn over the landmark's observed extent (the box of its supporting points in the
// quadric frame; `default_extent` around the quadric origin when the box is empty):
//   plane    CUBE, thin along the normal (quadric x), spanning the extent in quadric y and z;
//   sphere   SPHERE of the radius;
//   cylinder CYLINDER of the radius, spanning the extent along the axis (quadric z);
//   cone     TRIANGLE_LIST mesh of the surface between the extent's z limits (the apex side
//            included when the extent reaches it);
//   general  SPHERE scaled to the semi-axes for an ellipsoid; other general quadrics
//            (hyperboloids, ...) have no closed marker shape and get only their label.
#pragma once

#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include <vector>

#include "quadric_slam/mapping/landmark.h"

namespace quadric_slam {

struct MarkerStyle {
  double alpha = 0.6;             // opacity of the shapes, [0, 1]
  double plane_thickness = 0.01;  // m
  double default_extent = 0.5;    // m: size drawn when a landmark has no extent yet
  int cone_segments = 24;         // facets around a cone, >= 3
  bool labels = true;             // a text marker "<class> <id>" above each landmark
  double label_height = 0.06;     // m, text size
  void validate() const;          // throws std::invalid_argument naming the field and its range
};

// Throws std::invalid_argument when the style is invalid. Namespaces: the class names of
// geometry/quadric_class.h ("plane", "sphere", ...) and "labels".
visualization_msgs::MarkerArray quadricMarkers(const std::vector<QuadricLandmark>& landmarks,
                                               const std_msgs::Header& header,
                                               const MarkerStyle& style = MarkerStyle());

// The colour of a landmark: fully saturated hues spread by the golden ratio over the ids, so
// neighbouring ids differ clearly and a landmark keeps its colour from one publication to the next.
std_msgs::ColorRGBA landmarkColour(int id, double alpha);

}  // namespace quadric_slam
