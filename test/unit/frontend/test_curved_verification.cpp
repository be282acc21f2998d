// verifyCurvedCandidates: two upright cylinders side by side in the image, whose search windows
// overlap, are each verified once in parallel and kept as verified (the pixels the first takes do
// not fit the second: its verdict cannot change); a duplicate candidate on the first cylinder's
// pixels is verified again and dropped, as in the sequential order. assignLargestComponent reports
// every pixel that fitted, in whichever component. A flat strip whose normals bend is no cylinder.
// A cylinder along the middle of an elongated ellipsoid is reported as the ellipsoid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "quadric_slam/frontend/curved_candidates.h"
#include "quadric_slam/frontend/curved_verification.h"
#include "quadric_slam/frontend/segmentation_frame.h"

namespace qs = quadric_slam;

namespace {

constexpr int kWidth = 120, kHeight = 60;
constexpr double kFocal = 100.0, kCx = 60.0, kCy = 30.0;
constexpr double kRadius = 0.1, kDepth = 1.0;

// What a pixel's ray meets: the point and the surface's unit normal there.
struct Seen {
  Eigen::Vector3d point, normal;
};

// A kWidth x kHeight cloud: at each pixel, what `see` finds along the pixel's ray (through the
// pinhole of kFocal, kCx, kCy; z component 1) at row v, or no point.
pcl::PointCloud<pcl::PointNormal> rayCloud(
    const std::function<std::optional<Seen>(const Eigen::Vector3d& ray, int v)>& see) {
  pcl::PointCloud<pcl::PointNormal> cloud(kWidth, kHeight);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      pcl::PointNormal& q = cloud(u, v);
      q.x = q.y = q.z = q.normal_x = q.normal_y = q.normal_z = nan;
      const std::optional<Seen> seen =
          see(Eigen::Vector3d((u - kCx) / kFocal, (v - kCy) / kFocal, 1.0), v);
      if (!seen)
        continue;
      q.getVector3fMap() = seen->point.cast<float>();
      q.getNormalVector3fMap() = seen->normal.cast<float>();
    }
  }
  return cloud;
}

// Upright cylinders (axis along the camera's y) at these x offsets, kDepth away; 1 mm of depth
// noise along each ray; pixels that see no cylinder have no point.
pcl::PointCloud<pcl::PointNormal> cylindersCloud(const std::vector<double>& centres_x) {
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.001);
  return rayCloud([&](const Eigen::Vector3d& ray, int) -> std::optional<Seen> {
    double nearest = std::numeric_limits<double>::infinity();
    Eigen::Vector3d normal;
    for (const double cx : centres_x) {
      // (t ray_x - cx)^2 + (t ray_z - kDepth)^2 = r^2 in the x-z plane.
      const double a = ray.x() * ray.x() + ray.z() * ray.z();
      const double b = -2.0 * (ray.x() * cx + ray.z() * kDepth);
      const double c = cx * cx + kDepth * kDepth - kRadius * kRadius;
      const double discriminant = b * b - 4 * a * c;
      if (discriminant < 0)
        continue;
      const double t = (-b - std::sqrt(discriminant)) / (2 * a);
      if (t > 0 && t < nearest) {
        nearest = t;
        const Eigen::Vector3d p = t * ray;
        normal = Eigen::Vector3d(p.x() - cx, 0.0, p.z() - kDepth) / kRadius;
      }
    }
    if (!std::isfinite(nearest))
      return std::nullopt;
    return Seen{(nearest + noise(random)) * ray, normal};
  });
}

qs::SegmentationFrame frameOf(const pcl::PointCloud<pcl::PointNormal>& cloud) {
  qs::SegmentationFrame frame{cloud, kWidth, kHeight, std::vector<std::uint8_t>(cloud.size(), 0),
                              std::vector<std::uint8_t>(cloud.size(), 0)};
  for (std::size_t i = 0; i < cloud.size(); ++i)
    frame.valid[i] = std::isfinite(cloud.points[i].z);
  return frame;
}

// A candidate proposed as `shape`, its sample every third pixel (CGAL's stride) of the pixels
// within 1 cm of it, appended to the candidates' sample arrays.
qs::CgalShapeDetector::Shape sampledCandidate(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                              const qs::PrimitiveShape& shape,
                                              qs::CurvedCandidates& candidates) {
  qs::CgalShapeDetector::Shape candidate;
  candidate.shape = shape;
  for (int v = 0; v < kHeight; v += 3) {
    for (int u = 0; u < kWidth; u += 3) {
      const pcl::PointNormal& q = cloud(u, v);
      if (!std::isfinite(q.z) || std::abs(shape.distance(qs::pointOf(q))) > 0.01)
        continue;
      candidate.indices.push_back(static_cast<int>(candidates.points.size()));
      candidates.points.push_back(qs::pointOf(q));
      candidates.normals.push_back(qs::normalOf(q));
      candidates.pixels.push_back(v * kWidth + u);
    }
  }
  return candidate;
}

