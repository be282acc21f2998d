// The plane stage's merging of coplanar fragments (PlaneRegionGrower::mergeCoplanar) on rendered
// frames: fragments of one surface separated by a nearer object or by a hole in the depth become
// one segment; two parallel surfaces at one offset with the floor seen between them (two table tops
// at one height, a table top and a post's top 5 cm lower) stay two segments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/sim/primitive_scene_renderer.h"
#include "segment_rendered.h"

namespace qs = quadric_slam;
using qs::PrimitiveShape;

namespace {

// The label covering most of the truth's pixels of primitive t, and the share it covers.
std::pair<std::uint16_t, double> coveringLabel(const qs::Segmentation& result, const cv::Mat& truth,
                                               int t) {
  int total = 0;
  const std::vector<int> count = qs::test::labelCountsOn(result, truth, t, &total);
  std::uint16_t best = 0;
  for (std::uint16_t label = 1; label < count.size(); ++label)
    if (count[label] > count[best] || best == 0)
      best = label;
  return {best, total > 0 ? static_cast<double>(count[best]) / total : 0.0};
}

// A horizontal square plate (0.4 m wide) with its centre at `centre` (camera frame, y down).
qs::ScenePrimitive plate(const Eigen::Vector3d& centre) {
  qs::ScenePrimitive p;
  p.shape = PrimitiveShape::plane(Eigen::Vector3d(0, -1, 0), -centre.y());
  p.shape.point = centre;
  p.plane_half_size = 0.2;
  return p;
}

// The camera 1.2 m above a floor, looking 20 degrees down; two plates beside each other 1 m apart,
// the left one at 0.75 m above the floor, the right one `drop` lower; the floor is seen between
// them.
std::vector<qs::ScenePrimitive> twoPlates(double drop) {
  const Eigen::Isometry3d T_camera_world(
      Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()));
  std::vector<qs::ScenePrimitive> scene;
  qs::ScenePrimitive floor;
  floor.shape = PrimitiveShape::plane(Eigen::Vector3d(0, -1, 0), -1.2);
  scene.push_back(floor);
  scene.push_back(plate(Eigen::Vector3d(-0.5, 1.2 - 0.75, 1.6)));
  scene.push_back(plate(Eigen::Vector3d(0.5, 1.2 - 0.75 + drop, 1.6)));
  for (qs::ScenePrimitive& p : scene)
    p.shape = p.shape.transformed(T_camera_world);
  return scene;
}

void expectTwoPlateSegments(double drop) {
  const std::vector<qs::ScenePrimitive> scene = twoPlates(drop);
  const qs::PrimitiveRendering frame =
      qs::renderPrimitives(scene, qs::test::kinectVga(), qs::RenderParams());
  const qs::Segmentation result = qs::test::segmentRendered(frame.depth);
  const auto [left, left_share] = coveringLabel(result, frame.truth, 1);
  const auto [right, right_share] = coveringLabel(result, frame.truth, 2);
  EXPECT_GE(left_share, 0.8);
  EXPECT_GE(right_share, 0.8);
  EXPECT_NE(left, right) << "plates " << drop << " m apart in height merged into one segment";
}

TEST(PlaneMerging, TwoTableTopsAtOneHeightWithTheFloorBetweenStayTwo) {
  expectTwoPlateSegments(0.0);
}

TEST(PlaneMerging, TwoPlatesFiveCentimetresApartInHeightStayTwo) {
  expectTwoPlateSegments(0.05);
}

// A wall 2.5 m away split into a left and a right fragment: by a nearer upright pole, or by a
// band without depth.
std::vector<qs::ScenePrimitive> wallBehindPole() {
  std::vector<qs::ScenePrimitive> scene(2);
  scene[0].shape = PrimitiveShape::plane(Eigen::Vector3d(0.2, 0, -1).normalized(), -2.5);
  scene[1].shape =
      PrimitiveShape::cylinder(Eigen::Vector3d(0.0, 0, 1.5), Eigen::Vector3d(0, 1, 0), 0.15);
  scene[1].axis_min = -3.0;
  scene[1].axis_max = 3.0;
  return scene;
}

TEST(PlaneMerging, WallFragmentsBesideANearerPoleAreOneSegment) {
  const std::vector<qs::ScenePrimitive> scene = wallBehindPole();
  const qs::PrimitiveRendering frame =
      qs::renderPrimitives(scene, qs::test::kinectVga(), qs::RenderParams());
  const auto [wall, share] = coveringLabel(qs::test::segmentRendered(frame.depth), frame.truth, 0);
  EXPECT_NE(wall, 0);
  EXPECT_GE(share, 0.8) << "the wall's two sides are not one segment";
}

TEST(PlaneMerging, WallFragmentsBesideAHoleInTheDepthAreOneSegment) {
  std::vector<qs::ScenePrimitive> scene = wallBehindPole();
  scene.pop_back();
  qs::PrimitiveRendering frame =
      qs::renderPrimitives(scene, qs::test::kinectVga(), qs::RenderParams());
  // A vertical band of 60 pixels without depth (a dark or specular strip the sensor misses).
  frame.depth.colRange(290, 350).setTo(std::numeric_limits<float>::quiet_NaN());
  frame.truth.colRange(290, 350).setTo(0);
  const auto [wall, share] = coveringLabel(qs::test::segmentRendered(frame.depth), frame.truth, 0);
  EXPECT_NE(wall, 0);
  EXPECT_GE(share, 0.8) << "the wall's two sides are not one segment";
}

}  // namespace
