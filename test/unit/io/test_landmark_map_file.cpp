// mapFileFromLandmarks: every landmark becomes a schema entry whose shape keys rebuild the same
// quadric, survives the YAML round trip, and an ellipsoid is named as such.
#include <gtest/gtest.h>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/io/landmark_map_file.h"

namespace qs = quadric_slam;

TEST(LandmarkMapFile, LandmarksRoundTripThroughTheSchema) {
  qs::CylinderShape cylinder;
  cylinder.point = Eigen::Vector3d(1, 2, 0.5);
  cylinder.axis = Eigen::Vector3d(0, 0.1, 1);
  cylinder.radius = 0.12;
  qs::PlaneShape plane;
  plane.normal = Eigen::Vector3d(0, 0, 1);
  plane.offset = 0.72;
  std::vector<qs::QuadricLandmark> landmarks(3);
  landmarks[0].id = 4;
  landmarks[0].quadric_map = qs::quadricFromShape(cylinder);
  landmarks[0].observations = 17;
  landmarks[1].id = 9;
  landmarks[1].quadric_map = qs::quadricFromShape(plane);
  landmarks[2].id = 11;
  landmarks[2].quadric_map =
      qs::QuadricModel(qs::QuadricClass::kGeneral, Eigen::Isometry3d::Identity(),
                       Eigen::Vector3d(2, 3, 4), Eigen::Vector4d(1, 1, 1, -1));

  landmarks[1].extent_min = Eigen::Vector3d(-0.01, -0.5, -0.3);  // the plane's observed box
  landmarks[1].extent_max = Eigen::Vector3d(0.01, 0.6, 0.2);

  const qs::MapFile map =
      qs::parseMapYaml(qs::mapYamlString(qs::mapFileFromLandmarks(landmarks, "map")));
  EXPECT_EQ(map.frame_id, "map");
  ASSERT_EQ(map.quadrics.size(), 3u);
  EXPECT_EQ(map.quadrics[0].id, 4);
  EXPECT_EQ(map.quadrics[0].quadric_class, "cylinder");
  EXPECT_EQ(map.quadrics[0].observations, 17);
  const qs::CylinderShape back = qs::cylinderShape(
      qs::quadricFromShapeMap(qs::QuadricClass::kCylinder, map.quadrics[0].shape));
  EXPECT_NEAR(back.radius, 0.12, 1e-9);
  EXPECT_NEAR(std::abs(back.axis.dot(cylinder.axis.normalized())), 1.0, 1e-9);
  EXPECT_TRUE(map.quadrics[0].T_map_quadric.isApprox(landmarks[0].quadric_map.pose(), 1e-9));
  EXPECT_EQ(map.quadrics[1].quadric_class, "plane");
  const qs::PlaneShape plane_back =
      qs::planeShape(qs::quadricFromShapeMap(qs::QuadricClass::kPlane, map.quadrics[1].shape));
  EXPECT_NEAR(plane_back.normal.dot(plane.normal) * plane_back.offset, 0.72, 1e-9);
  EXPECT_FALSE(map.quadrics[0].has_extent) << "no observed box: no extent";
  ASSERT_TRUE(map.quadrics[1].has_extent);
  EXPECT_TRUE(map.quadrics[1].extent_min.isApprox(landmarks[1].extent_min, 1e-9));
  EXPECT_TRUE(map.quadrics[1].extent_max.isApprox(landmarks[1].extent_max, 1e-9));
  EXPECT_EQ(map.quadrics[2].quadric_class, "ellipsoid");
  EXPECT_TRUE(map.quadrics[2].scale.isApprox(Eigen::Vector3d(2, 3, 4)));
}
