// growPlaneCells (frontend/plane_cells.h): planes grown over cells judged by their own plane fits.
// Scenes are rendered on a 320 x 240 grid (the segmenter's grid at decimation 2) with the depth
// noise of frontend/plane_region_grower.h's sensor model (Nguyen et al. x 1.4, with the disparity
// quantisation's depth steps), and with pixel normals scattered as the estimator's are at 4 m.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <random>

#include "quadric_slam/frontend/plane_cells.h"
#include "quadric_slam/frontend/plane_region_grower.h"

namespace qs = quadric_slam;

namespace {

constexpr int kWidth = 320, kHeight = 240;
constexpr double kFocal = 292.5, kCx = 160.0, kCy = 120.0;

// What a ray (direction, unit z = 1 scaled) hits: depth along z and the true normal, or nothing.
struct Hit {
  bool ok = false;
  double z = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};
using Surface = std::function<Hit(const Eigen::Vector3d& ray)>;

// A plane n.p = d (n towards the camera, d < 0) as seen along the ray, when in front.
Hit planeHit(const Eigen::Vector3d& ray, const Eigen::Vector3d& n, double d) {
  Hit hit;
  const double t = d / n.dot(ray);
  if (t > 0 && n.dot(ray) < 0) {
    hit.ok = true;
    hit.z = t;
    hit.normal = n;
  }
  return hit;
}

// The organized cloud of the nearest surface per pixel: depth noise of the sensor model, depth
// quantised in disparity steps, normals scattered by normal_noise (rad, per component).
pcl::PointCloud<pcl::PointNormal> render(const std::vector<Surface>& surfaces, double normal_noise,
                                         std::vector<int>& truth, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  pcl::PointCloud<pcl::PointNormal> cloud(kWidth, kHeight);
  cloud.is_dense = false;
  truth.assign(kWidth * kHeight, -1);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const Eigen::Vector3d ray((u - kCx) / kFocal, (v - kCy) / kFocal, 1.0);
      Hit best;
      int which = -1;
      for (std::size_t s = 0; s < surfaces.size(); ++s) {
        const Hit hit = surfaces[s](ray);
        if (hit.ok && (!best.ok || hit.z < best.z)) {
          best = hit;
          which = static_cast<int>(s);
        }
      }
      pcl::PointNormal& p = cloud(u, v);
      if (!best.ok) {
        p.x = p.y = p.z = p.normal_x = p.normal_y = p.normal_z = NAN;
        continue;
      }
      truth[v * kWidth + u] = which;
      const double sigma = qs::kinectDepthSigma(best.z, 1.4, 0.0);
      const double step = 0.0029 * best.z * best.z;
      const double z = step * std::round((best.z + sigma * gauss(rng)) / step);
      const Eigen::Vector3d point = ray * z;
      Eigen::Vector3d normal =
          best.normal + normal_noise * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
      normal.normalize();
      p.x = static_cast<float>(point.x());
      p.y = static_cast<float>(point.y());
      p.z = static_cast<float>(point.z());
      p.normal_x = static_cast<float>(normal.x());
      p.normal_y = static_cast<float>(normal.y());
      p.normal_z = static_cast<float>(normal.z());
    }
  }
  return cloud;
}

std::vector<std::uint8_t> validOf(const pcl::PointCloud<pcl::PointNormal>& cloud) {
  std::vector<std::uint8_t> valid(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    valid[i] = std::isfinite(cloud.points[i].z) ? 1 : 0;
  return valid;
}

// The grower's parameters on the grid decimated by 2 (multi_resolution_labels.h's coarseParams).
qs::PlaneRegionGrower::Params coarseGrowerParams(int cell_size, double cell_min_depth = 3.0) {
  qs::PlaneRegionGrower::Params p;
  p.cell_min_depth = cell_min_depth;
  p.min_points = 125;
  p.min_fragment_points = 25;
  p.seed_stride = 2;
  p.cell_size = cell_size;
  p.correlated_points = 16;
  return p;
}

// Share of the truth surface's pixels in the largest region, and of that region's pixels on it.
void largestRegionCover(const std::vector<qs::PlaneRegionGrower::Region>& regions,
                        const std::vector<int>& truth, int surface, double& recall,
                        double& precision) {
  recall = precision = 0;
  const double total = static_cast<double>(std::count(truth.begin(), truth.end(), surface));
  for (const auto& region : regions) {
    int on = 0;
    for (int i : region.indices)
      on += truth[i] == surface;
    if (on / total > recall) {
      recall = on / total;
      precision = static_cast<double>(on) / region.indices.size();
    }
  }
}

}  // namespace

