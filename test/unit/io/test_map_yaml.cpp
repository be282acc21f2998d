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
