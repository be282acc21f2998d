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
//
// An edge of the support is the surface's silhouette only where what lies beyond it is farther or
// has no depth. Where a nearer surface stands beside it (an occlusion boundary), or the depth goes
// on smoothly beyond it (the surface continues outside the support), it is cut. Where one side is
// cut somewhere, each side's edge is fitted as a line of its own over the bins where it is the
// silhouette, and k is half the difference of the two slopes; when only one side has enough such
// bins, its edge alone is reported, and a cone is compared with it by the slope the cone's own
// silhouette generator on that side takes (predictedEdgeSlope).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "quadric_slam/frontend/primitive_shape.h"
#include "quadric_slam/frontend/segmentation_frame.h"

namespace quadric_slam {

// One side's silhouette edge as a line u(s) = u0 + slope s (only where the other side is cut).
struct SilhouetteEdge {
  double slope = 0.0;
  double slope_sigma = std::numeric_limits<double>::infinity();
  int bins = 0;  // 0: too few uncut bins on this side for a line
};

struct SilhouetteTaper {
  double slope = 0.0;  // k: change of the visible half width per metre along the axis
  double slope_sigma = std::numeric_limits<double>::infinity();  // its standard error
  int bins = 0;         // bins with enough points that entered the fit
  double length = 0.0;  // extent of the support along the axis (m)
  // The unit axis (s) and the lateral direction (u) the outline was measured along.
  Eigen::Vector3d axis = Eigen::Vector3d::Zero(), across = Eigen::Vector3d::Zero();
  // Each side's own edge when one side of the outline is cut somewhere (low: least u).
  SilhouetteEdge low_edge, high_edge;

  // True when the width changes along the axis beyond the measurement's noise: at least
  // kMinTaperBins bins and significantSlope(slope, slope_sigma, min_slope).
  bool significant(double min_slope) const;
};

// Whether a measured edge or taper slope stands out of its noise: |slope| above 3 sigma and above
// min_slope.
bool significantSlope(double slope, double sigma, double min_slope);

// Bins with enough points a taper needs.
constexpr int kMinTaperBins = 4;

// Which of the support's pixels (indices into frame's grid) lie on a cut outline: a 4-neighbour is
// outside the support and, outside it, a valid pixel within 6 grid pixels is nearer by more than
// max_depth_jump_factor of the pixel's depth, or one within 2 pixels is no farther than that. One
// flag per index.
std::vector<std::uint8_t> cutOutline(const SegmentationFrame& frame,
                                     const std::vector<int>& indices, double max_depth_jump_factor);

// The taper of `points` along the axis through axis_point with direction axis (unit or not);
// `cut` (empty, or one flag per point: cutOutline) marks the points on cut outlines. No taper (bins
// 0) when there are too few points, the support is shorter than 10 cm along the axis (over less, a
// segment's ragged ends and border pixels make the width), the line of sight runs within 12 degrees
// of the axis (the width across it is then not the silhouette), or one side is cut in all but a few
// bins (then low_edge or high_edge may still be measured).
SilhouetteTaper measureSilhouetteTaper(const Eigen::Vector3d& axis_point,
                                       const Eigen::Vector3d& axis,
                                       const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<std::uint8_t>& cut = {});

// The taper `shape` predicts along `axis`: tan(half angle) times the cosine between the cone's axis
// and `axis` for a cone, 0 for every other class.
double predictedTaper(const PrimitiveShape& shape, const Eigen::Vector3d& axis);

// The slope du/ds of the high (or low) silhouette edge that `shape` predicts in the taper's (s, u)
// plane: tan(theta +- half angle) for a cone whose axis runs at theta from s there (the apparent
// half angle taken as the true one), 0 for every other class.
double predictedEdgeSlope(const PrimitiveShape& shape, const SilhouetteTaper& taper, bool high);

}  // namespace quadric_slam
