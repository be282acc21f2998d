// How a curved segment's visible width changes along an axis: the one cue that tells a cone from a
// cylinder far from a depth camera. At 2-3 m a Kinect's depth noise (and its correlated part, which
// more pixels do not average away) lets a cylinder fit the visible side of a cone as closely as the
// cone does, but the segment's outline is measured across the image, where a pixel is a few
// millimetres: a cylinder's visible width is the same all along its axis, a cone's grows linearly
// towards its opening (its silhouette edges are the two generators at the half angle from the
// axis).
//
// The measurement: the points (camera frame, camera at the origin) are given axial coordinates s
// along a candidate axis and lateral coordinates u across it, perpendicular to the line of sight;
// in bins of s the half width is half the spread of u (trimmed of the extreme points), and a
// straight line h(s) = h0 + k s is fitted to the bins. A cone of half angle alpha whose axis makes
// the angle beta with the candidate axis predicts k = tan(alpha) cos(beta); a cylinder k = 0.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "quadric_slam/frontend/primitive_shape.h"

namespace quadric_slam {

struct SilhouetteTaper {
  double slope = 0.0;  // k: change of the visible half width per metre along the axis
  double slope_sigma = std::numeric_limits<double>::infinity();  // its standard error
  int bins = 0;         // bins with enough points that entered the fit
  double length = 0.0;  // extent of the support along the axis (m)

  // True when the width changes along the axis beyond the measurement's noise: at least
  // kMinTaperBins bins, |k| above 3 sigma and above min_slope.
  bool significant(double min_slope) const;
};

// Bins with enough points a taper needs.
constexpr int kMinTaperBins = 4;

// The taper of `points` along the axis through axis_point with direction axis (unit or not). No
// taper (bins 0) when there are too few points, the support is shorter than 10 cm along the axis
// (over less, a segment's ragged ends and border pixels make the width), or the line of sight runs
// within 12 degrees of the axis (the width across it is then not the silhouette).
SilhouetteTaper measureSilhouetteTaper(const Eigen::Vector3d& axis_point,
                                       const Eigen::Vector3d& axis,
                                       const std::vector<Eigen::Vector3d>& points);

// The taper `shape` predicts along `axis`: tan(half angle) times the cosine between the cone's axis
// and `axis` for a cone, 0 for every other class.
double predictedTaper(const PrimitiveShape& shape, const Eigen::Vector3d& axis);

}  // namespace quadric_slam
