// QuadricSegmenter on rendered frames with known truth (two planes, a sphere, a cylinder and a
// cone with Kinect-like depth noise, normals from the project's NormalEstimator): classes found,
// parameter errors within the tolerances of the task, no spurious segments; edge cases (empty,
// all-NaN, tiny, unorganized clouds) and parameter validation.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <limits>
#include <map>

#include "../kinect_vga.h"
#include "primitive_desk_scene.h"
#include "quadric_slam/frontend/multi_resolution_labels.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/sim/primitive_scene_renderer.h"

namespace qs = quadric_slam;
using qs::PrimitiveShape;
using qs::QuadricClass;

namespace {

constexpr double kDeg = M_PI / 180.0;

pcl::PointCloud<pcl::PointNormal> cloudWithNormals(const cv::Mat& depth) {
  const qs::DepthImageView<float> view = qs::depthViewOf(depth);
  const pcl::PointCloud<pcl::PointXYZ> cloud =
      qs::backProject(view, qs::test::kinectVga(), qs::BackProjectionParams());
  return qs::NormalEstimator(qs::NormalEstimator::Params()).compute(cloud);
}

double angleBetweenLines(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

double lineDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& d, const Eigen::Vector3d& q) {
  const Eigen::Vector3d v = q - p;
  return (v - d.normalized().dot(v) * d.normalized()).norm();
}

double iou(const cv::Mat& labels, std::uint16_t label, const cv::Mat& truth, std::uint16_t t) {
  int both = 0, either = 0;
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const bool a = labels.at<std::uint16_t>(y, x) == label;
      const bool b = truth.at<std::uint16_t>(y, x) == t;
      both += a && b;
      either += a || b;
    }
  return either ? static_cast<double>(both) / either : 0.0;
}

void checkScene(const Eigen::Isometry3d& T_camera_scene, unsigned seed,
                const qs::QuadricSegmenter::Params& params = qs::QuadricSegmenter::Params()) {
  const std::vector<qs::ScenePrimitive> scene = qs::test::primitiveDeskScene(T_camera_scene);
  qs::RenderParams render;
  render.seed = seed;
  const qs::PrimitiveRendering frame = qs::renderPrimitives(scene, qs::test::kinectVga(), render);
  const qs::QuadricSegmenter segmenter{params};
  const qs::Segmentation result = segmenter.segment(cloudWithNormals(frame.depth));
  // QS_DEBUG_DIR=dir writes the truth and the segmentation as pictures, and lists detections.
  if (const char* dir = std::getenv("QS_DEBUG_DIR")) {
    const std::string prefix = std::string(dir) + "/synthetic_" + std::to_string(seed);
    cv::imwrite(prefix + "_truth.png", qs::colouriseLabels(frame.truth));
    cv::imwrite(prefix + "_segmentation.png", qs::colouriseLabels(result.labels));
    for (const auto& d : result.detections) {
      std::printf("label %u %s points %d rms %.4f:", d.label,
                  qs::toString(d.shape.quadric_class).c_str(), d.num_points, d.fit_rms);
      for (double v : d.shape.shapeVector())
        std::printf(" %.4f", v);
      std::printf("\n");
    }
  }
  ASSERT_EQ(result.labels.rows, 480);
  ASSERT_EQ(result.labels.cols, 640);

  std::vector<bool> matched_detection(result.detections.size(), false);
  for (std::size_t t = 0; t < scene.size(); ++t) {
    const PrimitiveShape& truth = scene[t].shape;
    const std::string name = qs::toString(truth.quadric_class);
    // The detection overlapping this primitive's pixels best.
    int best = -1;
    double best_iou = 0;
    for (std::size_t i = 0; i < result.detections.size(); ++i) {
      const double o = iou(result.labels, result.detections[i].label, frame.truth,
                           static_cast<std::uint16_t>(t + 1));
      if (o > best_iou) {
        best_iou = o;
        best = static_cast<int>(i);
      }
    }
    ASSERT_GE(best, 0) << name << " not segmented";
    matched_detection[best] = true;
    const qs::QuadricDetection& d = result.detections[best];
    EXPECT_GT(best_iou, 0.6) << name;
    ASSERT_EQ(d.shape.quadric_class, truth.quadric_class)
        << name << " found as " << qs::toString(d.shape.quadric_class);
    EXPECT_EQ(d.covariance.rows(), qs::minimalDimension(truth.quadric_class));
    EXPECT_GT(d.num_points, 0);
    // About the rendered noise (1.5e-3 z^2: 9.4 mm at the wall's 2.5 m).
    EXPECT_LT(d.fit_rms, 0.015);
    const PrimitiveShape& s = d.shape;
    switch (truth.quadric_class) {
      case QuadricClass::kPlane: {
        EXPECT_LE(angleBetweenLines(s.direction, truth.direction), 1.0 * kDeg);
        const double sign = s.direction.dot(truth.direction) > 0 ? 1.0 : -1.0;
        EXPECT_NEAR(sign * s.planeOffset(), truth.planeOffset(), 0.01);
        break;
      }
      case QuadricClass::kSphere:
        EXPECT_LE((s.point - truth.point).norm(), 0.01);
        EXPECT_NEAR(s.size, truth.size, 0.005);
        break;
      case QuadricClass::kCylinder:
        EXPECT_LE(angleBetweenLines(s.direction, truth.direction), 2.0 * kDeg);
        EXPECT_NEAR(s.size, truth.size, 0.005);
        EXPECT_LE(lineDistance(truth.point, truth.direction, s.point), 0.01);
        break;
      default:
        EXPECT_LE(angleBetweenLines(s.direction, truth.direction), 3.0 * kDeg);
        EXPECT_GT(s.direction.dot(truth.direction), 0) << "cone axis points into the opening";
        EXPECT_NEAR(s.size, truth.size, 2.0 * kDeg);
        EXPECT_LE((s.point - truth.point).norm(), 0.03);
    }
  }
  for (std::size_t i = 0; i < result.detections.size(); ++i)
    EXPECT_TRUE(matched_detection[i])
        << "spurious " << qs::toString(result.detections[i].shape.quadric_class) << " with "
        << result.detections[i].num_points << " points";
}

}  // namespace

