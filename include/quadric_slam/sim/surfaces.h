// The ray-castable surfaces of a scene: each primitive expands into surfaces with their own id
// (a box into six rectangles, a capped cylinder into its lateral surface and two discs), each a
// bounded piece of one quadric of the map schema (io/map_yaml.h).
#pragma once

#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/sim/scene.h"

namespace quadric_slam {

enum class SurfaceKind { kRectangle, kDisc, kSphere, kCylinder, kCone, kEllipsoid };

// Local frame conventions follow the quadric's (msg/QuadricSurface.msg): plane normal = local x
// (rectangle and disc), cylinder and cone axis = local z, cone apex at the origin.
class Surface {
 public:
  // dims: rectangle (unused, half y, half z); disc (unused, radius, unused); sphere (r, r, r);
  // cylinder (radius, radius, half length); cone (tan(half_angle), z_min, z_max);
  // ellipsoid (semi-axes).
  Surface(int id, std::string name, SurfaceKind kind, const Eigen::Isometry3d& T_world_surface,
          const Eigen::Vector3d& dims, const Material& material, bool closed_face = false);

  int id() const { return id_; }
  const std::string& name() const { return name_; }
  SurfaceKind kind() const { return kind_; }
  const Eigen::Isometry3d& pose() const { return T_world_surface_; }
  const Eigen::Vector3d& dims() const { return dims_; }
  const Material& material() const { return material_; }
  // True for a face of a closed solid (box face, cylinder cap) with its normal (local x)
  // pointing outwards: invisible from behind its plane, so the renderer may skip it there.
  bool closedFace() const { return closed_face_; }
  // False when this is a closed face whose outside is turned away from `viewpoint` (world).
  bool mayBeVisibleFrom(const Eigen::Vector3d& viewpoint) const;
  // A world-frame sphere enclosing the surface (for the early-out).
  const Eigen::Vector3d& boundCentre() const { return bound_centre_; }
  double boundRadius() const { return bound_radius_; }

  // Nearest intersection of the ray origin + t * direction (world frame; direction need not be
  // unit) with t in (t_min, t_max). On a hit sets t, the unit world normal and the local point.
  bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_min,
                 double t_max, double* t, Eigen::Vector3d* normal_world,
                 Eigen::Vector3d* point_local) const;

  // The same in the surface frame (hot path of the renderer): only the ray parameter.
  bool intersectLocal(const Eigen::Vector3d& origin_local, const Eigen::Vector3d& direction_local,
                      double t_min, double t_max, double* t) const;
  // Outward (unnormalised) normal at a local point on the surface.
  Eigen::Vector3d normalLocal(const Eigen::Vector3d& point_local) const;
  const Eigen::Isometry3d& inversePose() const { return T_surface_world_; }

  // RGB colour of the material at a local point (procedural texture, no shading).
  Eigen::Vector3d albedo(const Eigen::Vector3d& point_local) const;

  // The quadric this surface lies on, in the map schema (id, class, pose, scale, shape;
  // observations left 0).
  MapFileQuadric toMapQuadric() const;

 private:
  int id_;
  std::string name_;
  SurfaceKind kind_;
  Eigen::Isometry3d T_world_surface_, T_surface_world_;
  Eigen::Vector3d dims_;
  Material material_;
  bool closed_face_ = false;
  Eigen::Vector3d bound_centre_;
  double bound_radius_ = 0.0;
};

// Expands the scene's primitives into surfaces with ids 1, 2, ... in scene order (box faces in
// the order +x, -x, +y, -y, +z, -z; capped cylinder: lateral, +z disc, -z disc). Names are the
// primitive's, with a suffix for faces (e.g. "desk/+z", "bin/-z"). Throws std::invalid_argument
// naming the primitive when its dimensions are unusable.
std::vector<Surface> buildSurfaces(const Scene& scene);

}  // namespace quadric_slam
