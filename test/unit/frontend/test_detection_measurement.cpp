// toMeasurement / toFrameMeasurements: a segmenter detection as a core QuadricMeasurement. Checked
// against truth: the measurement's quadric is the detected surface (its supporting points satisfy
// the quadric equation of eq. 5), the extent box is the tight box of those points in the quadric's
// frame, and the covariance is the Table II minimal covariance of a body-frame perturbation of that
// quadric (Monte Carlo over noisy fits; and for the segmenter's re-centred cylinder, equal to the
// covariance evaluated afresh in the final frame).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../kinect_vga.h"
#include "primitive_desk_scene.h"
#include "quadric_slam/frontend/detection_measurement.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/shape_refiner.h"
#include "quadric_slam/geometry/symmetry.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/sim/primitive_scene_renderer.h"

namespace qs = quadric_slam;
using qs::PrimitiveShape;
using qs::QuadricClass;

namespace {

pcl::PointCloud<pcl::PointNormal> cloudWithNormals(const cv::Mat& depth) {
  const qs::DepthImageView<float> view = qs::depthViewOf(depth);
  const pcl::PointCloud<pcl::PointXYZ> cloud =
      qs::backProject(view, qs::test::kinectVga(), qs::BackProjectionParams());
  return qs::NormalEstimator(qs::NormalEstimator::Params()).compute(cloud);
}

// (S p_Q)^T D(sigma) (S p_Q) + sigma_4 (eq. 5) of a point in the quadric's frame.
double quadricValue(const qs::QuadricModel& q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d sp = q.scale().asDiagonal() * (q.pose().inverse() * p);
  const Eigen::Vector4d s = q.signature();
  return s[0] * sp[0] * sp[0] + s[1] * sp[1] * sp[1] + s[2] * sp[2] * sp[2] + s[3];
}

}  // namespace

TEST(DetectionMeasurement, SegmenterDetectionsBecomeCoreQuadricsWithTheirExtentBoxes) {
  const qs::PrimitiveRendering frame = qs::renderPrimitives(
      qs::test::primitiveDeskScene(), qs::test::kinectVga(), qs::RenderParams());
  const pcl::PointCloud<pcl::PointNormal> cloud = cloudWithNormals(frame.depth);
  const qs::Segmentation seg = qs::QuadricSegmenter(qs::QuadricSegmenter::Params()).segment(cloud);
  ASSERT_GE(seg.detections.size(), 5u);
  const qs::FrameMeasurements fm = qs::toFrameMeasurements(seg, 12.5, "camera");
  EXPECT_DOUBLE_EQ(fm.stamp, 12.5);
  EXPECT_EQ(fm.frame_id, "camera");
  ASSERT_EQ(fm.observations.size(), seg.detections.size());
  for (std::size_t i = 0; i < seg.detections.size(); ++i) {
    const qs::QuadricDetection& d = seg.detections[i];
    const qs::QuadricMeasurement& m = fm.observations[i];
    const QuadricClass c = d.shape.quadric_class;
    const std::string name = qs::toString(c);
    EXPECT_EQ(m.quadric_camera.quadricClass(), c);
    EXPECT_EQ(m.label, d.label);
    EXPECT_EQ(m.num_points, d.num_points);
    EXPECT_DOUBLE_EQ(m.fit_rms, d.fit_rms);
    EXPECT_EQ(m.image_roi.x_offset, d.roi.x_offset);
    EXPECT_EQ(m.image_roi.width, d.roi.width);
    const int k = qs::minimalDimension(c);
    ASSERT_EQ(m.covariance.rows(), k) << name;
    ASSERT_EQ(m.covariance.cols(), k) << name;
    EXPECT_LT((m.covariance - m.covariance.transpose()).norm(), 1e-12 * m.covariance.norm());
    // The supporting points: on the measured quadric (geometric distance of the same surface
    // within a few RMS) and inside the extent box, which is tight (each face touched).
    const PrimitiveShape surface = PrimitiveShape::fromQuadric(m.quadric_camera);
    const Eigen::Isometry3d T_quadric_camera = m.quadric_camera.pose().inverse();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    double sum2 = 0;
    int n = 0, n_fit = 0;
    for (int v = 0; v < seg.labels.rows; ++v)
      for (int u = 0; u < seg.labels.cols; ++u) {
        if (seg.labels.at<std::uint16_t>(v, u) != d.label)
          continue;
        const auto& pt = cloud.at(u, v);
        const Eigen::Vector3d p(pt.x, pt.y, pt.z);
        const double dist = surface.distance(p);
        ++n;
        // fit_rms is over the fit's support, the points with normals (boundary points join the
        // labels afterwards: frontend/boundary_labels.h).
        if (std::isfinite(pt.normal_x)) {
          sum2 += dist * dist;
          ++n_fit;
        }
        const Eigen::Vector3d local = T_quadric_camera * p;
        lo = lo.cwiseMin(local);
        hi = hi.cwiseMax(local);
      }
    ASSERT_EQ(n, d.num_points) << name;
    // fit_rms is measured on the decimated grid the fit ran on: close to the full-grid RMS.
    EXPECT_NEAR(std::sqrt(sum2 / n_fit), d.fit_rms, 0.05 * d.fit_rms) << name;
    EXPECT_LT(d.fit_rms, 0.01) << name;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(m.extent_min[a], lo[a], 1e-6) << name << " axis " << a;
      EXPECT_NEAR(m.extent_max[a], hi[a], 1e-6) << name << " axis " << a;
    }
    // The quadric equation vanishes on the surface: probe the foot points along the normal.
    const Eigen::Vector3d centre_local = 0.5 * (lo + hi);
    const Eigen::Vector3d probe = m.quadric_camera.pose() * centre_local;
    const Eigen::Vector3d foot = probe - surface.distance(probe) * surface.normalAt(probe);
    EXPECT_NEAR(surface.distance(foot), 0.0, 1e-3) << name;
    EXPECT_NEAR(quadricValue(m.quadric_camera, foot), 0.0, 0.05) << name;
    if (c == QuadricClass::kPlane) {
      // A plane's points lie in the quadric frame's x = 0 plane: the box is thin in x (a few
      // noise RMS either side) and wide in y and z.
      EXPECT_LT(std::max(hi.x(), -lo.x()), 6 * d.fit_rms) << name;
      EXPECT_GT(std::min(hi.y() - lo.y(), hi.z() - lo.z()), 0.3) << name;
    }
    if (c == QuadricClass::kCylinder) {
      // The segmenter re-centres the axis point on the support: the covariance must be the one
      // of a perturbation in the final frame, i.e. equal to a fresh evaluation there.
      std::vector<Eigen::Vector3d> points;
      for (int v = 0; v < seg.labels.rows; ++v)
        for (int u = 0; u < seg.labels.cols; ++u)
          if (seg.labels.at<std::uint16_t>(v, u) == d.label &&
              std::isfinite(cloud.at(u, v).normal_x)) {
            // The fit's support: boundary points without normals join the labels afterwards
            // (frontend/boundary_labels.h) and leave the covariance as it is.
            const auto& pt = cloud.at(u, v);
            points.emplace_back(pt.x, pt.y, pt.z);
          }
      EXPECT_LT(std::abs(0.5 * (lo.z() + hi.z())), 0.02) << "axis point centred on the support";
      const qs::ShapeRefiner::Result fresh = qs::ShapeRefiner().evaluate(d.shape, points);
      ASSERT_TRUE(fresh.ok);
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
          const double scale = std::sqrt(fresh.covariance(a, a) * fresh.covariance(b, b));
          EXPECT_NEAR(m.covariance(a, b), fresh.covariance(a, b), 0.5 * scale)
              << "cylinder covariance entry " << a << ", " << b;
        }
    }
  }
}

