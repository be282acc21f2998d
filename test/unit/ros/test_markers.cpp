// quadricMarkers: every class becomes the rviz shape of its surface, placed and sized from the
// landmark's pose, scale and extent (checked geometrically: cone mesh vertices lie on the cone);
// the array starts with DELETEALL; ids, namespaces, colours and labels are as documented.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <set>
#include <stdexcept>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"
#include "quadric_slam/ros/conversions.h"
#include "quadric_slam/ros/markers.h"

namespace qs = quadric_slam;

namespace {

qs::QuadricLandmark landmark(int id, const qs::QuadricModel& quadric,
                             const Eigen::Vector3d& extent_min = Eigen::Vector3d::Zero(),
                             const Eigen::Vector3d& extent_max = Eigen::Vector3d::Zero()) {
  qs::QuadricLandmark l;
  l.id = id;
  l.quadric_map = quadric;
  l.extent_min = extent_min;
  l.extent_max = extent_max;
  return l;
}

std_msgs::Header mapHeader() {
  std_msgs::Header header;
  header.frame_id = "map";
  header.stamp = ros::Time(12.5);
  return header;
}

Eigen::Vector3d positionOf(const visualization_msgs::Marker& marker) {
  return Eigen::Vector3d(marker.pose.position.x, marker.pose.position.y, marker.pose.position.z);
}

const visualization_msgs::Marker* find(const visualization_msgs::MarkerArray& array,
                                       const std::string& ns, int id) {
  for (const auto& marker : array.markers) {
    if (marker.ns == ns && marker.id == id && marker.action == visualization_msgs::Marker::ADD)
      return &marker;
  }
  return nullptr;
}

}  // namespace

