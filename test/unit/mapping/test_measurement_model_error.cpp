// MeasurementModelError: a fragment of one surface seen near the image corner, where a
// structured-light camera bends flat surfaces (sim/kinect_depth_model.h, harsh preset: radial
// disparity distortion, fixed pattern, correlated noise), is the same surface as the rest of it for
// the landmark merger once the model error is in its covariance, and is not without it (its fit
// claims a fraction of a degree over thousands of pixels); two distinct planes 5 degrees apart
// that touch stay two. Also: the term's size (n_eff cells, depth squared), its limits and the
// parameter checks.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "quadric_slam/frontend/shape_refiner.h"
#include "quadric_slam/mapping/landmark_merger.h"
#include "quadric_slam/mapping/measurement_model_error.h"
#include "quadric_slam/sim/kinect_depth_model.h"

namespace quadric_slam {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kFocal = 585.0, kCx = 319.5, kCy = 239.5;

Eigen::Vector3d rayOf(int u, int v) {
  return {(u - kCx) / kFocal, (v - kCy) / kFocal, 1.0};
}

// A plane n.p = offset (camera frame, n towards the camera) seen over a block of pixels.
struct PlanePatch {
  Eigen::Vector3d normal;
  double offset;
  cv::Rect pixels;
};

// The depth image of the patches through the harsh Kinect model (one fixed seed).
cv::Mat measuredDepth(const std::vector<PlanePatch>& patches) {
  cv::Mat depth(kHeight, kWidth, CV_32FC1, cv::Scalar(std::nanf(""))),
      cosine(kHeight, kWidth, CV_32FC1, cv::Scalar(1.0f));
  for (const PlanePatch& patch : patches)
    for (int v = patch.pixels.y; v < patch.pixels.y + patch.pixels.height; ++v)
      for (int u = patch.pixels.x; u < patch.pixels.x + patch.pixels.width; ++u) {
        const Eigen::Vector3d d = rayOf(u, v);
        depth.at<float>(v, u) = static_cast<float>(patch.offset / patch.normal.dot(d));
        cosine.at<float>(v, u) = static_cast<float>(std::abs(patch.normal.dot(d.normalized())));
      }
  return KinectDepthModel(KinectDepthModel::harshParams()).apply(depth, cosine, 11);
}

// The segmenter's measurement of the pixels of `block` in `depth`: the refined plane, its fit
// covariance sigma^2 (J^T J)^-1, RMS, support size and extent box (frontend/quadric_segmenter.cpp).
QuadricMeasurement measure(const cv::Mat& depth, const cv::Rect& block) {
  std::vector<Eigen::Vector3d> points;
  for (int v = block.y; v < block.y + block.height; ++v)
    for (int u = block.x; u < block.x + block.width; ++u) {
      const float z = depth.at<float>(v, u);
      if (std::isfinite(z))
        points.push_back(z * rayOf(u, v));
    }
  const ShapeRefiner::Result fit = ShapeRefiner().refine(fitPlane(points), points);
  EXPECT_TRUE(fit.ok);
  QuadricMeasurement m;
  m.quadric_camera = fit.shape.quadric();
  m.covariance = fit.covariance;
  m.num_points = static_cast<int>(points.size());
  m.fit_rms = rmsDistance(fit.shape, points);
  m.extent_min = Eigen::Vector3d::Constant(1e9);
  m.extent_max = -m.extent_min;
  const Eigen::Isometry3d T_quadric_camera = m.quadric_camera.pose().inverse();
  for (const Eigen::Vector3d& p : points) {
    m.extent_min = m.extent_min.cwiseMin(T_quadric_camera * p);
    m.extent_max = m.extent_max.cwiseMax(T_quadric_camera * p);
  }
  return m;
}

// A landmark made of `observations` identical measurements (a camera that holds still sees the
// same systematic error every frame, so fusing them divides the covariance, not the error).
QuadricLandmark landmarkOf(int id, const QuadricMeasurement& m, int observations) {
  QuadricLandmark l;
  l.id = id;
  l.quadric_map = m.quadric_camera;
  l.covariance = m.covariance / observations;
  l.extent_min = m.extent_min;
  l.extent_max = m.extent_max;
  l.observations = observations;
  return l;
}

// The calibrated model error (config/mapping.yaml; the term is off by default).
MeasurementModelError::Params calibrated() {
  MeasurementModelError::Params p;
  p.sigma = 0.002;
  return p;
}

QuadricMeasurement withModelError(QuadricMeasurement m) {
  MeasurementModelError::add(m, calibrated());
  return m;
}

double angleBetweenNormals(const QuadricMeasurement& a, const QuadricMeasurement& b) {
  const Eigen::Vector3d na = a.quadric_camera.pose().linear().col(0),
                        nb = b.quadric_camera.pose().linear().col(0);
  return std::acos(std::min(1.0, std::abs(na.dot(nb))));
}

// A wall facing the camera at 2.5 m: its large central part, seen many times, and a small
// fragment in the image corner beside it, seen in 5 frames (the fragment a segmenter splits off
// where the wall meets an occluder or the image border).
struct WallAndCorner {
  QuadricMeasurement wall, corner;
};

WallAndCorner wallAndCorner() {
  const PlanePatch wall{-Eigen::Vector3d::UnitZ(), -2.5, cv::Rect(0, 0, kWidth, kHeight)};
  const cv::Mat depth = measuredDepth({wall});
  return {measure(depth, cv::Rect(80, 80, 400, 320)), measure(depth, cv::Rect(0, 0, 80, 80))};
}

TEST(MeasurementModelError, CornerFragmentOfABentWallMergesWithTheWall) {
  const WallAndCorner raw = wallAndCorner();
  // The corner is bent: its normal is off by more than its fit claims.
  const double angle = angleBetweenNormals(raw.wall, raw.corner);
  EXPECT_GT(angle, 0.01) << "the harsh model should tilt the corner fragment";
  const LandmarkMerger merger;
  const LandmarkMerger::Comparison without =
      merger.compare(landmarkOf(1, raw.wall, 600), landmarkOf(2, raw.corner, 5));
  EXPECT_TRUE(without.extents_touch);
  EXPECT_FALSE(without.within_gate) << "fit covariance only: d2 " << without.squared_distance;
  const LandmarkMerger::Comparison with = merger.compare(
      landmarkOf(1, withModelError(raw.wall), 600), landmarkOf(2, withModelError(raw.corner), 5));
  std::printf(
      "[ info     ] corner fragment %.2f deg off the wall: d2 %.1f without, %.1f with the "
      "model error (gate %.1f)\n",
      angle * 180 / M_PI, without.squared_distance, with.squared_distance,
      merger.gate(QuadricClass::kPlane));
  EXPECT_TRUE(with.sameSurface()) << "d2 " << with.squared_distance << " gate "
                                  << merger.gate(QuadricClass::kPlane) << ", normals "
                                  << angle * 180 / M_PI << " deg apart";
}

TEST(MeasurementModelError, TwoPlanesFiveDegreesApartThatTouchStayTwo) {
  // A wall and, beside it, a panel hinged on the wall along the image column u = 320 and turned
  // 5 degrees about the vertical: one continuous surface with a crease.
  const double z = 2.0, tilt = 5.0 * M_PI / 180.0;
  const Eigen::Vector3d hinge = z * rayOf(320, 240);
  const Eigen::Vector3d n_panel(std::sin(tilt), 0.0, -std::cos(tilt));
  const PlanePatch wall{-Eigen::Vector3d::UnitZ(), -z, cv::Rect(0, 0, 320, kHeight)};
  const PlanePatch panel{n_panel, n_panel.dot(hinge), cv::Rect(320, 0, 320, kHeight)};
  const cv::Mat depth = measuredDepth({wall, panel});
  const QuadricMeasurement a = withModelError(measure(depth, cv::Rect(40, 40, 280, 400)));
  const QuadricMeasurement b = withModelError(measure(depth, cv::Rect(320, 40, 280, 400)));
  const LandmarkMerger merger;
  const LandmarkMerger::Comparison c = merger.compare(landmarkOf(1, a, 20), landmarkOf(2, b, 20));
  std::printf("[ info     ] planes 5 deg apart: d2 %.1f with the model error (gate %.1f)\n",
              c.squared_distance, merger.gate(QuadricClass::kPlane));
  EXPECT_TRUE(c.extents_touch);
  EXPECT_FALSE(c.within_gate) << "d2 " << c.squared_distance;
}

TEST(MeasurementModelError, SizeFollowsDepthSquaredAndIndependentCells) {
  const WallAndCorner raw = wallAndCorner();
  MeasurementModelError::Params p = calibrated();
  const Eigen::MatrixXd C = MeasurementModelError::covariance(raw.wall, p);
  ASSERT_EQ(C.rows(), 3);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(C).eigenvalues().minCoeff(), 0.0);
  // The support's depth, and its cells: the two largest sides of its extent box (whose in-plane
  // axes are the plane frame's, not the image's: between the block's area and twice it) over
  // the cell (correlation_angle z)^2.
  const double z = MeasurementModelError::supportDepth(raw.wall);
  EXPECT_NEAR(z, 2.5, 0.05);
  const double cells = MeasurementModelError::independentCells(raw.wall, p);
  const double cell = p.correlation_angle * z;
  const double block_cells = (400 * z / kFocal) * (320 * z / kFocal) / (cell * cell);
  EXPECT_GE(cells, 0.95 * block_cells);
  EXPECT_LE(cells, 2.05 * block_cells);
  // Twice the sigma: four times the covariance; twice the correlation angle: a quarter of the
  // cells (while above one).
  MeasurementModelError::Params twice = p;
  twice.sigma = 2 * p.sigma;
  EXPECT_TRUE(MeasurementModelError::covariance(raw.wall, twice).isApprox(4 * C, 1e-9));
  twice = p;
  twice.correlation_angle = 0.5 * p.correlation_angle;
  EXPECT_NEAR(MeasurementModelError::independentCells(raw.wall, twice), 4 * cells, 1e-6 * cells);
  // The corner fragment covers fewer cells than the wall (never fewer than one), so its term is
  // larger relative to its fit covariance.
  EXPECT_GE(MeasurementModelError::independentCells(raw.corner, p), 1.0);
  EXPECT_LT(MeasurementModelError::independentCells(raw.corner, p), cells);
}