TEST(DetectionMeasurement, CovarianceIsTheBodyFramePerturbationOfTheMeasuredQuadric) {
  // Noisy samples of a cylinder patch; each fit's error with respect to the truth, in the fit's
  // Table II minimal space (geometry/symmetry.h surfaceMinus), has the predicted covariance.
  const PrimitiveShape truth =
      PrimitiveShape::cylinder(Eigen::Vector3d(0.1, 0.2, 1.5), Eigen::Vector3d(0.2, -1, 0.1), 0.1);
  const qs::QuadricModel truth_q = truth.quadric();
  const Eigen::Isometry3d T = truth_q.pose();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 0.003);
  const qs::ShapeRefiner refiner;
  constexpr int kTrials = 200;
  const int k = 5;
  Eigen::MatrixXd empirical = Eigen::MatrixXd::Zero(k, k), predicted = empirical;
  for (int t = 0; t < kTrials; ++t) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 300; ++i) {
      const double a = 1.2 * uni(rng), h = 0.15 + 0.1 * uni(rng);  // off-centre along the axis
      points.push_back(T * Eigen::Vector3d(0.1 * std::cos(a), 0.1 * std::sin(a), h) +
                       Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
    }
    const qs::ShapeRefiner::Result fit = refiner.refine(truth, points);
    ASSERT_TRUE(fit.ok);
    qs::QuadricDetection d;
    d.shape = fit.shape;
    d.covariance = fit.covariance;
    const qs::QuadricMeasurement m = qs::toMeasurement(d);
    const Eigen::VectorXd e = qs::surfaceMinus(m.quadric_camera, truth_q);
    empirical += e * e.transpose() / kTrials;
    predicted += m.covariance / kTrials;
  }
  for (int a = 0; a < k; ++a) {
    const double ratio = empirical(a, a) / predicted(a, a);
    EXPECT_GT(ratio, 0.7) << "minimal coordinate " << a;
    EXPECT_LT(ratio, 1.4) << "minimal coordinate " << a;
  }
  // The rho-phi coupling of the off-centre support (rho1 with phi2, rho2 with phi1) is predicted.
  for (auto [a, b] : {std::pair<int, int>{0, 3}, {1, 2}}) {
    const double corr_e = empirical(a, b) / std::sqrt(empirical(a, a) * empirical(b, b));
    const double corr_p = predicted(a, b) / std::sqrt(predicted(a, a) * predicted(b, b));
    EXPECT_GT(std::abs(corr_p), 0.3) << a << ", " << b;
    EXPECT_NEAR(corr_e, corr_p, 0.15) << a << ", " << b;
  }
}

TEST(DetectionMeasurement, RejectsACovarianceOfTheWrongSize) {
  qs::QuadricDetection d;
  d.shape = PrimitiveShape::sphere(Eigen::Vector3d(0, 0, 2), 0.2);
  d.covariance = Eigen::MatrixXd::Identity(3, 3);
  EXPECT_THROW(qs::toMeasurement(d), std::invalid_argument);
  d.covariance = Eigen::MatrixXd::Identity(4, 4);
  const qs::QuadricMeasurement m = qs::toMeasurement(d);
  EXPECT_NEAR(m.quadric_camera.scale().x(), 5.0, 1e-12);
  EXPECT_TRUE(m.quadric_camera.pose().translation().isApprox(Eigen::Vector3d(0, 0, 2)));
}
