// Map evaluation of ellipsoids (the general class with the ellipsoid signature): the errors do not
// depend on the order the estimate's frame gives its axes in (semi-axes compared sorted, the
// longest axes' directions compared as lines), they come out as constructed, an ellipsoid far off
// is not matched, and its range is the distance to its surface.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "quadric_slam/eval/map_metrics.h"

namespace quadric_slam {
namespace {

constexpr double kDeg = M_PI / 180.0;

MapFileQuadric ellipsoid(int id, const Eigen::Isometry3d& T, const Eigen::Vector3d& radii) {
  MapFileQuadric q;
  q.id = id;
  q.quadric_class = "ellipsoid";
  q.T_map_quadric = T;
  q.scale = radii.cwiseInverse();
  const Eigen::Vector3d c = T.translation();
  q.shape["center"] = {c.x(), c.y(), c.z()};
  q.shape["radii"] = {radii.x(), radii.y(), radii.z()};
  return q;
}

double errorNamed(const std::vector<ShapeError>& errors, const std::string& name) {
  for (const ShapeError& e : errors)
    if (e.name == name)
      return e.value;
  ADD_FAILURE() << "no error named " << name;
  return NAN;
}

TEST(MapMetricsEllipsoid, ErrorsAsConstructedWhateverTheAxisOrder) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.55, 0.8, 0.77);
  const Eigen::Vector3d radii(0.13, 0.08, 0.07);
  const MapFileQuadric truth = ellipsoid(1, T, radii);

  // The estimate: 2 cm off in y, its longest axis tilted 4 deg (about the truth's z), the middle
  // semi-axis 5 mm long, and its frame listing the axes as (z, x, y) of the truth's.
  Eigen::Isometry3d T_e = T;
  T_e.translation() += Eigen::Vector3d(0, 0.02, 0);
  T_e.linear() = T.linear() * Eigen::AngleAxisd(4 * kDeg, Eigen::Vector3d::UnitZ());
  Eigen::Matrix3d P;  // columns: new x = old z, new y = old x, new z = old y (det +1)
  P << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  T_e.linear() = T_e.linear() * P;
  const Eigen::Vector3d radii_e(0.07, 0.13, 0.085);  // along the new axes
  const MapFileQuadric estimate = ellipsoid(2, T_e, radii_e);

  const std::vector<ShapeError> errors = shapeErrors(truth, estimate);
  EXPECT_NEAR(errorNamed(errors, "center_m"), 0.02, 1e-12);
  EXPECT_NEAR(errorNamed(errors, "semi_axis_1_m"), 0.0, 1e-12);
  EXPECT_NEAR(errorNamed(errors, "semi_axis_2_m"), 0.005, 1e-12);
  EXPECT_NEAR(errorNamed(errors, "semi_axis_3_m"), 0.0, 1e-12);
  EXPECT_NEAR(errorNamed(errors, "axis_angle_deg"), 4.0, 1e-9);

  // Through the evaluator, with the estimate expressed in another frame.
  Eigen::Isometry3d T_truth_est = Eigen::Isometry3d::Identity();
  T_truth_est.linear() = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, 0.5, -1).normalized())
                             .toRotationMatrix();
  T_truth_est.translation() = Eigen::Vector3d(-3, 0.7, 1.9);
  MapFile truth_map, estimate_map;
  truth_map.quadrics = {truth};
  estimate_map.quadrics = {transformQuadric(estimate, T_truth_est.inverse()),
                           transformQuadric(ellipsoid(3, T_e * Eigen::Translation3d(0, 0, 1.0),
                                                      radii_e),
                                            T_truth_est.inverse())};  // 1 m off: unmatched
  const MapReport report = MapEvaluator().evaluate(truth_map, estimate_map, T_truth_est);
  ASSERT_EQ(report.truths.size(), 1u);
  ASSERT_TRUE(report.truths[0].matched);
  EXPECT_EQ(report.truths[0].estimate_id, 2);
  EXPECT_NEAR(errorNamed(report.truths[0].errors, "center_m"), 0.02, 1e-9);
  EXPECT_NEAR(errorNamed(report.truths[0].errors, "axis_angle_deg"), 4.0, 1e-6);
  EXPECT_EQ(report.unmatched_estimates, 1);
  EXPECT_EQ(report.skipped_truths + report.skipped_estimates, 0);
  EXPECT_NE(formatMapReport(report).find("class ellipsoid truths 1 matched 1"), std::string::npos)
      << formatMapReport(report);
}

TEST(MapMetricsEllipsoid, RangeIsTheDistanceToTheSurface) {
  const MapFileQuadric e =
      ellipsoid(1, Eigen::Isometry3d(Eigen::Translation3d(1, 2, 0)), Eigen::Vector3d(0.3, 0.2, 0.1));
  MapFile truth;
  truth.quadrics = {e};
  // Cameras on the quadric's x axis 2 m from the centre and on its z axis 3 m from it.
  const std::map<int, double> near = truthRanges(truth, {Eigen::Vector3d(3, 2, 0)});
  EXPECT_NEAR(near.at(1), 2.0 - 0.3, 1e-12);
  const std::map<int, double> above = truthRanges(truth, {Eigen::Vector3d(1, 2, 3)});
  EXPECT_NEAR(above.at(1), 3.0 - 0.1, 1e-12);
}

TEST(MapMetricsEllipsoid, GatesValidate) {
  MapEvaluator::Params p;
  p.ellipsoid_semi_axis_gate_m = 0.0;
  EXPECT_THROW(MapEvaluator{p}, std::invalid_argument);
  p = {};
  p.ellipsoid_angle_gate_deg = -1.0;
  EXPECT_THROW(MapEvaluator{p}, std::invalid_argument);
  EXPECT_EQ(MapEvaluator().gates("ellipsoid").size(), 5u);
}

}  // namespace
}  // namespace quadric_slam