TEST(QuadricSegmenter, FindsPlanesSphereCylinderAndConeWithSmallErrors) {
  checkScene(Eigen::Isometry3d::Identity(), 7);
}

TEST(QuadricSegmenter, FindsThemInATiltedView) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.08, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.05, -0.1, 0.1);
  checkScene(T, 19);
}

// The curved stages on a grid decimated once more (curved_decimation): the same surfaces, classes
// and accuracy.
TEST(QuadricSegmenter, FindsThemWithCurvedShapesOnACoarserGrid) {
  qs::QuadricSegmenter::Params params;
  params.curved_decimation = 2;
  checkScene(Eigen::Isometry3d::Identity(), 7, params);
}

namespace {

void checkLabelsConsistent(const qs::QuadricSegmenter::Params& params) {
  const qs::PrimitiveRendering frame =
      qs::renderPrimitives(qs::test::primitiveDeskScene(Eigen::Isometry3d::Identity()),
                           qs::test::kinectVga(), qs::RenderParams());
  const qs::Segmentation result =
      qs::QuadricSegmenter(params).segment(cloudWithNormals(frame.depth));
  ASSERT_FALSE(result.detections.empty());
  std::map<int, int> counts;
  for (int y = 0; y < result.labels.rows; ++y)
    for (int x = 0; x < result.labels.cols; ++x)
      ++counts[result.labels.at<std::uint16_t>(y, x)];
  for (std::size_t i = 0; i < result.detections.size(); ++i) {
    const qs::QuadricDetection& d = result.detections[i];
    EXPECT_EQ(d.label, i + 1);
    EXPECT_EQ(counts[d.label], d.num_points);
    // Every labelled pixel lies inside the detection's ROI.
    for (int y = 0; y < result.labels.rows; ++y)
      for (int x = 0; x < result.labels.cols; ++x)
        if (result.labels.at<std::uint16_t>(y, x) == d.label) {
          ASSERT_GE(x, d.roi.x_offset);
          ASSERT_LT(x, d.roi.x_offset + d.roi.width);
          ASSERT_GE(y, d.roi.y_offset);
          ASSERT_LT(y, d.roi.y_offset + d.roi.height);
        }
    EXPECT_TRUE((d.extent_max.array() >= d.extent_min.array()).all());
  }
}

}  // namespace

