#include "quadric_slam/frontend/silhouette_taper.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace quadric_slam {

namespace {

constexpr int kBins = 8;
// Bins when one side of the outline is cut somewhere: a side's uncut run may be a third of the
// support, and its slope needs kMinTaperBins bins there.
constexpr int kFineBins = 16;
constexpr int kMinPointsPerBin = 8;
constexpr double kMinLength = 0.1;       // m
constexpr double kMinSinViewAxis = 0.2;  // sin(12 deg)
// Chebyshev radius (grid pixels) within which a nearer surface marks an outline pixel as cut: the
// sensor leaves a seam without depth between the two surfaces, 3-5 pixels of the grid the curved
// shapes are fitted on at 2-3 m.
constexpr int kOccluderRadius = 6;
// Chebyshev radius (grid pixels) within which depth that goes on smoothly marks it as cut.
constexpr int kContinuationRadius = 2;

// One point of a bin: its lateral coordinate and whether it lies on a cut outline.
struct Lateral {
  double u;
  bool cut;
};

// A bin's two edges: the extreme lateral coordinates without the extreme points of each side (one
// in 50, at least one: a stray point of a neighbouring surface must not set the width), and whether
// each side is cut (half of its outermost points, a twentieth of the bin and at least three, lie
// on a cut outline: a hole in the support beside one of them does not cut the side).
struct BinEdges {
  double low = 0.0, high = 0.0;
  bool low_cut = false, high_cut = false;
};

BinEdges edgesOf(std::vector<Lateral>& bin) {
  std::sort(bin.begin(), bin.end(), [](const Lateral& a, const Lateral& b) { return a.u < b.u; });
  const std::size_t n = bin.size();
  const std::size_t trim = std::max<std::size_t>(1, n / 50);
  const std::size_t outermost = std::min(n, std::max<std::size_t>(3, n / 20));
  BinEdges edges;
  edges.low = bin[trim].u;
  edges.high = bin[n - 1 - trim].u;
  std::size_t low_cut = 0, high_cut = 0;
  for (std::size_t k = 0; k < outermost; ++k) {
    low_cut += bin[k].cut;
    high_cut += bin[n - 1 - k].cut;
  }
  edges.low_cut = 2 * low_cut >= outermost;
  edges.high_cut = 2 * high_cut >= outermost;
  return edges;
}

// Least squares line y = a + slope x; false with fewer than 3 points or no spread in x.
bool fitLine(const std::vector<double>& xs, const std::vector<double>& ys, double* slope,
             double* slope_sigma) {
  const std::size_t count = xs.size();
  if (count < 3)
    return false;
  const double n = static_cast<double>(count);
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    mx += xs[i] / n;
    my += ys[i] / n;
  }
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    sxx += (xs[i] - mx) * (xs[i] - mx);
    sxy += (xs[i] - mx) * (ys[i] - my);
  }
  if (!(sxx > 0.0))
    return false;
  *slope = sxy / sxx;
  double residual = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double e = ys[i] - (my + *slope * (xs[i] - mx));
    residual += e * e;
  }
  *slope_sigma = std::sqrt(residual / (n - 2.0) / sxx);
  return true;
}

// The points' axial (s) and lateral (u) coordinates binned along s into `bins` equal bins over
// [s_lo, s_lo + length]; per bin its edges and mean s. Bins with fewer than kMinPointsPerBin
// points, and the end bins (there the support is cut by the segment's ends, not by its
// silhouette), are left out.
struct BinnedOutline {
  std::vector<double> s;
  std::vector<BinEdges> edges;
};

