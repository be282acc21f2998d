#include "quadric_slam/frontend/grid_shape_ransac.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>

#include "quadric_slam/frontend/minimal_shapes.h"
#include "quadric_slam/frontend/shape_refiner.h"

namespace quadric_slam {

namespace {

// Assumed share of draws whose further points fall on the seed's surface when the seed does (the
// points are drawn near the seed). It sets the number of draws (the stopping rule below): 0.1
// drew too few on the generated scenes (far open bins and cones missed), 0.025 finds what CGAL
// finds at half its instructions.
constexpr double kLocalHit = 0.025;
// Draws at most, per extracted shape.
constexpr int kMaxDraws = 1000;
// Share of the neighbourhood scales drawn uniformly; the rest follows the mean score that each
// scale's proposals reached (after Schnabel et al. 2007's localised sampling: the scale that suits
// a surface's size and noise is learnt while drawing).
constexpr double kUniformScaleShare = 0.5;
// Attempts to find a free grid cell near the seed, per further point.
constexpr int kNeighbourAttempts = 12;
// A proposal is scored on its first kFirstCheck points (in a random order), then on twice as many,
// and so on, and dropped at a check when even kPreviewSlack times its share of inliers could not
// beat the best proposal or reach min_points.
constexpr int kFirstCheck = 48;
constexpr double kPreviewSlack = 1.5;
// When proposals of different classes are compared, a cone's inliers count kConeMargin times less
// and a sphere's kSphereMargin times less than a plane's or a cylinder's. A cone has one parameter
// more than a cylinder and fits the border of two surfaces (a bin's side and the floor beside it)
// with a wide opening. A sphere fits a short cylinder's visible side (height about its diameter)
// within epsilon as well as the cylinder does, and the verification can make a sphere of a
// cylinder candidate but not a cylinder of a sphere candidate (curved_model_selection.h).
constexpr double kConeMargin = 1.25;
constexpr double kSphereMargin = 1.1;
// After the draws, the best proposal of each class that reaches this share of the best's rank is
// refitted to its inliers (LO-RANSAC, Chum et al. 2003) up to kRefits times, each refit kept only
// when it gathers more inliers, before the classes are compared: a minimal set's shape is only as
// good as its three noisy normals, and a far cylinder's proposals stay below a plane's strip of
// it until refitted.
constexpr double kRefitShare = 0.7;
constexpr int kRefits = 2;
constexpr int kRefitIterations = 3;
// Rounds in a row whose best candidate had no connected support of min_points before the search
// gives up on the remaining points.
constexpr int kMaxFailedRounds = 3;

// A small, fast generator (xorshift64*, Vigna 2016) with an unbiased-enough range reduction
// (Lemire 2019's multiply-shift): the draws need speed, not statistical perfection.
class FastRandom {
 public:
  explicit FastRandom(unsigned int seed) : state_(0x9E3779B97F4A7C15ull ^ (seed + 1ull)) {}
  std::uint32_t next() {
    state_ ^= state_ >> 12;
    state_ ^= state_ << 25;
    state_ ^= state_ >> 27;
    return static_cast<std::uint32_t>((state_ * 0x2545F4914F6CDD1Dull) >> 32);
  }
  // Uniform in [0, n), n > 0.
  int below(int n) {
    return static_cast<int>((static_cast<std::uint64_t>(next()) * static_cast<std::uint32_t>(n)) >>
                            32);
  }
  // Uniform in [-r, r].
  int within(int r) { return below(2 * r + 1) - r; }
  double unit() { return next() * (1.0 / 4294967296.0); }

