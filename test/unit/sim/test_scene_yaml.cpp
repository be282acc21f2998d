#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/surfaces.h"

using namespace quadric_slam;

namespace {

const char* kMinimal = R"(
name: mini
centre_of_interest: [0, 0, 1]
primitives:
  - name: ball
    type: sphere
    position: [0, 0, 2]
    radius: 0.2
)";

// The error message of parsing `text`, or "" when it parses.
std::string errorOf(const std::string& text) {
  try {
    parseSceneYaml(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

void expectError(const std::string& text, const std::string& needle) {
  const std::string error = errorOf(text);
  EXPECT_NE(error.find(needle), std::string::npos)
      << "error '" << error << "' lacks '" << needle << "'";
}

}  // namespace

TEST(SceneYaml, MinimalSceneUsesDefaults) {
  const Scene s = parseSceneYaml(kMinimal);
  EXPECT_EQ(s.name, "mini");
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.fx, 525.0);
  EXPECT_EQ(s.camera.cy, 239.5);
  EXPECT_EQ(s.rate, 30.0);
  ASSERT_EQ(s.primitives.size(), 1u);
  EXPECT_EQ(s.primitives[0].type, PrimitiveType::kSphere);
  EXPECT_EQ(s.primitives[0].radius, 0.2);
  EXPECT_EQ(s.depth.max_range, 4.5);
}

TEST(SceneYaml, ErrorsNameTheBadKey) {
  const std::string base = kMinimal;
  expectError(base + "    colour: [1, 0]\n", "'colour' must be a list of 3");
  expectError(base + "    colour: [1, 0, 2]\n", "'colour' must be RGB in [0, 1]");
  expectError(base + "    radiuss: 0.3\n", "unknown key 'radiuss'");
  expectError(base + "    texture: {type: stripes}\n", "'type' must be none, checker or noise");
  expectError(base + "  - {name: can, type: cylinder, position: [0, 0, 1], radius: 0.1}\n",
              "primitives[1] (can): missing key 'length'");
  expectError(base + "  - {name: x, type: torus, position: [0, 0, 1]}\n",
              "unknown primitive type 'torus'");
  expectError(base + "  - {name: ball, type: sphere, position: [0, 0, 1], radius: 0.1}\n",
              "duplicate name 'ball'");
  expectError(base + "  - {name: s, type: sphere, position: [0, 0, 1], radius: -1}\n",
              "primitives[1] (s): radius must be > 0");
  expectError(base +
                  "  - {name: r, type: rectangle, position: [0, 0, 1], size: [1, 2], "
                  "normal: [0, 0, 1], rpy: [0, 0, 0]}\n",
              "either 'rpy' or 'normal'");
  expectError(base + "  - {name: r, type: rectangle, position: [0, 0, 1], size: [1, 2, 3]}\n",
              "'size' must be a list of 2");
  expectError(base + "  - {name: c, type: sphere, position: [0, 0, 1], radius: abc}\n",
              "'radius' must be a number");
  expectError(base + "camera: {fx: -1}\n", "camera: ");
  expectError(base + "camera: {focal: 500}\n", "camera: unknown key 'focal'");
  expectError(base + "depth_noise: {max_range: 0.1}\n", "max_range");
  expectError(base + "handheld: {distance: 0}\n", "handheld: ");
  expectError(base + "colour: [1, 1, 1]\n", "unknown key 'colour'");
  expectError("name: x\nprimitives: []\ncentre_of_interest: [0, 0, 0]\n",
              "'primitives' must be a non-empty list");
  expectError("name: x\nprimitives: [{name: a, type: sphere, position: [0, 0, 0], radius: 1}]\n",
              "missing key 'centre_of_interest'");
  expectError("name: [x\n", "bad YAML");
  EXPECT_EQ(errorOf(base), "");
}

TEST(SceneYaml, OrientationFromNormalOrAxis) {
  const Scene s = parseSceneYaml(std::string(kMinimal) + R"(
  - {name: floor, type: rectangle, position: [0, 0, 0], normal: [0, 0, 2], size: [4, 3]}
  - {name: can, type: cylinder, position: [1, 0, 0], axis: [1, 0, 0], radius: 0.1, length: 0.3}
  - {name: tilted, type: box, position: [1, 0, 0], rpy: [0.1, 0.2, 0.3], size: [1, 1, 1]}
)");
  ASSERT_EQ(s.primitives.size(), 4u);
  const Eigen::Matrix3d floor = s.primitives[1].T_world_primitive.linear();
  EXPECT_NEAR((floor.col(0) - Eigen::Vector3d::UnitZ()).norm(), 0, 1e-12);  // normal = local x
  EXPECT_NEAR(floor.determinant(), 1.0, 1e-12);
  EXPECT_EQ(s.primitives[1].size, Eigen::Vector3d(0, 4, 3));
  const Eigen::Matrix3d can = s.primitives[2].T_world_primitive.linear();
  EXPECT_NEAR((can.col(2) - Eigen::Vector3d::UnitX()).norm(), 0, 1e-12);  // axis = local z
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_TRUE(s.primitives[3].T_world_primitive.linear().isApprox(expected, 1e-12));
}

TEST(SceneYaml, RoundTripKeepsEveryField) {
  const std::string path = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/desk.yaml";
  const Scene a = readSceneYaml(path);
  const Scene b = parseSceneYaml(sceneYamlString(a));
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.camera.width, a.camera.width);
  EXPECT_EQ(b.camera.fx, a.camera.fx);
  EXPECT_EQ(b.rate, a.rate);
  EXPECT_EQ(b.centre_of_interest, a.centre_of_interest);
  EXPECT_EQ(b.background, a.background);
  EXPECT_EQ(b.handheld.azimuth, a.handheld.azimuth);
  EXPECT_EQ(b.handheld.start_stamp, a.handheld.start_stamp);
  EXPECT_EQ(b.depth.edge_dropout_px, a.depth.edge_dropout_px);
  EXPECT_EQ(b.depth.sigma_quadratic, a.depth.sigma_quadratic);
  EXPECT_EQ(b.depth.sigma_scale, a.depth.sigma_scale);
  EXPECT_EQ(b.depth.distortion_r2, a.depth.distortion_r2);
  EXPECT_EQ(b.depth.pattern_amplitude, a.depth.pattern_amplitude);
  EXPECT_EQ(b.depth.pattern_seed, a.depth.pattern_seed);
  EXPECT_EQ(b.depth.correlated_fraction, a.depth.correlated_fraction);
  EXPECT_EQ(b.depth.correlation_px, a.depth.correlation_px);
  EXPECT_EQ(b.depth.projector_side, a.depth.projector_side);
  ASSERT_EQ(b.primitives.size(), a.primitives.size());
  for (std::size_t i = 0; i < a.primitives.size(); ++i) {
    const PrimitiveSpec &p = a.primitives[i], &q = b.primitives[i];
    EXPECT_EQ(q.name, p.name);
    EXPECT_EQ(q.type, p.type);
    EXPECT_TRUE(q.T_world_primitive.isApprox(p.T_world_primitive, 1e-12)) << p.name;
    EXPECT_EQ(q.radius, p.radius);
    EXPECT_EQ(q.capped, p.capped);
    EXPECT_EQ(q.half_angle, p.half_angle);
    EXPECT_EQ(q.z_max, p.z_max);
    EXPECT_EQ(q.radii, p.radii);
    if (p.type == PrimitiveType::kRectangle || p.type == PrimitiveType::kBox) {
      EXPECT_EQ(q.size, p.size) << p.name;
    }
    EXPECT_EQ(q.material.colour, p.material.colour);
    EXPECT_EQ(q.material.texture, p.material.texture);
    EXPECT_EQ(q.material.colour2, p.material.colour2);
    EXPECT_EQ(q.material.texture_scale, p.material.texture_scale);
  }
}