BinnedOutline binOutline(const std::vector<double>& s, const std::vector<double>& u,
                         const std::vector<std::uint8_t>& cut, double s_lo, double length,
                         int bins) {
  std::vector<std::vector<Lateral>> bin_u(bins);
  std::vector<double> bin_s(bins, 0.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const int k = std::min(bins - 1, static_cast<int>((s[i] - s_lo) / length * bins));
    bin_u[k].push_back({u[i], !cut.empty() && cut[i] != 0});
    bin_s[k] += s[i];
  }
  BinnedOutline out;
  for (int k = 1; k + 1 < bins; ++k) {
    if (static_cast<int>(bin_u[k].size()) < kMinPointsPerBin)
      continue;
    out.s.push_back(bin_s[k] / static_cast<double>(bin_u[k].size()));
    out.edges.push_back(edgesOf(bin_u[k]));
  }
  return out;
}

}  // namespace

bool significantSlope(double slope, double sigma, double min_slope) {
  return std::abs(slope) > 3.0 * sigma && std::abs(slope) > min_slope;
}

bool SilhouetteTaper::significant(double min_slope) const {
  return bins >= kMinTaperBins && significantSlope(slope, slope_sigma, min_slope);
}

std::vector<std::uint8_t> cutOutline(const SegmentationFrame& frame,
                                     const std::vector<int>& indices,
                                     double max_depth_jump_factor) {
  std::vector<std::uint8_t> cut(indices.size(), 0);
  if (indices.empty())
    return cut;
  const int width = frame.width, height = frame.height;
  const ImageRoi roi = grown(roiOf(indices, width), kOccluderRadius + 1, width, height);
  std::vector<std::uint8_t> inside(static_cast<std::size_t>(roi.width) * roi.height, 0);
  const auto local = [&](int x, int y) {
    return static_cast<std::size_t>(y - roi.y_offset) * roi.width + (x - roi.x_offset);
  };
  for (int i : indices)
    inside[local(i % width, i / width)] = 1;
  const int x_end = roi.x_offset + roi.width, y_end = roi.y_offset + roi.height;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const int x = indices[k] % width, y = indices[k] / width;
    // Only pixels on the support's outline: one of their 4-neighbours outside it.
    const bool outline = x == roi.x_offset || x + 1 == x_end || y == roi.y_offset ||
                         y + 1 == y_end || !inside[local(x - 1, y)] || !inside[local(x + 1, y)] ||
                         !inside[local(x, y - 1)] || !inside[local(x, y + 1)];
    if (!outline)
      continue;
    const float z = frame.cloud.points[indices[k]].z;
    const float jump = z * static_cast<float>(max_depth_jump_factor);
    for (int yy = std::max(roi.y_offset, y - kOccluderRadius);
         yy <= std::min(y_end - 1, y + kOccluderRadius) && !cut[k]; ++yy) {
      for (int xx = std::max(roi.x_offset, x - kOccluderRadius);
           xx <= std::min(x_end - 1, x + kOccluderRadius); ++xx) {
        const int j = yy * width + xx;
        if (inside[local(xx, yy)] || !frame.valid[j])
          continue;
        const float dz = frame.cloud.points[j].z - z;
        const bool near =
            std::abs(xx - x) <= kContinuationRadius && std::abs(yy - y) <= kContinuationRadius;
        if (dz < -jump || (near && dz <= jump)) {
          cut[k] = 1;
          break;
        }
      }
    }
  }
  return cut;
}

