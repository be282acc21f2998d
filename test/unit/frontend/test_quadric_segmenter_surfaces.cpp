// QuadricSegmenter on real Kinect frames (test/data): each large surface is ONE plane segment.
//
// The truth of a surface is independent of the segmenter: a RANSAC plane fit followed by least
// squares on its inliers, on the points of a hand-chosen seed rectangle on that surface (stated
// per surface below, checked against the frames' colour images), then every pixel within three
// standard deviations of the Kinect's axial noise (Nguyen et al. 2012, x1.4 as measured on these
// frames' floors and walls) of that plane and 8-connected to the seed: the surface's pixels. The
// surface passes when one plane segment covers at least a given share of them.
//
// The target: 80%. Measured with the default parameters (decimation 2, plane cells of 16
// pixels from 3 m): fr3 1341847980.723020 floor 92.8%, partition 85.2%, desk top 80.6%;
// 1341847982.998830 floor 91.5%, partition 85.2%, desk top 81.2%; fr2_desk a desk top 86.6%, floor
// to 4 m 82.3%. With cells from 2 m (plane_cell_min_depth 2): 94.0, 91.7, 85.0; 95.4, 89.2, 85.8;
// 88.8, 84.9.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "../test_data.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"

namespace qs = quadric_slam;

namespace {

struct Rect {
  int u0, v0, u1, v1;  // pixel columns [u0, u1), rows [v0, v1)
};

struct Surface {
  std::string name;
  Rect seed;
  double max_depth = 10.0;  // the surface's pixels are those up to this depth (m)
};

struct Case {
  std::string file;  // relative to test/data
  qs::CameraIntrinsics k;
  double units_per_metre;
  std::vector<Surface> surfaces;
};

qs::CameraIntrinsics intrinsics(double fx, double fy, double cx, double cy) {
  qs::CameraIntrinsics k;
  k.fx = fx;
  k.fy = fy;
  k.cx = cx;
  k.cy = cy;
  k.width = 640;
  k.height = 480;
  return k;
}

// One standard deviation of the Kinect's axial noise at depth z (m), x1.4 for real frames.
double sigma(double z) {
  return 1.4 * (0.0012 + 0.0019 * (z - 0.4) * (z - 0.4));
}

// RANSAC (fixed seed) on the seed rectangle's points, then least squares (PCA) on the inliers.
// Returns n, d with n.p = d.
bool robustPlane(const pcl::PointCloud<pcl::PointXYZ>& cloud, const Rect& r, Eigen::Vector3d& n,
                 double& d) {
  std::vector<Eigen::Vector3d> points;
  for (int v = r.v0; v < r.v1; ++v)
    for (int u = r.u0; u < r.u1; ++u) {
      const pcl::PointXYZ& p = cloud(u, v);
      if (std::isfinite(p.z) && p.z > 0)
        points.emplace_back(p.x, p.y, p.z);
    }
  if (points.size() < 50)
    return false;
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  std::size_t best = 0;
  for (int it = 0; it < 500; ++it) {
    const Eigen::Vector3d a = points[pick(rng)], b = points[pick(rng)], c = points[pick(rng)];
    const Eigen::Vector3d m = (b - a).cross(c - a);
    if (m.norm() < 1e-9)
      continue;
    const Eigen::Vector3d normal = m.normalized();
    std::size_t inliers = 0;
    for (const auto& p : points)
      inliers += std::abs(normal.dot(p - a)) < 2 * sigma(p.z());
    if (inliers > best) {
      best = inliers;
      n = normal;
      d = normal.dot(a);
    }
  }
  for (int round = 0; round < 2; ++round) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector3d> in;
    for (const auto& p : points)
      if (std::abs(n.dot(p) - d) < 2 * sigma(p.z()))
        in.push_back(p);
    for (const auto& p : in)
      mean += p;
    mean /= static_cast<double>(in.size());
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (const auto& p : in)
      C += (p - mean) * (p - mean).transpose();
    n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).eigenvectors().col(0);
    d = n.dot(mean);
  }
  return best > points.size() / 2;
}

