// computeBoxGradientNormals against a plain reference written the slow, obvious way (explicit edge
// scans and box sums in double), on a real TUM frame: the fixed-point ring of summed-area tables
// must give the same normals. Also: any thread count gives bitwise the same cloud, a reused output
// is fully overwritten, and wide windows over far points do not overflow the 32-bit sums.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "../real_frames.h"
#include "quadric_slam/frontend/box_gradient_normals.h"
#include "quadric_slam/frontend/frame.h"

namespace qs = quadric_slam;

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// Angle between two directions, accurate near zero (acos of a dot product is not: a float normal's
// length differs from 1 by ~1e-7, which acos turns into ~0.03 deg).
double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

// The estimator's rules, written out without any of its speed-ups.
class ReferenceNormals {
 public:
  ReferenceNormals(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                   const qs::BoxGradientSettings& settings)
      : cloud_(cloud), settings_(settings) {}

  bool hasData(int u, int v) const {
    const pcl::PointXYZ& p = cloud_(u, v);
    return std::isfinite(p.z) && p.z > 0 && p.z <= qs::kBoxGradientMaxCoordinate &&
           std::abs(p.x) <= qs::kBoxGradientMaxCoordinate &&
           std::abs(p.y) <= qs::kBoxGradientMaxCoordinate;
  }

  bool isEdge(int u, int v) const {
    if (!hasData(u, v))
      return true;
    const double z = cloud_(u, v).z, limit = settings_.max_depth_change_factor * z;
    const int width = static_cast<int>(cloud_.width), height = static_cast<int>(cloud_.height);
    if (u + 1 < width && hasData(u + 1, v) && std::abs(cloud_(u + 1, v).z - z) > limit)
      return true;
    return v + 1 < height && hasData(u, v + 1) && std::abs(cloud_(u, v + 1).z - z) > limit;
  }

  bool windowFree(int u, int v, int r) const {
    const int h = std::max(1, r / 2);
    for (int dv = -r; dv <= r; ++dv) {
      for (int du = -r; du <= r; ++du) {
        const bool in_window =
            (std::abs(du) <= r && std::abs(dv) <= h) || (std::abs(du) <= h && std::abs(dv) <= r);
        if (in_window && isEdge(u + du, v + dv))
          return false;
      }
    }
    return true;
  }

  Eigen::Vector3d mean(int u0, int u1, int v0, int v1) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u)
        sum += cloud_(u, v).getVector3fMap().cast<double>();
    }
    return sum / ((u1 - u0 + 1) * (v1 - v0 + 1));
  }

  // The normal at (u, v) estimated there (stride 1), facing the sensor; false when none.
  bool normalAt(int u, int v, Eigen::Vector3d& normal) const {
    if (isEdge(u, v))
      return false;
    const int width = static_cast<int>(cloud_.width), height = static_cast<int>(cloud_.height);
    const double z = cloud_(u, v).z;
    double half = settings_.max_half_window;
    if (settings_.depth_dependent_smoothing)
      half *= std::clamp(z / 2.0, 0.25, 1.0);
    const int r_min = std::max(2, static_cast<int>(half) / 3);
    int r = std::min({static_cast<int>(half), u, width - 1 - u, v, height - 1 - v});
    while (r >= r_min && !windowFree(u, v, r))
      --r;
    if (r < r_min)
      return false;
    const int h = std::max(1, r / 2);
    const Eigen::Vector3d along_u =
        mean(u + 1, u + r, v - h, v + h) - mean(u - r, u - 1, v - h, v + h);
    const Eigen::Vector3d along_v =
        mean(u - h, u + h, v + 1, v + r) - mean(u - h, u + h, v - r, v - 1);
    normal = along_u.cross(along_v).normalized();
    if (normal.dot(cloud_(u, v).getVector3fMap().cast<double>()) > 0)
      normal = -normal;
    return true;
  }

 private:
  const pcl::PointCloud<pcl::PointXYZ>& cloud_;
  qs::BoxGradientSettings settings_;
};

bool bitwiseEqual(const pcl::PointCloud<pcl::PointNormal>& a,
                  const pcl::PointCloud<pcl::PointNormal>& b) {
  if (a.size() != b.size() || a.width != b.width)
    return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const float fa[7] = {a[i].x,        a[i].y,        a[i].z,        a[i].normal_x,
                         a[i].normal_y, a[i].normal_z, a[i].curvature};
    const float fb[7] = {b[i].x,        b[i].y,        b[i].z,        b[i].normal_x,
                         b[i].normal_y, b[i].normal_z, b[i].curvature};
    if (std::memcmp(fa, fb, sizeof(fa)) != 0)
      return false;
  }
  return true;
}

}  // namespace