// A candidate per cylinder (sampledCandidate), proposed as the cylinder itself; `duplicate_first`
// proposes the first one twice.
qs::CurvedCandidates candidatesOf(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                  const std::vector<double>& centres_x, bool duplicate_first) {
  qs::CurvedCandidates candidates;
  std::vector<qs::CgalShapeDetector::Shape> shapes;
  for (const double cx : centres_x) {
    shapes.push_back(
        sampledCandidate(cloud,
                         qs::PrimitiveShape::cylinder(Eigen::Vector3d(cx, 0.0, kDepth),
                                                      Eigen::Vector3d::UnitY(), kRadius),
                         candidates));
  }
  candidates.shapes = shapes;
  if (duplicate_first)
    candidates.shapes.insert(candidates.shapes.begin() + 1, shapes.front());
  return candidates;
}

struct Verified {
  std::vector<std::vector<int>> supports;
  int verified_again = 0;
};

Verified verify(const pcl::PointCloud<pcl::PointNormal>& cloud,
                const qs::CurvedCandidates& candidates, int threads) {
  qs::SegmentationFrame frame = frameOf(cloud);
  qs::QuadricSegmenter::Params params;
  params.threads = threads;
  const qs::ShapeRefiner refiner(params.refiner);
  Verified out;
  out.verified_again = qs::verifyCurvedCandidates(
      frame, candidates, params, refiner,
      [&](const std::vector<int>& indices, const qs::ShapeRefiner::Result& fit) {
        EXPECT_EQ(fit.shape.quadric_class, qs::QuadricClass::kCylinder);
        for (int i : indices)
          frame.used[i] = 1;
        out.supports.push_back(indices);
      });
  return out;
}

const std::vector<double> kCentres = {-0.12, 0.12};

// Both cylinders kept, in parallel as in order, with this many verdicts verified again.
void expectTheSequentialVerdicts(bool duplicate_first, int verified_again) {
  const auto cloud = cylindersCloud(kCentres);
  const qs::CurvedCandidates candidates = candidatesOf(cloud, kCentres, duplicate_first);
  const Verified sequential = verify(cloud, candidates, 1);
  const Verified parallel = verify(cloud, candidates, 2);
  ASSERT_EQ(sequential.supports.size(), 2u);
  EXPECT_EQ(parallel.supports, sequential.supports);
  EXPECT_EQ(parallel.verified_again, verified_again);
}

}  // namespace

// The windows searched for the supports (the samples' box grown by 4 x cgal_stride pixels)
// overlap: the image gap between the cylinders is narrower than that.
TEST(CurvedVerification, OverlappingWindowsWithDisjointSupportsAreNotVerifiedAgain) {
  expectTheSequentialVerdicts(false, 0);
}

TEST(CurvedVerification, ACandidateOnTakenPixelsIsVerifiedAgainAndDropped) {
  expectTheSequentialVerdicts(true, 1);
}

TEST(CurvedVerification, AssignmentReportsEveryFittingPixel) {
  const auto cloud = cylindersCloud({0.0});
  qs::SegmentationFrame frame = frameOf(cloud);
  // A column of missing depth splits the cylinder's pixels into two components.
  for (int v = 0; v < kHeight; ++v)
    frame.valid[v * kWidth + 55] = 0;
  qs::QuadricSegmenter::Params params;
  params.min_curved_points = 50;
  const qs::PrimitiveShape cylinder = qs::PrimitiveShape::cylinder(
      Eigen::Vector3d(0.0, 0.0, kDepth), Eigen::Vector3d::UnitY(), kRadius);
  std::vector<int> eligible;
  const std::vector<int> support = qs::assignLargestComponent(
      frame, cylinder, qs::ImageRoi{0, 0, kWidth, kHeight}, params, &eligible);
  int seen = 0, left = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    seen += frame.valid[i];
    left += frame.valid[i] && static_cast<int>(i % kWidth) < 55;
  }
  ASSERT_GT(left, params.min_curved_points);
  // Every valid pixel fits (1 mm noise, true normals); the support is the larger side only (both
  // sides face the camera alike, so the smaller does not join as the surface's other face).
  EXPECT_EQ(static_cast<int>(eligible.size()), seen);
  EXPECT_EQ(static_cast<int>(support.size()), std::max(left, seen - left));
}