TEST(MeasurementModelError, LeavesWhatItCannotScaleAlone) {
  const WallAndCorner raw = wallAndCorner();
  MeasurementModelError::Params off;
  off.sigma = 0.0;
  EXPECT_EQ(MeasurementModelError::covariance(raw.wall, off).norm(), 0.0);
  QuadricMeasurement no_rms = raw.wall;
  no_rms.fit_rms = 0.0;  // no residual: the geometry cannot be recovered from the fit
  EXPECT_EQ(MeasurementModelError::covariance(no_rms, calibrated()).norm(), 0.0);
  QuadricMeasurement m = raw.wall;
  MeasurementModelError::add(m, calibrated());
  EXPECT_TRUE(
      m.covariance.isApprox(raw.wall.covariance +
                            MeasurementModelError::covariance(raw.wall, calibrated())));
}

TEST(MeasurementModelError, ParamsValidate) {
  EXPECT_NO_THROW(MeasurementModelError::Params{}.validate());
  auto message = [](const MeasurementModelError::Params& p) {
    try {
      p.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  MeasurementModelError::Params p = calibrated();
  p.sigma = -0.001;
  EXPECT_NE(message(p).find("sigma"), std::string::npos);
  p.sigma = 0.2;
  EXPECT_NE(message(p).find("[0, 0.1]"), std::string::npos);
  p = {};
  p.correlation_angle = 0.0;
  EXPECT_NE(message(p).find("correlation_angle"), std::string::npos);
  p.correlation_angle = 2.0;
  EXPECT_NE(message(p).find("(0, 1.5]"), std::string::npos);
}

}  // namespace
}  // namespace quadric_slam