 private:
  std::uint64_t state_;
};

// The neighbourhood scale of a draw, in [0, sum.size()): kUniformScaleShare uniformly, the rest in
// proportion to the mean score of each scale's proposals so far.
int drawScale(const std::vector<double>& sum, const std::vector<double>& count,
              FastRandom& random) {
  const int scales = static_cast<int>(sum.size());
  std::vector<double> mean(scales, 0.0);
  double total = 0;
  for (int l = 0; l < scales; ++l) {
    mean[l] = count[l] > 0 ? sum[l] / count[l] : 0.0;
    total += mean[l];
  }
  double x = random.unit();
  for (int l = 0; l < scales; ++l) {
    const double learnt = total > 0 ? mean[l] / total : 1.0 / scales;
    x -= kUniformScaleShare / scales + (1 - kUniformScaleShare) * learnt;
    if (x <= 0)
      return l;
  }
  return scales - 1;
}

// The sample's cells over their bounding box: which point sits in cell (u, v).
class CellGrid {
 public:
  explicit CellGrid(const std::vector<Eigen::Vector2i>& cells) : lo_(cells[0]), hi_(cells[0]) {
    for (const Eigen::Vector2i& c : cells) {
      lo_ = lo_.cwiseMin(c);
      hi_ = hi_.cwiseMax(c);
    }
    width_ = hi_.x() - lo_.x() + 1;
    index_.assign(static_cast<std::size_t>(width_) * (hi_.y() - lo_.y() + 1), -1);
    for (int i = 0; i < static_cast<int>(cells.size()); ++i)
      index_[offset(cells[i].x(), cells[i].y())] = i;
  }
  // The point in cell (u, v), or -1.
  int at(int u, int v) const {
    if (u < lo_.x() || u > hi_.x() || v < lo_.y() || v > hi_.y())
      return -1;
    return index_[offset(u, v)];
  }
  int extent() const { return std::max(width_, hi_.y() - lo_.y() + 1); }