TEST(QuadricSegmenter, LabelsAreConsistentWithDetections) {
  checkLabelsConsistent(qs::QuadricSegmenter::Params());
}

// Curved segments labelled from the coarser grid and planes from the finer one share one label
// image and numbering.
TEST(QuadricSegmenter, LabelsAreConsistentWithCurvedShapesOnACoarserGrid) {
  qs::QuadricSegmenter::Params params;
  params.curved_decimation = 2;
  checkLabelsConsistent(params);
}

TEST(QuadricSegmenter, EmptyAllNanAndTinyCloudsGiveNoDetections) {
  const qs::QuadricSegmenter segmenter{qs::QuadricSegmenter::Params()};
  EXPECT_TRUE(segmenter.segment(pcl::PointCloud<pcl::PointNormal>()).detections.empty());
  pcl::PointCloud<pcl::PointNormal> nan_cloud(640, 480);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (auto& p : nan_cloud.points)
    p.x = p.y = p.z = p.normal_x = p.normal_y = p.normal_z = nan;
  const qs::Segmentation r = segmenter.segment(nan_cloud);
  EXPECT_TRUE(r.detections.empty());
  EXPECT_EQ(cv::countNonZero(r.labels), 0);
  pcl::PointCloud<pcl::PointNormal> tiny(4, 3);
  for (auto& p : tiny.points) {
    p.x = p.y = 0;
    p.z = 1;
    p.normal_x = p.normal_y = 0;
    p.normal_z = -1;
  }
  EXPECT_TRUE(segmenter.segment(tiny).detections.empty());
  pcl::PointCloud<pcl::PointNormal> unorganized;
  unorganized.push_back(tiny.points[0]);
  unorganized.push_back(tiny.points[1]);
  EXPECT_THROW(segmenter.segment(unorganized), std::invalid_argument);
}

TEST(QuadricSegmenter, ParamsValidateNamesTheBadField) {
  auto expectNamed = [](qs::QuadricSegmenter::Params p, const std::string& field) {
    try {
      p.validate();
      ADD_FAILURE() << field << ": no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  qs::QuadricSegmenter::Params p;
  EXPECT_NO_THROW(p.validate());
  p.cgal_stride = 0;
  expectNamed(p, "cgal_stride");
  p = qs::QuadricSegmenter::Params();
  p.max_range = 0.1;
  expectNamed(p, "max_range");
  p = qs::QuadricSegmenter::Params();
  p.planes.min_points = 1;
  expectNamed(p, "min_points");
  p = qs::QuadricSegmenter::Params();
  p.curved_max_normal_angle = 2.0;
  expectNamed(p, "curved_max_normal_angle");
  p = qs::QuadricSegmenter::Params();
  p.curved_decimation = 0;
  expectNamed(p, "curved_decimation");
  p = qs::QuadricSegmenter::Params();
  p.planes.correlated_points = 0.5;
  expectNamed(p, "correlated_points");
}

// The plane statistics' correlated points are points of the grid: a grid decimated by d holds
// 1 / d^2 of them (at least one), so a surface's noise does not change with the grid.
TEST(QuadricSegmenter, CoarseGridParamsScaleTheCorrelatedDepthPoints) {
  qs::QuadricSegmenter::Params p;
  ASSERT_DOUBLE_EQ(p.planes.correlated_points, 64.0);
  EXPECT_DOUBLE_EQ(qs::coarseParams(p, 2).planes.correlated_points, 16.0);
  EXPECT_DOUBLE_EQ(qs::coarseParams(p, 4).planes.correlated_points, 4.0);
  EXPECT_DOUBLE_EQ(qs::coarseParams(p, 8).planes.correlated_points, 1.0);
  EXPECT_EQ(qs::coarseParams(p, 4).min_curved_points, p.min_curved_points / 16);
}