TEST(SceneYaml, ShippedScenesLoadAndHaveTheDeskObjects) {
  for (const char* name : {"desk", "desk_fr2"}) {
    const std::string path =
        std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/" + name + ".yaml";
    const Scene scene = readSceneYaml(path);
    int spheres = 0, cylinders = 0, cones = 0, boxes = 0, rectangles = 0;
    for (const PrimitiveSpec& p : scene.primitives) {
      spheres += p.type == PrimitiveType::kSphere;
      cylinders += p.type == PrimitiveType::kCylinder;
      cones += p.type == PrimitiveType::kCone;
      boxes += p.type == PrimitiveType::kBox;
      rectangles += p.type == PrimitiveType::kRectangle;
    }
    EXPECT_GE(spheres, 1) << name;
    EXPECT_GE(cylinders, 2) << name;
    EXPECT_GE(cones, 1) << name;
    EXPECT_GE(boxes, 1) << name;
    EXPECT_GE(rectangles, 3) << name;  // floor and two walls
    EXPECT_NO_THROW(buildSurfaces(scene)) << name;
  }
}

TEST(SceneYaml, ReadErrorsNameTheFile) {
  try {
    readSceneYaml("/nonexistent/scene.yaml");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.yaml"), std::string::npos);
  }
}

TEST(SceneYaml, DepthModelPresetThenOverrides) {
  const std::string base = kMinimal;
  // Default: the harsh model.
  EXPECT_EQ(parseSceneYaml(base).depth.correlated_fraction,
            KinectDepthModel::harshParams().correlated_fraction);
  const Scene nguyen = parseSceneYaml(base + "depth_noise:\n  model: nguyen\n");
  EXPECT_EQ(nguyen.depth.sigma_scale, 1.0);
  EXPECT_EQ(nguyen.depth.correlated_fraction, 0.0);
  EXPECT_EQ(nguyen.depth.distortion_r2, 0.0);
  EXPECT_EQ(nguyen.depth.projector_side, 0);
  const Scene tuned = parseSceneYaml(
      base + "depth_noise:\n  model: nguyen\n  sigma_scale: 1.5\n  correlation_px: 2.5\n");
  EXPECT_EQ(tuned.depth.sigma_scale, 1.5);
  EXPECT_EQ(tuned.depth.correlation_px, 2.5);
  EXPECT_EQ(tuned.depth.correlated_fraction, 0.0);
  expectError(base + "depth_noise:\n  model: gentle\n", "'model'");
  expectError(base + "depth_noise:\n  correlated_fraction: 2\n", "correlated_fraction");
  expectError(base + "depth_noise:\n  projector_side: 0.5\n", "projector_side");
}

TEST(SceneYaml, RoomSceneLoads) {
  const Scene room =
      readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/room.yaml");
  EXPECT_EQ(room.name, "room");
  EXPECT_GE(room.primitives.size(), 10u);
  EXPECT_EQ(room.depth.sigma_scale, KinectDepthModel::harshParams().sigma_scale);
}