// A wall 4 m away filling the view, pixel normals scattered by about 20 deg (the estimator's at
// that range): the cells grow it as one region with the wall's plane; growing pixel by pixel, the
// largest region gets under half of it.
TEST(PlaneCells, FarWallWithNoisyNormalsIsOneRegion) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, 0.0, -1.0).normalized();
  const double d = -4.0;
  std::vector<int> truth;
  const auto cloud = render({[&](const Eigen::Vector3d& ray) { return planeHit(ray, n, d); }},
                            0.35, truth);
  const auto valid = validOf(cloud);

  std::vector<std::uint8_t> used(cloud.size(), 0);
  const auto regions = qs::growPlaneCells(cloud, valid, used, coarseGrowerParams(8));
  ASSERT_FALSE(regions.empty());
  double recall = 0, precision = 0;
  largestRegionCover(regions, truth, 0, recall, precision);
  EXPECT_GE(recall, 0.9);
  EXPECT_EQ(regions.size(), 1u);
  const auto& plane = regions.front().plane;
  EXPECT_LT(std::acos(std::min(1.0, std::abs(plane.direction.dot(n)))), 1.0 * M_PI / 180);
  EXPECT_NEAR(std::abs(plane.direction.dot(plane.point)), std::abs(d), 0.02);
  for (int i : regions.front().indices)
    EXPECT_EQ(used[i], 1);

  std::vector<std::uint8_t> used_pixels(cloud.size(), 0);
  const auto pixel_regions =
      qs::PlaneRegionGrower(coarseGrowerParams(0)).grow(cloud, valid, used_pixels);
  double pixel_recall = 0;
  largestRegionCover(pixel_regions, truth, 0, pixel_recall, precision);
  EXPECT_LT(pixel_recall, 0.5) << "the scene no longer shows what the cells are for";
}

// A floor meeting a wall at 2.5-3.5 m, cells from 2 m: two regions, neither taking the other's pixels along the
// crease (where the wall's pixels lie within the floor's distance threshold).
TEST(PlaneCells, CreaseKeepsTwoSurfacesApart) {
  const Eigen::Vector3d floor_n(0.0, -1.0, 0.0), wall_n(0.0, 0.0, -1.0);
  std::vector<int> truth;
  const auto cloud =
      render({[&](const Eigen::Vector3d& ray) { return planeHit(ray, floor_n, -0.8); },
              [&](const Eigen::Vector3d& ray) { return planeHit(ray, wall_n, -3.0); }},
             0.05, truth);
  const auto valid = validOf(cloud);
  std::vector<std::uint8_t> used(cloud.size(), 0);
  const auto regions = qs::growPlaneCells(cloud, valid, used, coarseGrowerParams(8, 2.0));
  for (int surface : {0, 1}) {
    SCOPED_TRACE(surface == 0 ? "floor" : "wall");
    double recall = 0, precision = 0;
    largestRegionCover(regions, truth, surface, recall, precision);
    EXPECT_GE(recall, 0.8);
    EXPECT_GE(precision, 0.99);
  }
}

// A cylinder of 0.25 m radius at 1.5 m, cells allowed at every depth: its cells are flat within
// the noise and chain along the axis, but no region survives the flatness test, and no pixel is
// taken.
TEST(PlaneCells, CurvedSurfaceGivesNoRegion) {
  const double radius = 0.25, centre_z = 1.5;
  std::vector<int> truth;
  const auto cloud = render({[&](const Eigen::Vector3d& ray) {
                              // x^2 + (z - c)^2 = r^2 along ray t (x_r, ., 1).
                              Hit hit;
                              const double a = ray.x() * ray.x() + 1.0;
                              const double b = -2.0 * centre_z;
                              const double c = centre_z * centre_z - radius * radius;
                              const double disc = b * b - 4 * a * c;
                              if (disc < 0)
                                return hit;
                              hit.z = (-b - std::sqrt(disc)) / (2 * a);
                              hit.ok = true;
                              const Eigen::Vector3d p = ray * hit.z;
                              hit.normal = Eigen::Vector3d(p.x(), 0, p.z() - centre_z) / radius;
                              return hit;
                            }},
                            0.05, truth);
  const auto valid = validOf(cloud);
  std::vector<std::uint8_t> used(cloud.size(), 0);
  const auto regions = qs::growPlaneCells(cloud, valid, used, coarseGrowerParams(8, 0.0));
  EXPECT_TRUE(regions.empty());
  EXPECT_EQ(std::count(used.begin(), used.end(), 1), 0);
}

// A wall at 1.5 m is left to the pixel grower with the default cell_min_depth (3 m) and grown by
// the cells without it.
TEST(PlaneCells, NearSurfacesAreLeftToThePixels) {
  std::vector<int> truth;
  const auto cloud = render(
      {[&](const Eigen::Vector3d& ray) { return planeHit(ray, Eigen::Vector3d(0, 0, -1), -1.5); }},
      0.05, truth);
  const auto valid = validOf(cloud);
  std::vector<std::uint8_t> used(cloud.size(), 0);
  EXPECT_TRUE(qs::growPlaneCells(cloud, valid, used, coarseGrowerParams(8)).empty());
  const auto regions = qs::growPlaneCells(cloud, valid, used, coarseGrowerParams(8, 0.0));
  double recall = 0, precision = 0;
  largestRegionCover(regions, truth, 0, recall, precision);
  EXPECT_GE(recall, 0.95);
}

TEST(PlaneCells, OffWhenCellSizeBelowTwo) {
  std::vector<int> truth;
  const auto cloud = render(
      {[&](const Eigen::Vector3d& ray) { return planeHit(ray, Eigen::Vector3d(0, 0, -1), -2.0); }},
      0.05, truth);
  std::vector<std::uint8_t> used(cloud.size(), 0);
  EXPECT_TRUE(qs::growPlaneCells(cloud, validOf(cloud), used, coarseGrowerParams(1)).empty());
  qs::PlaneRegionGrower::Params bad = coarseGrowerParams(65);
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = coarseGrowerParams(8, -1.0);
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}
