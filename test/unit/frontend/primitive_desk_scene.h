// The frontend tests' rendered scene (sim/primitive_scene_renderer.h): floor 0.8 m below the
// camera, a wall at 2.5 m, and a sphere, an upright cylinder (axis point at its base, far from the
// visible middle) and an upside-down cone (apex up) standing on the floor at 1.5-1.8 m;
// T_camera_scene tilts and moves the whole scene.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "quadric_slam/sim/primitive_scene_renderer.h"

namespace quadric_slam {
namespace test {

inline std::vector<ScenePrimitive> primitiveDeskScene(
    const Eigen::Isometry3d& T_camera_scene = Eigen::Isometry3d::Identity()) {
  std::vector<ScenePrimitive> scene(5);
  scene[0].shape = PrimitiveShape::plane(Eigen::Vector3d(0, -1, 0), -0.8);
  scene[1].shape = PrimitiveShape::plane(Eigen::Vector3d(0, 0, -1), -2.5);
  scene[2].shape = PrimitiveShape::sphere(Eigen::Vector3d(-0.45, 0.25, 1.6), 0.15);
  scene[3].shape =
      PrimitiveShape::cylinder(Eigen::Vector3d(0.05, 0.8, 1.8), Eigen::Vector3d(0, -1, 0), 0.09);
  scene[3].axis_min = 0.0;
  scene[3].axis_max = 0.55;
  scene[4].shape =
      PrimitiveShape::cone(Eigen::Vector3d(0.55, 0.3, 1.5), Eigen::Vector3d(0, 1, 0), 0.4);
  scene[4].axis_min = 0.1;
  scene[4].axis_max = 0.5;
  for (auto& p : scene)
    p.shape = p.shape.transformed(T_camera_scene);
  return scene;
}

}  // namespace test
}  // namespace quadric_slam
