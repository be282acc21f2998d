#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "quadric_slam/eval/map_metrics.h"

using quadric_slam::MapEvaluator;
using quadric_slam::MapFile;
using quadric_slam::MapFileQuadric;
using quadric_slam::MapReport;
using quadric_slam::TruthResult;

namespace {

constexpr double kDeg = M_PI / 180.0;

MapFileQuadric quadric(int id, const std::string& c,
                       std::map<std::string, std::vector<double>> shape) {
  MapFileQuadric q;
  q.id = id;
  q.quadric_class = c;
  q.shape = std::move(shape);
  return q;
}

std::vector<double> vec(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

double errorNamed(const TruthResult& r, const std::string& name) {
  for (const auto& e : r.errors) {
    if (e.name == name)
      return e.value;
  }
  ADD_FAILURE() << "no error named " << name;
  return NAN;
}

Eigen::Isometry3d someTransform() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, 0.5, -1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(-3, 0.7, 1.9);
  return T;
}

}  // namespace

TEST(MapMetrics, TransformMovesShapesConsistently) {
  const Eigen::Isometry3d T = someTransform();
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 2) / 3.0;
  const MapFileQuadric plane = quadric(1, "plane", {{"normal", vec(n)}, {"offset", {1.5}}});
  const MapFileQuadric moved = quadric_slam::transformQuadric(plane, T);
  // A point on the plane stays on the moved plane.
  const Eigen::Vector3d p = 1.5 * n + Eigen::Vector3d(2, -1, 0);  // n.(2,-1,0) = 0
  const auto& n2 = moved.shape.at("normal");
  EXPECT_NEAR(Eigen::Vector3d(n2[0], n2[1], n2[2]).dot(T * p), moved.shape.at("offset")[0], 1e-12);
  // Round trip through the inverse gives zero errors.
  const MapFileQuadric cone =
      quadric(2, "cone", {{"apex", {1, 2, 3}}, {"axis", {0, 0, -1}}, {"half_angle", {0.4}}});
  const MapFileQuadric back =
      quadric_slam::transformQuadric(quadric_slam::transformQuadric(cone, T), T.inverse());
  for (const auto& e : quadric_slam::shapeErrors(cone, back))
    EXPECT_NEAR(e.value, 0.0, 1e-9) << e.name;
}

