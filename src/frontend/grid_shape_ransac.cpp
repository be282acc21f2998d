#include "quadric_slam/frontend/grid_shape_ransac.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>

#include "quadric_slam/frontend/shape_refiner.h"

namespace quadric_slam {

namespace {

// A sample: point and unit normal.
struct Oriented {
  Eigen::Vector3d p, n;
};

// Assumed share of draws whose further points fall on the seed's surface when the seed does (the
// points are drawn near the seed). It sets the number of draws (the stopping rule below): 0.3
// drew too few on the generated scenes (a far open bin found in 6 of 11 frames), 0.03 cost as
// much as CGAL for little more.
constexpr double kLocalHit = 0.1;
// Draws at most, per extracted shape.
constexpr int kMaxDraws = 1000;
// Share of the neighbourhood scales drawn uniformly; the rest follows the mean score that each
// scale's valid proposals reached (Schnabel et al. 2007, localized sampling: the scale that suits a
// surface's size and noise is learnt while drawing).
constexpr double kUniformScaleShare = 0.5;
// Least-squares refits of the best candidate to its inliers (LO-RANSAC), each kept only when it
// gathers more inliers: a minimal set's shape is only as good as its three noisy normals.
constexpr int kRefits = 2;
// Rounds in a row whose best candidate had no connected support of min_points before the search
// gives up on the remaining points.
constexpr int kMaxFailedRounds = 3;
// Attempts to find a free grid cell near the seed, per further point.
constexpr int kNeighbourAttempts = 12;
// A candidate is scored on its first kPreviewPoints points (in a random order) first, and dropped
// when even kPreviewSlack times that share of the points could not beat the best candidate.
constexpr int kPreviewPoints = 48;
constexpr double kPreviewSlack = 1.5;

// The plane through three points.
std::optional<PrimitiveShape> planeThrough(const Oriented* s) {
  const Eigen::Vector3d n = (s[1].p - s[0].p).cross(s[2].p - s[0].p);
  if (n.norm() < 1e-12)
    return std::nullopt;
  const Eigen::Vector3d unit = n.normalized();
  return PrimitiveShape::plane(unit, unit.dot(s[0].p));
}

// The sphere whose centre lies on both points' normal lines (their closest approach).
std::optional<PrimitiveShape> sphereThrough(const Oriented* s) {
  const Eigen::Vector3d w = s[0].p - s[1].p;
  const double b = s[0].n.dot(s[1].n), d = s[0].n.dot(w), e = s[1].n.dot(w);
  const double denom = 1.0 - b * b;
  if (denom < 1e-6)
    return std::nullopt;
  const double t = (b * e - d) / denom, u = (e - b * d) / denom;
  const Eigen::Vector3d centre = 0.5 * (s[0].p + t * s[0].n + s[1].p + u * s[1].n);
  const double radius = 0.5 * ((s[0].p - centre).norm() + (s[1].p - centre).norm());
  return PrimitiveShape::sphere(centre, radius);
}

// The cylinder whose axis is perpendicular to both normals and meets both normal lines (in the
// plane across the axis, where they intersect).
std::optional<PrimitiveShape> cylinderThrough(const Oriented* s) {
  const Eigen::Vector3d cross = s[0].n.cross(s[1].n);
  if (cross.norm() < 1e-3)
    return std::nullopt;
  const Eigen::Vector3d axis = cross.normalized();
  const auto across = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d {
    return v - axis.dot(v) * axis;
  };
  const Eigen::Vector3d q0 = across(s[0].p), q1 = across(s[1].p);
  const Eigen::Vector3d m0 = across(s[0].n).normalized(), m1 = across(s[1].n).normalized();
  const Eigen::Vector3d w = q0 - q1;
  const double b = m0.dot(m1), d = m0.dot(w), e = m1.dot(w);
  const double denom = 1.0 - b * b;
  if (denom < 1e-6)
    return std::nullopt;
  const double t = (b * e - d) / denom, u = (e - b * d) / denom;
  const Eigen::Vector3d centre = 0.5 * (q0 + t * m0 + q1 + u * m1);
  const double radius = 0.5 * ((q0 - centre).norm() + (q1 - centre).norm());
  return PrimitiveShape::cylinder(centre, axis, radius);
}

// The cone tangent to the three points' planes: the apex where the three tangent planes meet; the
// unit directions from the apex to the points make one angle with the axis, which is therefore
// normal to the plane through their tips. The axis points into the opening (towards the points).
std::optional<PrimitiveShape> coneThrough(const Oriented* s) {
  Eigen::Matrix3d normals;
  normals << s[0].n.transpose(), s[1].n.transpose(), s[2].n.transpose();
  const Eigen::Vector3d offsets(s[0].n.dot(s[0].p), s[1].n.dot(s[1].p), s[2].n.dot(s[2].p));
  if (std::abs(normals.determinant()) < 1e-6)
    return std::nullopt;
  const Eigen::Vector3d apex = normals.partialPivLu().solve(offsets);
  Eigen::Vector3d tips[3];
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = s[k].p - apex;
    if (v.norm() < 1e-9)
      return std::nullopt;
    tips[k] = v.normalized();
  }
  Eigen::Vector3d axis = (tips[1] - tips[0]).cross(tips[2] - tips[0]);
  if (axis.norm() < 1e-9)
    return std::nullopt;
  axis.normalize();
  if (axis.dot(tips[0] + tips[1] + tips[2]) < 0)
    axis = -axis;
  const double half_angle = std::acos(std::clamp(axis.dot(tips[0]), -1.0, 1.0));
  if (!(half_angle > 0 && half_angle < M_PI / 2))
    return std::nullopt;
  return PrimitiveShape::cone(apex, axis, half_angle);
}

// A neighbourhood scale in [0, sum.size()): kUniformScaleShare uniformly, the rest in proportion
// to the mean score of each scale's proposals so far.
int drawScale(const std::vector<double>& sum, const std::vector<double>& count,
              std::mt19937& random) {
  const int scales = static_cast<int>(sum.size());
  std::vector<double> mean(scales, 0.0);
  double total = 0;
  for (int l = 0; l < scales; ++l) {
    mean[l] = count[l] > 0 ? sum[l] / count[l] : 0.0;
    total += mean[l];
  }
  double x = std::uniform_real_distribution<double>(0.0, 1.0)(random);
  for (int l = 0; l < scales; ++l) {
    const double learnt = total > 0 ? mean[l] / total : 1.0 / scales;
    x -= kUniformScaleShare / scales + (1 - kUniformScaleShare) * learnt;
    if (x <= 0)
      return l;
  }
  return scales - 1;
}

}  // namespace