TEST(BoxGradientNormals, AgreesWithTheReferenceOnARealFrame) {
  const auto cloud = qs::test::fr3HouseholdCloud();
  qs::BoxGradientSettings settings;
  settings.stride = 1;
  pcl::PointCloud<pcl::PointNormal> out;
  qs::computeBoxGradientNormals(cloud, settings, out);
  ASSERT_EQ(out.size(), cloud.size());
  const ReferenceNormals reference(cloud, settings);

  std::mt19937 random(7);
  std::uniform_int_distribution<int> pick_u(0, 639), pick_v(0, 479);
  int with_normal = 0, without = 0;
  for (int sample = 0; sample < 3000; ++sample) {
    const int u = pick_u(random), v = pick_v(random);
    const pcl::PointNormal& p = out(u, v);
    ASSERT_EQ(std::memcmp(&p.x, &cloud(u, v).x, 3 * sizeof(float)), 0) << "points are copied";
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    const bool has_reference = reference.normalAt(u, v, expected);
    ASSERT_EQ(has_reference, std::isfinite(p.normal_x)) << u << ", " << v;
    EXPECT_TRUE(std::isnan(p.curvature));
    if (!has_reference) {
      ++without;
      continue;
    }
    ++with_normal;
    const Eigen::Vector3d estimated(p.normal_x, p.normal_y, p.normal_z);
    EXPECT_NEAR(estimated.norm(), 1.0, 1e-6);
    // 32-bit fixed point at micrometre resolution: the same normal to a hundredth of a degree
    // (the worst case is a smallest window on a near surface, ~0.002 deg).
    EXPECT_LT(angleDeg(estimated, expected), 0.01) << u << ", " << v;
  }
  // The frame is mostly smooth surfaces with holes and edges: both cases are exercised.
  EXPECT_GT(with_normal, 1500);
  EXPECT_GT(without, 300);
}

TEST(BoxGradientNormals, EveryThreadCountGivesTheSameCloud) {
  const auto cloud = qs::test::fr3HouseholdCloud();
  for (int stride : {1, 2, 3}) {
    SCOPED_TRACE(stride);
    qs::BoxGradientSettings settings;
    settings.stride = stride;
    settings.threads = 1;
    pcl::PointCloud<pcl::PointNormal> single;
    qs::computeBoxGradientNormals(cloud, settings, single);
    for (int threads : {2, 3, 7}) {
      settings.threads = threads;
      pcl::PointCloud<pcl::PointNormal> parallel;
      qs::computeBoxGradientNormals(cloud, settings, parallel);
      EXPECT_TRUE(bitwiseEqual(single, parallel)) << threads << " threads";
    }
  }
}

TEST(BoxGradientNormals, ReusedOutputIsFullyOverwritten) {
  const auto cloud = qs::test::fr3HouseholdCloud();
  const qs::BoxGradientSettings settings;
  pcl::PointCloud<pcl::PointNormal> fresh;
  qs::computeBoxGradientNormals(cloud, settings, fresh);
  pcl::PointCloud<pcl::PointNormal> reused(cloud.width, cloud.height);
  for (auto& p : reused) {
    p.x = p.y = p.z = 7.f;
    p.normal_x = p.normal_y = p.normal_z = p.curvature = 0.5f;
  }
  const pcl::PointNormal* storage = reused.points.data();
  qs::computeBoxGradientNormals(cloud, settings, reused);
  EXPECT_EQ(reused.points.data(), storage) << "same size: storage kept";
  EXPECT_TRUE(bitwiseEqual(fresh, reused));

  pcl::PointCloud<pcl::PointNormal> wrong_size(3, 3);
  qs::computeBoxGradientNormals(cloud, settings, wrong_size);
  EXPECT_EQ(wrong_size.width, cloud.width);
  EXPECT_EQ(wrong_size.height, cloud.height);
  EXPECT_TRUE(bitwiseEqual(fresh, wrong_size));
}

TEST(BoxGradientNormals, WideWindowsOverFarPointsDoNotOverflow) {
  // A tilted plane 300-900 m away seen through a 640x480 pinhole, smoothed with 100-pixel windows:
  // the largest fixed-point box sums the scale must keep inside 32 bits.
  const Eigen::Vector3d plane_normal = Eigen::Vector3d(0.2, -0.3, -1.0).normalized();
  const double offset = -500.0;
  pcl::PointCloud<pcl::PointXYZ> cloud(640, 480);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3d ray((u - 319.5) / 525.0, (v - 239.5) / 525.0, 1.0);
      const Eigen::Vector3d point = ray * (offset / plane_normal.dot(ray));
      cloud(u, v) = pcl::PointXYZ(static_cast<float>(point.x()), static_cast<float>(point.y()),
                                  static_cast<float>(point.z()));
    }
  }
  cloud(600, 20).z = 2.0f * static_cast<float>(qs::kBoxGradientMaxCoordinate);  // too far: no data
  qs::BoxGradientSettings settings;
  settings.max_half_window = 100;
  settings.stride = 1;
  pcl::PointCloud<pcl::PointNormal> out;
  qs::computeBoxGradientNormals(cloud, settings, out);
  std::vector<double> angles;
  for (const auto& p : out) {
    if (std::isfinite(p.normal_x)) {
      const Eigen::Vector3d n(p.normal_x, p.normal_y, p.normal_z);
      angles.push_back(angleDeg(n, plane_normal));
    }
  }
  ASSERT_GT(angles.size(), 640u * 480u / 3);
  std::sort(angles.begin(), angles.end());
  // Float points 500 m away carry ~30 um of rounding; 100-pixel boxes average it away.
  EXPECT_LT(angles[angles.size() / 2], 0.05);
  EXPECT_LT(angles.back(), 1.0);
  EXPECT_TRUE(std::isnan(out(600, 20).normal_x));
  EXPECT_FLOAT_EQ(out(600, 20).z, cloud(600, 20).z) << "the point itself is kept";
}
