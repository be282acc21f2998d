#include "quadric_slam/frontend/silhouette_taper.h"

#include <algorithm>
#include <cmath>

namespace quadric_slam {

namespace {

constexpr int kBins = 8;
constexpr int kMinPointsPerBin = 8;
constexpr double kMinLength = 0.1;       // m
constexpr double kMinSinViewAxis = 0.2;  // sin(12 deg)

// The spread of u without the extreme points of each side (one in 50, at least one): a stray
// point of a neighbouring surface must not set the width.
double trimmedSpread(std::vector<double>& u) {
  const std::size_t n = u.size();
  const std::size_t trim = std::max<std::size_t>(1, n / 50);
  std::nth_element(u.begin(), u.begin() + trim, u.end());
  const double lo = u[trim];
  std::nth_element(u.begin(), u.begin() + (n - 1 - trim), u.end());
  const double hi = u[n - 1 - trim];
  return hi - lo;
}

}  // namespace

bool SilhouetteTaper::significant(double min_slope) const {
  return bins >= kMinTaperBins && std::abs(slope) > 3.0 * slope_sigma &&
         std::abs(slope) > min_slope;
}

SilhouetteTaper measureSilhouetteTaper(const Eigen::Vector3d& axis_point,
                                       const Eigen::Vector3d& axis,
                                       const std::vector<Eigen::Vector3d>& points) {
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

  std::vector<std::vector<double>> bin_u(kBins);
  std::vector<double> bin_s(kBins, 0.0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int k = std::min(kBins - 1, static_cast<int>((s[i] - s_lo) / out.length * kBins));
    bin_u[k].push_back(u[i]);
    bin_s[k] += s[i];
  }
  // Least squares line through (mean s, half width) of the bins with enough points. The end bins
  // are left out: there the support is cut by the segment's ends, not by its silhouette.
  std::vector<double> xs, hs;
  for (int k = 1; k + 1 < kBins; ++k) {
    if (static_cast<int>(bin_u[k].size()) < kMinPointsPerBin)
      continue;
    xs.push_back(bin_s[k] / static_cast<double>(bin_u[k].size()));
    hs.push_back(0.5 * trimmedSpread(bin_u[k]));
  }
  out.bins = static_cast<int>(xs.size());
  if (out.bins < kMinTaperBins)
    return out;
  const double n = static_cast<double>(out.bins);
  double mx = 0.0, mh = 0.0;
  for (int i = 0; i < out.bins; ++i) {
    mx += xs[i] / n;
    mh += hs[i] / n;
  }
  double sxx = 0.0, sxh = 0.0;
  for (int i = 0; i < out.bins; ++i) {
    sxx += (xs[i] - mx) * (xs[i] - mx);
    sxh += (xs[i] - mx) * (hs[i] - mh);
  }
  if (!(sxx > 0.0))
    return out;
  out.slope = sxh / sxx;
  double residual = 0.0;
  for (int i = 0; i < out.bins; ++i) {
    const double e = hs[i] - (mh + out.slope * (xs[i] - mx));
    residual += e * e;
  }
  out.slope_sigma = std::sqrt(residual / (n - 2.0) / sxx);
  return out;
}

double predictedTaper(const PrimitiveShape& shape, const Eigen::Vector3d& axis) {
  if (shape.quadric_class != QuadricClass::kCone || !(axis.norm() > 0.0))
    return 0.0;
  return std::tan(shape.size) * shape.direction.normalized().dot(axis.normalized());
}

}  // namespace quadric_slam