GridShapeRansac::GridShapeRansac(const Params& params) : params_(params) {
  params_.validate();
}

std::vector<GridShapeRansac::Shape> GridShapeRansac::detect(
    const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
    const std::vector<Eigen::Vector2i>& cells) const {
  if (points.size() != normals.size() || points.size() != cells.size())
    throw std::invalid_argument("GridShapeRansac: points, normals and cells differ in length");
  std::vector<Shape> shapes;
  const int n = static_cast<int>(points.size());
  const int min_points = params_.min_points;
  if (n < min_points)
    return shapes;

  // The grid of cells over the points' bounding box: each cell's point, or -1.
  Eigen::Vector2i lo = cells[0], hi = cells[0];
  for (const Eigen::Vector2i& c : cells) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const int grid_w = hi.x() - lo.x() + 1, grid_h = hi.y() - lo.y() + 1;
  std::vector<int> grid(static_cast<std::size_t>(grid_w) * grid_h, -1);
  const auto cellIndex = [&](int u, int v) { return (v - lo.y()) * grid_w + (u - lo.x()); };
  for (int i = 0; i < n; ++i)
    grid[cellIndex(cells[i].x(), cells[i].y())] = i;
  // Scales of the neighbourhoods the further points are drawn from: within 2, 4, ... cells of the
  // seed, up to the grid's extent.
  int scales = 1;
  while ((2 << scales) < std::max(grid_w, grid_h))
    ++scales;

  const double eps = params_.epsilon, cos_min = params_.normal_threshold;
  ShapeRefiner::Params refiner_params;
  refiner_params.max_iterations = 5;
  const ShapeRefiner refiner(refiner_params);
  const auto fits = [&](const PrimitiveShape& shape, int i) {
    return std::abs(shape.distance(points[i])) <= eps &&
           std::abs(shape.normalAt(points[i]).dot(normals[i])) >= cos_min;
  };

  std::mt19937 random(params_.random_seed);
  std::vector<std::uint8_t> free(n, 1);
  std::vector<int> free_list(n);
  for (int i = 0; i < n; ++i)
    free_list[i] = i;
  std::vector<int> support, stack;
  std::vector<std::uint8_t> inlier(n, 0), seen(n, 0);
  int failed_rounds = 0;
  while (static_cast<int>(free_list.size()) >= min_points && failed_rounds < kMaxFailedRounds) {
    const int remaining = static_cast<int>(free_list.size());
    std::shuffle(free_list.begin(), free_list.end(), random);  // the preview's random order
    std::uniform_int_distribution<int> pick(0, remaining - 1);
    // Per neighbourhood scale: the summed score of its valid proposals, and their number.
    std::vector<double> scale_sum(scales, 0.0), scale_count(scales, 0.0);
    // Draws needed for a chance below `probability` of missing a surface of `size` points.
    const auto drawsFor = [&](int size) {
      const double hit = kLocalHit * std::min(1.0, static_cast<double>(size) / remaining);
      return std::min(kMaxDraws, static_cast<int>(std::ceil(std::log(params_.probability) /
                                                            std::log1p(-std::min(hit, 0.999)))));
    };
    std::optional<PrimitiveShape> best;
    int best_score = 0;
    for (int draw = 0; draw < drawsFor(std::max(min_points, best_score)); ++draw) {
      Oriented sample[3];
      int chosen[3] = {free_list[pick(random)], -1, -1};
      const int level = drawScale(scale_sum, scale_count, random);
      const int radius = 2 << level;
      std::uniform_int_distribution<int> offset(-radius, radius);
      int count = 1;
      for (int attempt = 0; attempt < kNeighbourAttempts && count < 3; ++attempt) {
        const int u = cells[chosen[0]].x() + offset(random);
        const int v = cells[chosen[0]].y() + offset(random);
        if (u < lo.x() || u > hi.x() || v < lo.y() || v > hi.y())
          continue;
        const int k = grid[cellIndex(u, v)];
        if (k < 0 || !free[k] || k == chosen[0] || k == chosen[1])
          continue;
        chosen[count++] = k;
      }
      if (count < 3)
        continue;
      for (int k = 0; k < 3; ++k)
        sample[k] = {points[chosen[k]], normals[chosen[k]]};
      const std::optional<PrimitiveShape> proposals[4] = {
          params_.planes ? planeThrough(sample) : std::nullopt,
          params_.spheres ? sphereThrough(sample) : std::nullopt,
          params_.cylinders ? cylinderThrough(sample) : std::nullopt,
          params_.cones ? coneThrough(sample) : std::nullopt};
      for (const std::optional<PrimitiveShape>& proposal : proposals) {
        if (!proposal || !fits(*proposal, chosen[0]) || !fits(*proposal, chosen[1]) ||
            !fits(*proposal, chosen[2]))
          continue;
        int score = 0, scored = 0;
        bool dropped = false;
        for (const int i : free_list) {
          score += fits(*proposal, i);
          if (++scored == kPreviewPoints && remaining > 2 * kPreviewPoints &&
              kPreviewSlack * score * remaining < static_cast<double>(best_score) * scored) {
            dropped = true;
            break;
          }
        }
        scale_sum[level] += dropped ? 0 : score;
        scale_count[level] += 1;
        if (!dropped && score > best_score) {
          best_score = score;
          best = proposal;
        }
      }
    }
    if (!best || best_score < min_points)
      break;
    for (int refit = 0; refit < kRefits; ++refit) {
      std::vector<Eigen::Vector3d> on;
      for (const int i : free_list)
        if (fits(*best, i))
          on.push_back(points[i]);
      const ShapeRefiner::Result result = refiner.refine(*best, on);
      if (!result.ok || !result.shape.point.allFinite() || !result.shape.direction.allFinite() ||
          !std::isfinite(result.shape.size))
        break;
      int score = 0;
      for (const int i : free_list)
        score += fits(result.shape, i);
      if (score <= best_score)
        break;
      best = result.shape;
      best_score = score;
    }
    // The support: the largest grid-connected set of the free points that fit.
    for (const int i : free_list)
      inlier[i] = fits(*best, i);
    std::vector<int> largest;
    for (const int start : free_list) {
      if (!inlier[start] || seen[start])
        continue;
      support.clear();
      stack.assign(1, start);
      seen[start] = 1;
      while (!stack.empty()) {
        const int k = stack.back();
        stack.pop_back();
        support.push_back(k);
        for (int dv = -kClusterCells; dv <= kClusterCells; ++dv) {
          for (int du = -kClusterCells; du <= kClusterCells; ++du) {
            const int u = cells[k].x() + du, v = cells[k].y() + dv;
            if (u < lo.x() || u > hi.x() || v < lo.y() || v > hi.y())
              continue;
            const int m = grid[cellIndex(u, v)];
            if (m < 0 || !inlier[m] || seen[m])
              continue;
            seen[m] = 1;
            stack.push_back(m);
          }
        }
      }
      if (support.size() > largest.size())
        largest = support;
    }
    for (const int i : free_list)
      inlier[i] = seen[i] = 0;
    if (static_cast<int>(largest.size()) < min_points) {
      ++failed_rounds;
      continue;
    }
    failed_rounds = 0;
    Shape shape;
    shape.shape = *best;
    std::sort(largest.begin(), largest.end());
    shape.indices = largest;
    for (const int i : largest)
      free[i] = 0;
    free_list.erase(
        std::remove_if(free_list.begin(), free_list.end(), [&](int i) { return !free[i]; }),
        free_list.end());
    shapes.push_back(std::move(shape));
  }
  return shapes;
}

}  // namespace quadric_slam