// The surface's pixels: within 3 sigma of the plane, up to max_depth, 8-connected to the seed.
cv::Mat surfaceMask(const pcl::PointCloud<pcl::PointXYZ>& cloud, const Surface& s,
                    const Eigen::Vector3d& n, double d) {
  cv::Mat inlier(480, 640, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) {
      const pcl::PointXYZ& p = cloud(u, v);
      if (std::isfinite(p.z) && p.z > 0 && p.z <= s.max_depth &&
          std::abs(n.dot(Eigen::Vector3d(p.x, p.y, p.z)) - d) < 3 * sigma(p.z))
        inlier.at<std::uint8_t>(v, u) = 1;
    }
  cv::Mat components;
  cv::connectedComponents(inlier, components, 8, CV_32S);
  std::map<int, int> seed_votes;
  for (int v = s.seed.v0; v < s.seed.v1; ++v)
    for (int u = s.seed.u0; u < s.seed.u1; ++u)
      if (inlier.at<std::uint8_t>(v, u))
        ++seed_votes[components.at<int>(v, u)];
  int seed_component = 0, votes = 0;
  for (const auto& [c, count] : seed_votes)
    if (count > votes) {
      seed_component = c;
      votes = count;
    }
  return components == seed_component & inlier;
}

void expectOneSegmentPerSurface(const Case& c, double min_coverage) {
  const cv::Mat depth =
      qs::readTumDepthPng(qs::test::shippedData(c.file).string(), c.units_per_metre);
  const pcl::PointCloud<pcl::PointXYZ> cloud =
      qs::backProject(qs::depthViewOf(depth), c.k, qs::BackProjectionParams());
  const qs::QuadricSegmenter segmenter{qs::QuadricSegmenter::Params()};
  const qs::Segmentation result =
      segmenter.segment(qs::NormalEstimator(qs::NormalEstimator::Params()).compute(cloud));
  for (const Surface& s : c.surfaces) {
    Eigen::Vector3d n;
    double d = 0;
    ASSERT_TRUE(robustPlane(cloud, s.seed, n, d)) << c.file << " " << s.name << ": no plane";
    const cv::Mat mask = surfaceMask(cloud, s, n, d);
    const int pixels = cv::countNonZero(mask);
    std::map<int, int> per_label;
    for (int v = 0; v < 480; ++v)
      for (int u = 0; u < 640; ++u)
        if (mask.at<std::uint8_t>(v, u))
          ++per_label[result.labels.at<std::uint16_t>(v, u)];
    int best = 0, best_label = 0;
    for (const auto& [label, count] : per_label)
      if (label != 0 && count > best &&
          result.detections[label - 1].shape.quadric_class == qs::QuadricClass::kPlane) {
        best = count;
        best_label = label;
      }
    const double coverage = pixels > 0 ? static_cast<double>(best) / pixels : 0.0;
    std::printf("%s %s: %d pixels, plane (%.3f %.3f %.3f) d %.3f; best segment %d covers %.1f%%\n",
                c.file.c_str(), s.name.c_str(), pixels, n.x(), n.y(), n.z(), d, best_label,
                100 * coverage);
    EXPECT_GT(pixels, 3000) << s.name << ": the surface is large";
    EXPECT_GE(coverage, min_coverage) << c.file << " " << s.name << " is not one segment";
  }
}

const qs::CameraIntrinsics kFr3 = intrinsics(535.4, 539.2, 320.1, 247.6);
const qs::CameraIntrinsics kFr2 = intrinsics(520.9, 521.0, 325.1, 249.7);

// Seeds (pixel rectangles), in both fr3 frames: the floor right of the swivel chair at the bottom
// right; the partition's bare board above the bottles on the right of the desk; the desk top's
// free left end, left of the dice.
const std::vector<Surface> kFr3Surfaces = {{"floor", {540, 440, 630, 476}},
                                           {"partition", {380, 25, 450, 80}},
                                           {"desk top", {70, 222, 120, 242}}};

}  // namespace

TEST(QuadricSegmenterSurfaces, Fr3FloorPartitionAndDeskTopAreOneSegmentEach) {
  for (const char* file : {"tum_frames/fr3_long_office_household/1341847980.723020.png",
                           "tum_frames/fr3_long_office_household/1341847982.998830.png"})
    expectOneSegmentPerSurface({file, kFr3, 5000.0, kFr3Surfaces}, 0.8);
}

// fr2_desk `a`: the desk top (seed: the free surface in front of the keyboard) and the floor
// behind the desk on the right, out to 4 m (seed: floor right of the monitor at 3.5-4 m).
TEST(QuadricSegmenterSurfaces, Fr2DeskTopAndFloorOutTo4mAreOneSegmentEach) {
  expectOneSegmentPerSurface(
      {"tum_frames/fr2_desk/a_depth.png",
       kFr2,
       5208.0,
       {{"desk top", {100, 370, 330, 410}}, {"floor to 4 m", {490, 150, 600, 195}, 4.0}}},
      0.8);
}