 private:
  std::size_t offset(int u, int v) const {
    return static_cast<std::size_t>(v - lo_.y()) * width_ + (u - lo_.x());
  }
  Eigen::Vector2i lo_, hi_;
  int width_ = 0;
  std::vector<int> index_;
};

// A proposal and what it scored: inliers among the free points, and its rank (inliers, a cone's
// divided by kConeMargin).
struct Candidate {
  std::optional<PrimitiveShape> shape;
  int score = 0;
  double rank = 0;
};

double rankOf(const PrimitiveShape& shape, int score) {
  switch (shape.quadric_class) {
    case QuadricClass::kCone:
      return score / kConeMargin;
    case QuadricClass::kSphere:
      return score / kSphereMargin;
    default:
      return score;
  }
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
  const CellGrid grid(cells);
  // Neighbourhoods the further points are drawn from: within 2, 4, ... cells of the seed, up to
  // the grid's extent.
  int scales = 1;
  while ((2 << scales) < grid.extent())
    ++scales;
  const double eps = params_.epsilon, cos_min = params_.normal_threshold;
  ShapeRefiner::Params refiner_params;
  refiner_params.max_iterations = kRefitIterations;
  const ShapeRefiner refiner(refiner_params);

  FastRandom random(params_.random_seed);
  std::vector<std::uint8_t> free(n, 1);
  std::vector<int> free_list(n);
  for (int i = 0; i < n; ++i)
    free_list[i] = i;
  const auto inliersOf = [&](const PrimitiveShape& shape) {
    const ShapeInlierTest fits(shape, eps, cos_min);
    int score = 0;
    for (const int i : free_list)
      score += fits(points[i], normals[i]);
    return score;
  };
  // Refits a candidate to its inliers while that gathers more of them.
  const auto refit = [&](Candidate& candidate) {
    for (int round = 0; round < kRefits; ++round) {
      const ShapeInlierTest fits(*candidate.shape, eps, cos_min);
      std::vector<Eigen::Vector3d> on;
      for (const int i : free_list)
        if (fits(points[i], normals[i]))
          on.push_back(points[i]);
      const ShapeRefiner::Result result = refiner.refine(*candidate.shape, on);
      if (!result.ok || result.shape.quadric_class != candidate.shape->quadric_class ||
          !result.shape.point.allFinite() || !result.shape.direction.allFinite() ||
          !std::isfinite(result.shape.size))
        return;
      const int score = inliersOf(result.shape);
      if (score <= candidate.score)
        return;
      candidate = {result.shape, score, rankOf(result.shape, score)};
    }
  };

  std::vector<int> support, stack, largest;
  std::vector<std::uint8_t> inlier(n, 0), seen(n, 0);
  int failed_rounds = 0;
  while (static_cast<int>(free_list.size()) >= min_points && failed_rounds < kMaxFailedRounds) {
    const int remaining = static_cast<int>(free_list.size());
    // The previews' random order (Fisher-Yates).
    for (int k = remaining - 1; k > 0; --k)
      std::swap(free_list[k], free_list[random.below(k + 1)]);
    // Per neighbourhood scale: the summed score of its proposals, and their number.
    std::vector<double> scale_sum(scales, 0.0), scale_count(scales, 0.0);
    // Draws needed for a chance below `probability` of missing a surface of `size` points.
    const auto drawsFor = [&](int size) {
      const double hit = kLocalHit * std::min(1.0, static_cast<double>(size) / remaining);
      return std::min(kMaxDraws, static_cast<int>(std::ceil(std::log(params_.probability) /
                                                            std::log1p(-std::min(hit, 0.999)))));
    };
    Candidate best, class_best[4];
    for (int draw = 0; draw < drawsFor(std::max(min_points, best.score)); ++draw) {
      // A seed, and two free points near it at a drawn scale.
      int chosen[3] = {free_list[random.below(remaining)], -1, -1};
      const int level = drawScale(scale_sum, scale_count, random);
      const int radius = 2 << level;
      int count = 1;
      for (int attempt = 0; attempt < kNeighbourAttempts && count < 3; ++attempt) {
        const int k = grid.at(cells[chosen[0]].x() + random.within(radius),
                              cells[chosen[0]].y() + random.within(radius));
        if (k < 0 || !free[k] || k == chosen[0] || k == chosen[1])
          continue;
        chosen[count++] = k;
      }
      if (count < 3)
        continue;
      OrientedPoint sample[3];
      for (int k = 0; k < 3; ++k)
        sample[k] = {points[chosen[k]], normals[chosen[k]]};
      const std::optional<PrimitiveShape> proposals[4] = {
          params_.planes ? planeThrough(sample) : std::nullopt,
          params_.spheres ? sphereThrough(sample) : std::nullopt,
          params_.cylinders ? cylinderThrough(sample) : std::nullopt,
          params_.cones ? coneThrough(sample) : std::nullopt};
      for (int c = 0; c < 4; ++c) {
        if (!proposals[c])
          continue;
        // The sample itself must fit.
        const ShapeInlierTest fits(*proposals[c], eps, cos_min);
        if (!fits(sample[0].p, sample[0].n) || !fits(sample[1].p, sample[1].n) ||
            !fits(sample[2].p, sample[2].n))
          continue;
        int score = 0, scored = 0, next_check = kFirstCheck;
        bool dropped = false;
        for (const int i : free_list) {
          score += fits(points[i], normals[i]);
          if (++scored == next_check && scored < remaining) {
            next_check *= 2;
            if (kPreviewSlack * score * remaining <
                std::max(best.rank, static_cast<double>(min_points)) * scored) {
              dropped = true;
              break;
            }
          }
        }
        scale_sum[level] += dropped ? 0 : score;
        scale_count[level] += 1;
        if (dropped)
          continue;
        const Candidate proposal{proposals[c], score, rankOf(*proposals[c], score)};
        if (proposal.rank > best.rank)
          best = proposal;
        if (proposal.rank > class_best[c].rank)
          class_best[c] = proposal;
      }
    }
    if (!best.shape)
      break;
    // Each class's best, refitted when near the best, then compared (a tie goes to the class
    // listed first: plane, sphere, cylinder, cone). Refitted before the least support is checked:
    // where the depth noise exceeds epsilon (far surfaces), a shape through three noisy points
    // holds only part of its surface's points, and the refit gathers the rest (a generated cone
    // 2.9 m away: 32-37 of 136 points before, 41 after, against a least support of 40).
    const double refit_rank = kRefitShare * best.rank;
    best = Candidate();
    for (Candidate& candidate : class_best) {
      if (!candidate.shape)
        continue;
      if (candidate.rank >= refit_rank)
        refit(candidate);
      if (candidate.rank > best.rank)
        best = candidate;
    }
    if (!best.shape || best.score < min_points)
      break;
    // The support: the largest grid-connected set of the free points that fit.
    const ShapeInlierTest fits(*best.shape, eps, cos_min);
    for (const int i : free_list)
      inlier[i] = fits(points[i], normals[i]);
    largest.clear();
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
            const int m = grid.at(cells[k].x() + du, cells[k].y() + dv);
            if (m < 0 || !inlier[m] || seen[m])
              continue;
            seen[m] = 1;
            stack.push_back(m);
          }
        }
      }
      if (support.size() > largest.size())
        largest.swap(support);
    }
    for (const int i : free_list)
      inlier[i] = seen[i] = 0;
    if (static_cast<int>(largest.size()) < min_points) {
      ++failed_rounds;
      continue;
    }
    failed_rounds = 0;
    Shape shape;
    shape.shape = *best.shape;
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
