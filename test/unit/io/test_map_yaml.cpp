#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <stdexcept>

#include "quadric_slam/io/map_yaml.h"

using quadric_slam::MapFile;
using quadric_slam::MapFileQuadric;

TEST(MapYaml, RoundTripKeepsEveryField) {
  MapFile map;
  map.frame_id = "world";
  MapFileQuadric sphere;
  sphere.id = 3;
  sphere.quadric_class = "sphere";
  sphere.observations = 57;
  sphere.large_views = 41;
  sphere.T_map_quadric.translation() = Eigen::Vector3d(0.2, 0.9, 0.55);
  sphere.T_map_quadric.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  sphere.scale = Eigen::Vector3d::Constant(1.0 / 0.16);
  sphere.shape["center"] = {0.2, 0.9, 0.55};
  sphere.shape["radius"] = {0.16};
  map.quadrics.push_back(sphere);
  map.merged_into = {{5, 3}, {9, 3}};

  const MapFile back = quadric_slam::parseMapYaml(quadric_slam::mapYamlString(map));
  EXPECT_EQ(back.frame_id, "world");
  ASSERT_EQ(back.quadrics.size(), 1u);
  const MapFileQuadric& q = back.quadrics[0];
  EXPECT_EQ(q.id, 3);
  EXPECT_EQ(q.quadric_class, "sphere");
  EXPECT_EQ(q.observations, 57);
  EXPECT_EQ(q.large_views, 41);
  EXPECT_TRUE(q.T_map_quadric.isApprox(sphere.T_map_quadric, 1e-8));
  EXPECT_TRUE(q.scale.isApprox(sphere.scale, 1e-8));
  EXPECT_EQ(q.shape.at("center").size(), 3u);
  EXPECT_NEAR(q.shape.at("radius").at(0), 0.16, 1e-12);
  EXPECT_EQ(back.merged_into, map.merged_into);
}

TEST(MapYaml, ParsesTheDocumentedSchema) {
  const MapFile map = quadric_slam::parseMapYaml(R"(
frame_id: map
quadrics:
  - id: 1
    class: plane
    observations: 12
    pose: {position: [0, 0, 0], orientation: [0, 0, 0, 1]}
    scale: [1, 1, 1]
    shape: {normal: [1, 0, 0], offset: 0.0}
)");
  ASSERT_EQ(map.quadrics.size(), 1u);
  EXPECT_EQ(map.quadrics[0].shape.at("normal"), (std::vector<double>{1, 0, 0}));
  EXPECT_TRUE(map.merged_into.empty()) << "optional";
  EXPECT_EQ(quadric_slam::parseMapYaml("quadrics: []\nmerged_into: {7: 1, 8: 1}\n").merged_into,
            (std::map<int, int>{{7, 1}, {8, 1}}));
}

TEST(MapYaml, BadInputNamesTheProblem) {
  try {
    quadric_slam::parseMapYaml("quadrics:\n  - {id: 4, class: sphere, scale: [1, 1]}\n");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("quadric 4"), std::string::npos) << e.what();
  }
  EXPECT_THROW(
      quadric_slam::parseMapYaml("quadrics:\n  - {id: 1, class: plane, pose: {position: [0, 0, 0], "
                                 "orientation: [0, 0, 0, 2]}, scale: [1, 1, 1]}\n"),
      std::runtime_error);
  EXPECT_THROW(quadric_slam::readMapYaml("/nonexistent/map.yaml"), std::runtime_error);
  EXPECT_THROW(quadric_slam::parseMapYaml("quadrics: []\nmerged_into: [7, 1]\n"),
               std::runtime_error);
  EXPECT_THROW(quadric_slam::parseMapYaml("quadrics: []\nmerged_into: {a: 1}\n"),
               std::runtime_error);
}

// The optional extent (box of the surface's piece in the quadric frame) survives the round trip,
// is absent unless given, and a box with a corner missing or inverted is refused by name.
TEST(MapYaml, ExtentIsOptionalAndChecked) {
  MapFile map;
  MapFileQuadric plane;
  plane.id = 2;
  plane.quadric_class = "plane";
  plane.shape["normal"] = {0, 0, 1};
  plane.shape["offset"] = {0.75};
  plane.has_extent = true;
  plane.extent_min = Eigen::Vector3d(-0.004, -0.8, -0.4);
  plane.extent_max = Eigen::Vector3d(0.003, 0.8, 0.4);
  map.quadrics.push_back(plane);
  plane.id = 3;
  plane.has_extent = false;
  map.quadrics.push_back(plane);

  const std::string text = quadric_slam::mapYamlString(map);
  const MapFile back = quadric_slam::parseMapYaml(text);
  ASSERT_EQ(back.quadrics.size(), 2u);
  EXPECT_TRUE(back.quadrics[0].has_extent);
  EXPECT_TRUE(back.quadrics[0].extent_min.isApprox(plane.extent_min, 1e-9));
  EXPECT_TRUE(back.quadrics[0].extent_max.isApprox(Eigen::Vector3d(0.003, 0.8, 0.4), 1e-9));
  EXPECT_FALSE(back.quadrics[1].has_extent);
  EXPECT_EQ(text.find("extent_max"), text.rfind("extent_max")) << "only the first has one:\n"
                                                               << text;

  const std::string head =
      "quadrics:\n  - {id: 5, class: plane, pose: {position: [0, 0, 0], orientation: [0, 0, 0, "
      "1]}, scale: [1, 1, 1], ";
  for (const std::string& bad : {std::string("extent_min: [0, 0, 0]}\n"),
                                 std::string("extent_min: [0, 1, 0], extent_max: [0, 0, 0]}\n"),
                                 std::string("extent_min: [0, 0], extent_max: [1, 1, 1]}\n")}) {
    try {
      quadric_slam::parseMapYaml(head + bad);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("quadric 5"), std::string::npos) << what;
      EXPECT_NE(what.find("extent_m"), std::string::npos) << what;
    }
  }
}