TEST(MapMetrics, HandMadeMapsWithKnownErrors) {
  MapFile truth;
  truth.quadrics = {
      quadric(1, "plane", {{"normal", {0, 0, 1}}, {"offset", {0.0}}}),
      quadric(2, "plane", {{"normal", {1, 0, 0}}, {"offset", {2.0}}}),
      quadric(3, "sphere", {{"center", {1, 1, 0.5}}, {"radius", {0.2}}}),
      quadric(4, "cylinder", {{"point", {0, 1, 0.5}}, {"axis", {0, 0, 1}}, {"radius", {0.1}}}),
      quadric(5, "cone", {{"apex", {2, 0, 1}}, {"axis", {0, 0, -1}}, {"half_angle", {0.5}}}),
      quadric(6, "general", {}),  // a hyperboloid, say: not evaluated
  };

  // Estimates built in the truth frame with known errors, then expressed in the estimate frame.
  const Eigen::Isometry3d T_truth_est = someTransform();
  const Eigen::Vector3d tilted_floor =
      Eigen::AngleAxisd(2.0 * kDeg, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d tilted_axis =
      Eigen::AngleAxisd(3.0 * kDeg, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d cone_axis =
      Eigen::AngleAxisd(4.0 * kDeg, Eigen::Vector3d::UnitY()) * -Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d wall_30 =
      Eigen::AngleAxisd(30.0 * kDeg, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d::UnitX();
  MapFile in_truth_frame;
  in_truth_frame.quadrics = {
      // floor with the opposite sign convention: (-n, -d) is the same plane, offset 0.03 m
      quadric(11, "plane", {{"normal", vec(-tilted_floor)}, {"offset", {-0.03}}}),
      // duplicate of the sphere listed first, farther than the real match
      quadric(12, "sphere", {{"center", {1.1, 1, 0.5}}, {"radius", {0.2}}}),
      quadric(13, "sphere", {{"center", {1.03, 1.04, 0.5}}, {"radius", {0.21}}}),
      // axis flipped and tilted 3 deg about x, point 2 cm off in x and slid 0.3 m along the axis
      quadric(14, "cylinder",
              {{"point", vec(Eigen::Vector3d(0.02, 1, 0.5) + 0.3 * tilted_axis)},
               {"axis", vec(-tilted_axis)},
               {"radius", {0.12}}}),
      quadric(
          15, "cone",
          {{"apex", {2, 0.05, 1}}, {"axis", vec(cone_axis)}, {"half_angle", {0.5 + 2.0 * kDeg}}}),
      quadric(16, "sphere", {{"center", {11, 1, 0.5}}, {"radius", {0.2}}}),  // nothing there
      quadric(17, "plane", {{"normal", vec(wall_30)}, {"offset", {2.0}}}),   // 30 deg off the wall
      quadric(18, "general", {}),
  };
  MapFile estimate;
  for (const auto& q : in_truth_frame.quadrics) {
    estimate.quadrics.push_back(quadric_slam::transformQuadric(q, T_truth_est.inverse()));
  }

  const MapReport report = MapEvaluator().evaluate(truth, estimate, T_truth_est);
  ASSERT_EQ(report.truths.size(), 5u);
  EXPECT_EQ(report.matched, 4);
  EXPECT_EQ(report.misses, 1);
  EXPECT_EQ(report.duplicates, 1);
  EXPECT_EQ(report.unmatched_estimates, 2);
  EXPECT_EQ(report.skipped_truths, 1);
  EXPECT_EQ(report.skipped_estimates, 1);

  const TruthResult& floor = report.truths[0];
  ASSERT_TRUE(floor.matched);
  EXPECT_EQ(floor.estimate_id, 11);
  EXPECT_NEAR(errorNamed(floor, "normal_angle_deg"), 2.0, 1e-9);
  EXPECT_NEAR(errorNamed(floor, "offset_m"), 0.03, 1e-9);
  EXPECT_FALSE(report.truths[1].matched);  // the wall: only a 30 deg-off plane near it

  const TruthResult& sphere = report.truths[2];
  ASSERT_TRUE(sphere.matched);
  EXPECT_EQ(sphere.estimate_id, 13);
  EXPECT_EQ(sphere.duplicate_ids, std::vector<int>{12});
  EXPECT_NEAR(errorNamed(sphere, "center_m"), 0.05, 1e-9);
  EXPECT_NEAR(errorNamed(sphere, "radius_m"), 0.01, 1e-9);

  const TruthResult& cylinder = report.truths[3];
  ASSERT_TRUE(cylinder.matched);
  EXPECT_NEAR(errorNamed(cylinder, "axis_angle_deg"), 3.0, 1e-9);
  EXPECT_NEAR(errorNamed(cylinder, "axis_distance_m"), 0.02, 1e-9);
  EXPECT_NEAR(errorNamed(cylinder, "radius_m"), 0.02, 1e-9);

  const TruthResult& cone = report.truths[4];
  ASSERT_TRUE(cone.matched);
  EXPECT_NEAR(errorNamed(cone, "apex_m"), 0.05, 1e-9);
  EXPECT_NEAR(errorNamed(cone, "axis_angle_deg"), 4.0, 1e-9);
  EXPECT_NEAR(errorNamed(cone, "half_angle_deg"), 2.0, 1e-9);

  const auto& planes = report.classes.at("plane");
  EXPECT_EQ(planes.truths, 2);
  EXPECT_EQ(planes.matched, 1);
  EXPECT_EQ(planes.misses, 1);
  EXPECT_EQ(planes.unmatched_estimates, 1);
  EXPECT_EQ(report.classes.at("sphere").duplicates, 1);
  EXPECT_EQ(report.classes.at("sphere").unmatched_estimates, 1);

  const std::string text = quadric_slam::formatMapReport(report);
  EXPECT_NE(text.find("truth 2 plane missed seen_frames 0 large_views 0\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("truth 3 sphere matched estimate 13 center_m 0.050000 radius_m 0.010000"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("map_summary matched 4 misses 1 duplicates 1 unmatched_estimates 2 "
                      "misses_seen_30 0 misses_large_30 0"),
            std::string::npos)
      << text;

  // Without the alignment the estimate lies elsewhere: nothing matches.
  const MapReport unaligned =
      MapEvaluator().evaluate(truth, estimate, Eigen::Isometry3d::Identity());
  EXPECT_EQ(unaligned.matched, 0);
  EXPECT_EQ(unaligned.misses, 5);
}

// Range bands: a surface's range is its median distance from the camera positions; the summary per
// class and band counts matches and misses of the truths in that band only.
TEST(MapMetrics, RangesAndBandsFollowTheCameraPath) {
  MapFile truth;
  truth.quadrics.push_back(quadric(1, "plane", {{"normal", {0, 0, 1}}, {"offset", {0.0}}}));
  truth.quadrics.push_back(quadric(2, "plane", {{"normal", {1, 0, 0}}, {"offset", {3.0}}}));
  truth.quadrics.push_back(quadric(3, "sphere", {{"center", {0.5, 0, 1.0}}, {"radius", {0.2}}}));
  truth.quadrics.push_back(
      quadric(4, "cylinder", {{"point", {-2.0, 0, 0}}, {"axis", {0, 0, 1}}, {"radius", {0.5}}}));
  truth.quadrics.push_back(
      quadric(5, "cone", {{"apex", {0, 0, 3.0}}, {"axis", {0, 0, 1}}, {"half_angle", {M_PI / 4}}}));
  // Cameras at 1.5 m height along x in [-0.5, 0.5]: the median camera is (0, 0, 1.5).
  std::vector<Eigen::Vector3d> cameras;
  for (int i = 0; i <= 10; ++i)
    cameras.emplace_back(-0.5 + 0.1 * i, 0.0, 1.5);
  const std::map<int, double> ranges = quadric_slam::truthRanges(truth, cameras);
  ASSERT_EQ(ranges.size(), 5u);
  EXPECT_NEAR(ranges.at(1), 1.5, 1e-9);                         // floor below
  EXPECT_NEAR(ranges.at(2), 3.0, 1e-9);                         // wall x = 3 (median x 0)
  EXPECT_NEAR(ranges.at(3), std::hypot(0.5, 0.5) - 0.2, 1e-9);  // sphere from (0, 0, 1.5)
  EXPECT_NEAR(ranges.at(4), 2.0 - 0.5, 1e-9);                   // cylinder axis at x = -2
  // The cone's axis crosses the camera path: from (x, 0, 1.5) (radial |x|, axial 1.5 below the
  // apex) the distance to the 45-degree line is (1.5 - |x|) sin 45; the median |x| is 0.3.
  EXPECT_NEAR(ranges.at(5), (1.5 - 0.3) * std::sin(M_PI / 4), 1e-9);
  EXPECT_THROW(quadric_slam::truthRanges(truth, {}), std::invalid_argument);

  EXPECT_EQ(quadric_slam::rangeBand(1.5, {2.0, 4.0}), "0-2m");
  EXPECT_EQ(quadric_slam::rangeBand(3.0, {2.0, 4.0}), "2-4m");
  EXPECT_EQ(quadric_slam::rangeBand(4.5, {2.0, 4.0}), "4m+");

  // An estimate of the floor only (2 cm off): the near plane band has a match, the far one a miss.
  MapFile estimate;
  estimate.quadrics.push_back(quadric(7, "plane", {{"normal", {0, 0, 1}}, {"offset", {0.02}}}));
  const MapReport report = MapEvaluator().evaluate(truth, estimate, Eigen::Isometry3d::Identity());
  const auto by_range = quadric_slam::summariseByRange(report, ranges, {2.0, 4.0});
  ASSERT_EQ(by_range.count("plane 0-2m"), 1u);
  ASSERT_EQ(by_range.count("plane 2-4m"), 1u);
  EXPECT_EQ(by_range.at("plane 0-2m").matched, 1);
  EXPECT_EQ(by_range.at("plane 0-2m").misses, 0);
  EXPECT_NEAR(by_range.at("plane 0-2m").mean_errors.at(1).value, 0.02, 1e-9);  // offset_m
  EXPECT_EQ(by_range.at("plane 2-4m").matched, 0);
  EXPECT_EQ(by_range.at("plane 2-4m").misses, 1);
  EXPECT_EQ(by_range.at("sphere 0-2m").misses, 1);
  const std::string text = quadric_slam::formatMapReport(report, &by_range);
  EXPECT_NE(text.find("class_range plane 0-2m truths 1 matched 1 misses 0 duplicates 0"),
            std::string::npos)
      << text;
}

TEST(MapMetrics, BadInputNamesTheProblem) {
  MapEvaluator::Params params;
  params.sphere_radius_gate_m = 0.0;
  try {
    MapEvaluator evaluator(params);
    FAIL() << "expected invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sphere_radius_gate_m"), std::string::npos);
  }
  MapFile truth, estimate;
  truth.quadrics = {quadric(7, "sphere", {{"center", {0, 0, 0}}, {"radius", {1}}})};
  estimate.quadrics = {quadric(9, "sphere", {{"centre", {0, 0, 0}}, {"radius", {1}}})};
  try {
    MapEvaluator().evaluate(truth, estimate, Eigen::Isometry3d::Identity());
    FAIL() << "expected runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("quadric 9"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'center'"), std::string::npos) << e.what();
  }
}

