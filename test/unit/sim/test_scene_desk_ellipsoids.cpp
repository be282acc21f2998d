// config/scenes/desk_ellipsoids.yaml is desk.yaml with one more ellipsoid (the stone): every other
// primitive is desk.yaml's, unchanged, so figures on the two scenes differ by that surface only.
#include <gtest/gtest.h>

#include <string>

#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/surfaces.h"

namespace quadric_slam {
namespace {

Scene scene(const std::string& name) {
  return readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/" + name + ".yaml");
}

TEST(SceneDeskEllipsoids, IsTheDeskPlusOneEllipsoid) {
  const Scene desk = scene("desk"), two = scene("desk_ellipsoids");
  ASSERT_EQ(two.primitives.size(), desk.primitives.size() + 1);
  for (std::size_t i = 0; i < desk.primitives.size(); ++i) {
    const PrimitiveSpec &a = desk.primitives[i], &b = two.primitives[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.type, b.type) << a.name;
    EXPECT_TRUE(a.T_world_primitive.isApprox(b.T_world_primitive, 1e-12)) << a.name;
    EXPECT_EQ(a.size, b.size) << a.name;
    EXPECT_EQ(a.radius, b.radius) << a.name;
    EXPECT_EQ(a.radii, b.radii) << a.name;
    EXPECT_EQ(a.length, b.length) << a.name;
    EXPECT_EQ(a.half_angle, b.half_angle) << a.name;
  }
  const PrimitiveSpec& stone = two.primitives.back();
  EXPECT_EQ(stone.type, PrimitiveType::kEllipsoid);
  // Resting on the desk top (z = 0.7 m).
  EXPECT_NEAR(stone.T_world_primitive.translation().z() - stone.radii.z(), 0.7, 1e-9);
  EXPECT_EQ(two.camera.fx, desk.camera.fx);
  EXPECT_NO_THROW(buildSurfaces(two));
}

}  // namespace
}  // namespace quadric_slam