TEST(QuadricMarkers, EachClassIsDrawnWhereItsSurfaceIs) {
  qs::PlaneShape plane;
  plane.normal = Eigen::Vector3d(0, 0, 1);
  plane.offset = 0.7;  // a desk top 70 cm up
  qs::SphereShape sphere;
  sphere.center = Eigen::Vector3d(1.0, 2.0, 0.9);
  sphere.radius = 0.15;
  qs::CylinderShape cylinder;
  cylinder.point = Eigen::Vector3d(-1.0, 0.5, 0.0);
  cylinder.axis = Eigen::Vector3d(0.0, 0.2, 1.0).normalized();
  cylinder.radius = 0.05;
  qs::ConeShape cone;
  cone.apex = Eigen::Vector3d(0.3, -0.4, 1.0);
  cone.axis = Eigen::Vector3d(0.0, 0.0, -1.0);
  cone.half_angle = 0.3;
  const std::vector<qs::QuadricLandmark> landmarks = {
      landmark(1, qs::quadricFromShape(plane), Eigen::Vector3d(0, -0.4, 0.2),
               Eigen::Vector3d(0, 0.6, 1.0)),
      landmark(2, qs::quadricFromShape(sphere)),
      landmark(3, qs::quadricFromShape(cylinder), Eigen::Vector3d(-0.05, -0.05, -0.1),
               Eigen::Vector3d(0.05, 0.05, 0.3)),
      landmark(4, qs::quadricFromShape(cone), Eigen::Vector3d(-0.1, -0.1, 0.1),
               Eigen::Vector3d(0.1, 0.1, 0.4))};
  const auto array = qs::quadricMarkers(landmarks, mapHeader());

  ASSERT_FALSE(array.markers.empty());
  EXPECT_EQ(array.markers.front().action, visualization_msgs::Marker::DELETEALL);
  for (const auto& marker : array.markers) {
    EXPECT_EQ(marker.header.frame_id, "map");
    EXPECT_EQ(marker.header.stamp, ros::Time(12.5));
  }
  // 4 shapes and 4 labels after the DELETEALL.
  EXPECT_EQ(array.markers.size(), 9u);

  const auto* plane_marker = find(array, "plane", 1);
  ASSERT_NE(plane_marker, nullptr);
  EXPECT_EQ(plane_marker->type, visualization_msgs::Marker::CUBE);
  const Eigen::Isometry3d T_map_plane = qs::fromPoseMsg(plane_marker->pose);
  // Thin along the normal (the marker's x), centred on the extent in the plane.
  EXPECT_NEAR(std::abs(T_map_plane.linear().col(0).dot(plane.normal)), 1.0, 1e-9);
  EXPECT_NEAR(plane.normal.dot(positionOf(*plane_marker)), plane.offset, 1e-9);
  EXPECT_NEAR(positionOf(*plane_marker).z(), 0.7, 1e-9);
  const Eigen::Vector3d expected_centre =
      qs::quadricFromShape(plane).pose() * Eigen::Vector3d(0, 0.1, 0.6);
  EXPECT_LT((positionOf(*plane_marker) - expected_centre).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(plane_marker->scale.x, qs::MarkerStyle().plane_thickness);
  EXPECT_NEAR(plane_marker->scale.y, 1.0, 1e-12);
  EXPECT_NEAR(plane_marker->scale.z, 0.8, 1e-12);

  const auto* sphere_marker = find(array, "sphere", 2);
  ASSERT_NE(sphere_marker, nullptr);
  EXPECT_EQ(sphere_marker->type, visualization_msgs::Marker::SPHERE);
  EXPECT_LT((positionOf(*sphere_marker) - sphere.center).norm(), 1e-9);
  EXPECT_NEAR(sphere_marker->scale.x, 0.3, 1e-9);
  EXPECT_NEAR(sphere_marker->scale.z, 0.3, 1e-9);

  const auto* cylinder_marker = find(array, "cylinder", 3);
  ASSERT_NE(cylinder_marker, nullptr);
  EXPECT_EQ(cylinder_marker->type, visualization_msgs::Marker::CYLINDER);
  const Eigen::Isometry3d T_map_cylinder = qs::fromPoseMsg(cylinder_marker->pose);
  EXPECT_NEAR(std::abs(T_map_cylinder.linear().col(2).dot(cylinder.axis)), 1.0, 1e-9);
  // Centred on the axis, midway along the extent [-0.1, 0.3] (the direction is the quadric's z).
  const Eigen::Vector3d axis_z = qs::quadricFromShape(cylinder).pose().linear().col(2);
  const Eigen::Vector3d axis_origin = qs::quadricFromShape(cylinder).pose().translation();
  EXPECT_LT((positionOf(*cylinder_marker) - (axis_origin + 0.1 * axis_z)).norm(), 1e-9);
  EXPECT_NEAR(cylinder_marker->scale.x, 0.1, 1e-9);
  EXPECT_NEAR(cylinder_marker->scale.z, 0.4, 1e-9);

  const auto* cone_marker = find(array, "cone", 4);
  ASSERT_NE(cone_marker, nullptr);
  EXPECT_EQ(cone_marker->type, visualization_msgs::Marker::TRIANGLE_LIST);
  ASSERT_EQ(cone_marker->points.size(), 6u * qs::MarkerStyle().cone_segments);
  const Eigen::Isometry3d T_map_mesh = qs::fromPoseMsg(cone_marker->pose);
  const qs::QuadricModel cone_quadric = qs::quadricFromShape(cone);
  for (const auto& point : cone_marker->points) {
    const Eigen::Vector3d p_map = T_map_mesh * Eigen::Vector3d(point.x, point.y, point.z);
    EXPECT_LT(qs::exactDistance(cone_quadric, p_map), 1e-9);
    // Between 0.1 and 0.4 m from the apex along the axis, into the opening.
    const double along = (p_map - cone.apex).dot(cone.axis);
    EXPECT_GT(along, 0.1 - 1e-9);
    EXPECT_LT(along, 0.4 + 1e-9);
  }

  std::set<std::tuple<float, float, float>> colours;
  for (int id = 1; id <= 4; ++id) {
    const auto* label = find(array, "labels", id);
    ASSERT_NE(label, nullptr);
    EXPECT_EQ(label->type, visualization_msgs::Marker::TEXT_VIEW_FACING);
    EXPECT_NE(label->text.find(std::to_string(id)), std::string::npos);
  }
  for (const auto* marker : {plane_marker, sphere_marker, cylinder_marker, cone_marker}) {
    EXPECT_FLOAT_EQ(marker->color.a, 0.6f);
    colours.insert({marker->color.r, marker->color.g, marker->color.b});
  }
  EXPECT_EQ(colours.size(), 4u) << "each landmark has its own colour";
}

TEST(QuadricMarkers, GeneralQuadricsAndDefaults) {
  const Eigen::Isometry3d pose(Eigen::Translation3d(1, 2, 3) *
                               Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  const qs::QuadricModel ellipsoid(qs::QuadricClass::kGeneral, pose, Eigen::Vector3d(2, 4, 5),
                                   Eigen::Vector4d(1, 1, 1, -1));
  const qs::QuadricModel hyperboloid(qs::QuadricClass::kGeneral, pose, Eigen::Vector3d(2, 4, 5),
                                     Eigen::Vector4d(1, 1, -1, -1));
  qs::CylinderShape cylinder;
  cylinder.radius = 0.2;
  qs::MarkerStyle style;
  style.labels = false;
  const auto array = qs::quadricMarkers({landmark(5, ellipsoid), landmark(6, hyperboloid),
                                         landmark(7, qs::quadricFromShape(cylinder))},
                                        mapHeader(), style);
  // DELETEALL, the ellipsoid and the cylinder: the hyperboloid has no marker shape, labels are off.
  ASSERT_EQ(array.markers.size(), 3u);
  const auto* ellipsoid_marker = find(array, "general", 5);
  ASSERT_NE(ellipsoid_marker, nullptr);
  EXPECT_EQ(ellipsoid_marker->type, visualization_msgs::Marker::SPHERE);
  EXPECT_NEAR(ellipsoid_marker->scale.x, 1.0, 1e-12);  // semi-axis 1/2
  EXPECT_NEAR(ellipsoid_marker->scale.y, 0.5, 1e-12);  // 1/4
  EXPECT_NEAR(ellipsoid_marker->scale.z, 0.4, 1e-12);  // 1/5
  EXPECT_TRUE(qs::fromPoseMsg(ellipsoid_marker->pose).isApprox(pose, 1e-9));
  // Without an extent the cylinder gets the default length around its origin.
  const auto* cylinder_marker = find(array, "cylinder", 7);
  ASSERT_NE(cylinder_marker, nullptr);
  EXPECT_NEAR(cylinder_marker->scale.z, style.default_extent, 1e-12);
  EXPECT_NEAR(cylinder_marker->scale.x, 0.4, 1e-12);
  EXPECT_LT(positionOf(*cylinder_marker).norm(), 1e-12);

  // An empty map still clears rviz.
  const auto empty = qs::quadricMarkers({}, mapHeader());
  ASSERT_EQ(empty.markers.size(), 1u);
  EXPECT_EQ(empty.markers[0].action, visualization_msgs::Marker::DELETEALL);
}

TEST(QuadricMarkers, ColoursAreStableAndDistinct) {
  for (int id = 0; id < 50; ++id) {
    const auto a = qs::landmarkColour(id, 0.5), b = qs::landmarkColour(id, 0.5);
    EXPECT_EQ(a.r, b.r);
    EXPECT_EQ(a.g, b.g);
    EXPECT_EQ(a.b, b.b);
    EXPECT_FLOAT_EQ(a.a, 0.5f);
    const auto next = qs::landmarkColour(id + 1, 0.5);
    const double difference =
        std::abs(a.r - next.r) + std::abs(a.g - next.g) + std::abs(a.b - next.b);
    EXPECT_GT(difference, 0.3) << "ids " << id << " and " << id + 1;
  }
}

TEST(QuadricMarkers, StyleValidateNamesTheField) {
  qs::MarkerStyle style;
  style.cone_segments = 2;
  try {
    qs::quadricMarkers({}, mapHeader(), style);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cone_segments"), std::string::npos);
  }
  style = {};
  style.alpha = 1.5;
  EXPECT_THROW(style.validate(), std::invalid_argument);
}