SilhouetteTaper measureSilhouetteTaper(const Eigen::Vector3d& axis_point,
                                       const Eigen::Vector3d& axis,
                                       const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<std::uint8_t>& cut) {
  SilhouetteTaper out;
  if (points.size() < static_cast<std::size_t>(kMinTaperBins * kMinPointsPerBin) ||
      !(axis.norm() > 0.0))
    return out;
  const Eigen::Vector3d a = axis.normalized();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points)
    centroid += p;
  centroid /= static_cast<double>(points.size());
  const Eigen::Vector3d across = a.cross(centroid.normalized());
  if (!(across.norm() > kMinSinViewAxis))
    return out;
  const Eigen::Vector3d b = across.normalized();

  std::vector<double> s(points.size()), u(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    s[i] = (points[i] - axis_point).dot(a);
    u[i] = (points[i] - axis_point).dot(b);
  }
  const auto [lo_it, hi_it] = std::minmax_element(s.begin(), s.end());
  const double s_lo = *lo_it, s_hi = *hi_it;
  out.length = s_hi - s_lo;
  if (out.length < kMinLength)
    return out;

  out.axis = a;
  out.across = b;
  const BinnedOutline coarse = binOutline(s, u, cut, s_lo, out.length, kBins);
  const bool any_cut = std::any_of(coarse.edges.begin(), coarse.edges.end(),
                                   [](const BinEdges& e) { return e.low_cut || e.high_cut; });
  if (!any_cut) {
    // Both sides are the silhouette all along: a line through the bins' half widths.
    std::vector<double> half_widths;
    for (const BinEdges& e : coarse.edges)
      half_widths.push_back(0.5 * (e.high - e.low));
    out.bins = static_cast<int>(coarse.s.size());
    if (out.bins < kMinTaperBins || !fitLine(coarse.s, half_widths, &out.slope, &out.slope_sigma))
      out.bins = 0;
    return out;
  }
  // One side is cut somewhere: each side's edge is a line of its own over the bins where that
  // side is the silhouette, and the taper is half the difference of their slopes. Where the
  // support lies across the axis does not enter (a one-sided width measured from the fitted axis
  // would read the axis's position, which the visible strip of a cylinder does not fix).
  const BinnedOutline fine = binOutline(s, u, cut, s_lo, out.length, kFineBins);
  std::vector<double> low_s, low_u, high_s, high_u;
  for (std::size_t k = 0; k < fine.s.size(); ++k) {
    if (!fine.edges[k].low_cut) {
      low_s.push_back(fine.s[k]);
      low_u.push_back(fine.edges[k].low);
    }
    if (!fine.edges[k].high_cut) {
      high_s.push_back(fine.s[k]);
      high_u.push_back(fine.edges[k].high);
    }
  }
  const auto edgeOf = [](const std::vector<double>& xs, const std::vector<double>& us) {
    SilhouetteEdge edge;
    if (static_cast<int>(xs.size()) >= kMinTaperBins &&
        fitLine(xs, us, &edge.slope, &edge.slope_sigma))
      edge.bins = static_cast<int>(xs.size());
    return edge;
  };
  out.low_edge = edgeOf(low_s, low_u);
  out.high_edge = edgeOf(high_s, high_u);
  if (out.low_edge.bins > 0 && out.high_edge.bins > 0) {
    out.bins = std::min(out.low_edge.bins, out.high_edge.bins);
    out.slope = 0.5 * (out.high_edge.slope - out.low_edge.slope);
    out.slope_sigma = 0.5 * std::hypot(out.low_edge.slope_sigma, out.high_edge.slope_sigma);
  }
  return out;
}

double predictedTaper(const PrimitiveShape& shape, const Eigen::Vector3d& axis) {
  if (shape.quadric_class != QuadricClass::kCone || !(axis.norm() > 0.0))
    return 0.0;
  return std::tan(shape.size) * shape.direction.normalized().dot(axis.normalized());
}

double predictedEdgeSlope(const PrimitiveShape& shape, const SilhouetteTaper& taper, bool high) {
  if (shape.quadric_class != QuadricClass::kCone)
    return 0.0;
  const Eigen::Vector3d d = shape.direction.normalized();
  const double along = d.dot(taper.axis), across = d.dot(taper.across);
  if (!(std::abs(along) > 0.0))
    return 0.0;
  // The cone's axis in the (s, u) plane at the angle theta from the s axis; its silhouette
  // generators at theta +- half angle. Along +d the cone widens, so the generator turned towards
  // +u is the high edge when d runs along +s.
  const double theta = std::atan2(across, along);
  const double turn = (along > 0.0) == high ? shape.size : -shape.size;
  return std::tan(theta + turn);
}

}  // namespace quadric_slam