namespace {

// A bounded piece of a horizontal plane (normal +z) centred at `centre`, half sizes hx, hy: the
// quadric frame's x is the normal (as the generator's rectangles), its y, z span the piece.
MapFileQuadric horizontalPiece(int id, const Eigen::Vector3d& centre, double hx, double hy,
                               int seen_frames) {
  MapFileQuadric q = quadric(id, "plane", {{"normal", {0, 0, 1}}, {"offset", {centre.z()}}});
  q.T_map_quadric.linear() << 0, 1, 0,  //
      0, 0, 1,                          //
      1, 0, 0;                          // columns: x -> +z, y -> +x, z -> +y
  q.T_map_quadric.translation() = centre;
  q.has_extent = true;
  q.extent_min = Eigen::Vector3d(0, -hx, -hy);
  q.extent_max = Eigen::Vector3d(0, hx, hy);
  q.observations = seen_frames;
  return q;
}

}  // namespace

// Coplanar truths share every shape parameter: the floor and the disc of a column standing on it,
// two desk tops at one height. The extents and the views tell them apart.
TEST(MapMetrics, CoplanarTruthsAreToldApartByExtentsAndViews) {
  MapFile truth;
  truth.quadrics.push_back(horizontalPiece(1, Eigen::Vector3d(0, 0, 0), 3.5, 3.5, 1200));  // floor
  truth.quadrics.push_back(horizontalPiece(2, Eigen::Vector3d(1, 1, 0), 0.15, 0.15, 0));   // cap
  truth.quadrics.push_back(horizontalPiece(3, Eigen::Vector3d(-2, 0, 0.75), 0.4, 0.8, 300));
  truth.quadrics.push_back(horizontalPiece(4, Eigen::Vector3d(1, 2.5, 0.75), 0.8, 0.4, 500));
  truth.quadrics.push_back(horizontalPiece(5, Eigen::Vector3d(0, -3, 1.0), 0.6, 0.3, 40));
  truth.quadrics.push_back(horizontalPiece(6, Eigen::Vector3d(2, -2, 1.2), 0.1, 0.1, 10));
  // Frames with 2000 pixels or more of it: the cabinet top 32, a strip seen in 50 frames 5.
  truth.quadrics[4].large_views = 32;
  truth.quadrics.push_back(horizontalPiece(7, Eigen::Vector3d(-2, -3, 1.6), 0.5, 0.05, 50));
  truth.quadrics.back().large_views = 5;

  // The estimate: the floor's observed part (around the cap), both desk tops as seen (a few cm
  // short of their edges), in a frame moved by T.
  const Eigen::Isometry3d T = someTransform();
  MapFile estimate;
  for (const MapFileQuadric& q :
       {horizontalPiece(11, Eigen::Vector3d(0.5, 0.5, 0.004), 1.5, 1.5, 0),
        horizontalPiece(13, Eigen::Vector3d(-2, 0, 0.752), 0.35, 0.7, 0),
        horizontalPiece(14, Eigen::Vector3d(1, 2.5, 0.748), 0.7, 0.35, 0)})
    estimate.quadrics.push_back(quadric_slam::transformQuadric(q, T.inverse()));

  const MapReport report = MapEvaluator().evaluate(truth, estimate, T);
  ASSERT_EQ(report.truths.size(), 7u);
  EXPECT_EQ(report.truths[0].estimate_id, 11);  // the floor, not the unseen cap on it
  EXPECT_FALSE(report.truths[1].matched);
  EXPECT_EQ(report.truths[2].estimate_id, 13);
  EXPECT_EQ(report.truths[3].estimate_id, 14);
  EXPECT_EQ(report.duplicates, 0);
  EXPECT_EQ(report.unmatched_estimates, 0);
  // Misses: the cap (never seen), the cabinet top (40 frames, 32 large), the small top (10
  // frames), the strip (50 frames, 5 large).
  EXPECT_EQ(report.misses, 4);
  EXPECT_EQ(report.seen_misses, 2);
  EXPECT_EQ(report.large_view_misses, 1);
  const std::string text = quadric_slam::formatMapReport(report);
  EXPECT_NE(text.find("truth 5 plane missed seen_frames 40 large_views 32\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("misses_seen_30 2 misses_large_30 1"), std::string::npos) << text;

  // Without extents the two desk tops are one parameter set: one desk takes both estimates.
  MapFile no_extents = estimate;
  for (MapFileQuadric& q : no_extents.quadrics)
    q.has_extent = false;
  const MapReport blind = MapEvaluator().evaluate(truth, no_extents, T);
  EXPECT_EQ(blind.duplicates, 1);
  EXPECT_EQ(blind.misses, 5);

  // A truth file that counts no views (hand-written): every truth takes estimates, so the cap,
  // inside the floor estimate's box, competes with the floor on the shape errors alone.
  MapFile uncounted = truth;
  for (MapFileQuadric& q : uncounted.quadrics)
    q.observations = 0;
  const MapReport any_view = MapEvaluator().evaluate(uncounted, estimate, T);
  EXPECT_EQ(any_view.seen_misses, 0);
  EXPECT_EQ(any_view.matched + any_view.misses, 7);
}
