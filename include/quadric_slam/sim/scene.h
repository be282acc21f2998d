// What a synthetic scene is made of: primitives with a pose, dimensions and a material, the
// camera, the centre of interest for the hand-held motion and the depth model. Plain data; the
// YAML form lives in io/scene.h, the ray-castable surfaces in sim/surfaces.h.
#pragma once

#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "quadric_slam/types/camera_intrinsics.h"
#include "quadric_slam/sim/kinect_depth_model.h"
#include "quadric_slam/sim/trajectory.h"

namespace quadric_slam {

enum class Texture { kNone, kChecker, kNoise };

struct Material {
  Eigen::Vector3d colour = Eigen::Vector3d(0.7, 0.7, 0.7);  // RGB in [0, 1]
  Texture texture = Texture::kNone;
  Eigen::Vector3d colour2 = Eigen::Vector3d(0.3, 0.3, 0.3);  // second texture colour, RGB [0, 1]
  double texture_scale = 0.1;                                // checker cell / noise cell size (m)
};

enum class PrimitiveType { kRectangle, kBox, kSphere, kCylinder, kCone, kEllipsoid };

// Lower-case names used in scene files: rectangle, box, sphere, cylinder, cone, ellipsoid.
std::string toString(PrimitiveType type);
// Throws std::invalid_argument for an unknown name.
PrimitiveType primitiveTypeFromString(const std::string& name);

// One object of a scene. T_world_primitive places the primitive's own frame:
//   rectangle: centre at the origin, normal = local x, sides size.y() x size.z() along local y, z;
//   box:       centre at the origin, edges size.x/y/z along local x/y/z (six rectangle faces);
//   sphere:    centre at the origin, `radius`;
//   cylinder:  axis = local z, centre of the axis segment at the origin, `radius`, `length`,
//              discs at both ends when `capped`;
//   cone:      apex at the origin, axis = local z (into the opening), `half_angle`, surface
//              between z_min and z_max (a truncated cone when z_min > 0), never capped;
//   ellipsoid: centre at the origin, semi-axes `radii` along local x/y/z.
struct PrimitiveSpec {
  std::string name;
  PrimitiveType type = PrimitiveType::kSphere;
  Eigen::Isometry3d T_world_primitive = Eigen::Isometry3d::Identity();
  Eigen::Vector3d size = Eigen::Vector3d::Ones();   // rectangle (y, z used), box (m)
  double radius = 0.1;                              // sphere, cylinder (m)
  double length = 0.2;                              // cylinder (m)
  bool capped = false;                              // cylinder
  double half_angle = 0.5;                          // cone (rad)
  double z_min = 0.0, z_max = 0.2;                  // cone (m from the apex)
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();  // ellipsoid (m)
  Material material;

  // Empty when the dimensions are usable, else a sentence naming the bad field.
  std::string problem() const;
};

struct Scene {
  std::string name = "scene";  // sequence name (the bag is <name>.bag)
  CameraIntrinsics camera{525.0, 525.0, 319.5, 239.5, 640, 480};
  double rate = 30.0;                                             // frames per second (Hz)
  Eigen::Vector3d centre_of_interest = Eigen::Vector3d::Zero();   // world (m)
  Eigen::Vector3d background = Eigen::Vector3d(0.55, 0.6, 0.65);  // RGB [0, 1] where nothing is hit
  HandheldTrajectory::Params handheld;
  KinectDepthModel::Params depth;
  std::vector<PrimitiveSpec> primitives;
};

}  // namespace quadric_slam