// A flat strip of a wall whose normals bend across it as a cylinder's would: the normal
// estimation's windows smooth across the strip's border with a neighbouring surface (a wall's strip
// beside the floor). A cylinder proposed there, tangent to the strip with the normals' curvature,
// fits the points no closer than their plane, and is not kept.
TEST(CurvedVerification, AFlatStripWithBendingNormalsIsNoCylinder) {
  constexpr int kTop = 20, kRows = 12;
  constexpr double kWall = 0.9, kBend = 0.6;  // depth (m); normals' turn across the strip (rad)
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 0.001);
  const auto cloud = rayCloud([&](const Eigen::Vector3d& ray, int v) -> std::optional<Seen> {
    if (v < kTop || v >= kTop + kRows)
      return std::nullopt;
    const double turn = kBend * (v - kTop) / (kRows - 1);
    return Seen{(kWall + noise(random)) * ray,
                Eigen::Vector3d(0.0, std::sin(turn), -std::cos(turn))};
  });
  // The cylinder the normals describe: curvature kBend over the strip's height, axis along x,
  // touching the strip along its middle row.
  const double height = kRows * kWall / kFocal, radius = height / kBend;
  const double middle_y = (kTop + 0.5 * kRows - kCy) / kFocal * kWall;
  qs::CurvedCandidates candidates;
  qs::CgalShapeDetector::Shape shape;
  shape.shape = qs::PrimitiveShape::cylinder(Eigen::Vector3d(0.0, middle_y, kWall + radius),
                                             Eigen::Vector3d::UnitX(), radius);
  for (int v = kTop; v < kTop + kRows; v += 3)
    for (int u = 0; u < kWidth; u += 3) {
      shape.indices.push_back(static_cast<int>(candidates.points.size()));
      candidates.points.push_back(qs::pointOf(cloud(u, v)));
      candidates.normals.push_back(qs::normalOf(cloud(u, v)));
      candidates.pixels.push_back(v * kWidth + u);
    }
  candidates.shapes.push_back(shape);
  qs::SegmentationFrame frame = frameOf(cloud);
  const qs::QuadricSegmenter::Params params;
  const qs::ShapeRefiner refiner(params.refiner);
  int accepted = 0;
  qs::verifyCurvedCandidates(frame, candidates, params, refiner,
                             [&](const std::vector<int>&, const qs::ShapeRefiner::Result& fit) {
                               ++accepted;
                               std::printf("kept: class %d, size %.3f, RMS %.4f m\n",
                                           static_cast<int>(fit.shape.quadric_class),
                                           fit.shape.size, fit.rms);
                             });
  EXPECT_EQ(accepted, 0);
}

// An elongated ellipsoid lying across the view, with depth noise that hides its shape on the strip
// a cylinder along its long axis fits: that support alone passes the shape test. Beyond the support
// the surface continues without a depth jump (the ellipsoid's ends), where the cylinder fails and
// one quadric fits: the ellipsoid is reported instead of the cylinder.
TEST(CurvedVerification, ACylinderAlongAnEllipsoidIsTheEllipsoid) {
  const Eigen::Vector3d centre(0.0, 0.0, 0.6), semi_axes(0.13, 0.08, 0.07);
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0.0, 0.004);
  const auto cloud = rayCloud([&](const Eigen::Vector3d& ray, int) -> std::optional<Seen> {
    // sum_i ((t ray_i - centre_i) / semi_axis_i)^2 = 1
    const Eigen::Vector3d r = ray.cwiseQuotient(semi_axes), c = centre.cwiseQuotient(semi_axes);
    const double a = r.squaredNorm(), b = -2.0 * r.dot(c), d = c.squaredNorm() - 1.0;
    const double discriminant = b * b - 4 * a * d;
    if (discriminant < 0)
      return std::nullopt;
    const double t = (-b - std::sqrt(discriminant)) / (2 * a);
    const Eigen::Vector3d p = t * ray;
    const Eigen::Vector3d normal =
        (p - centre).cwiseQuotient(semi_axes.cwiseProduct(semi_axes)).normalized();
    return Seen{(t + noise(random)) * ray, normal};
  });
  qs::CurvedCandidates candidates;
  candidates.shapes.push_back(sampledCandidate(
      cloud, qs::PrimitiveShape::cylinder(centre, Eigen::Vector3d::UnitX(), 0.075), candidates));
  qs::SegmentationFrame frame = frameOf(cloud);
  const qs::QuadricSegmenter::Params params;
  const qs::ShapeRefiner refiner(params.refiner);
  std::vector<qs::QuadricClass> kept;
  qs::verifyCurvedCandidates(
      frame, candidates, params, refiner,
      [&](const std::vector<int>& indices, const qs::ShapeRefiner::Result& fit) {
        kept.push_back(fit.shape.quadric_class);
        std::printf("kept: class %d, %zu points, RMS %.4f m\n",
                    static_cast<int>(fit.shape.quadric_class), indices.size(), fit.rms);
      });
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept.front(), qs::QuadricClass::kGeneral);
}
