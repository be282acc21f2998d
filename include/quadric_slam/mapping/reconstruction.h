// Reconstruction of the map's surfaces (the paper's Section V, Figs. 1 and 5): the supporting
// points of a landmark's observations, drawn projected onto the landmark's current surface
// estimate.
//
// Points are stored projected onto the landmark's surface, in its own quadric frame (as estimated
// when they were added), one per cell of the surface, so memory is bounded by the observed area
// rather than by the number of frames or the depth noise, and a landmark whose estimate moves
// carries its points with it: cloud() places every point with the current T_map_quadric and
// projects it onto the current surface (geometry/surface_distance.h).
// The cells are in coordinates of the surface itself, voxel_size on a side: a plane's in-plane
// coordinates; azimuth and height along the axis for cylinders and cones, azimuth and elevation
// for spheres, at angular steps set by the landmark's radius (cone: half angle) when its first
// point came. So a patch seen again keeps its cell while the estimate converges (a radius that
// grows by a centimetre, a plane merged with a parallel estimate of itself), where cells of the
// quadric frame's 3D grid would give it a second layer of points each time. General quadrics use
// the frame's 3D voxels. Each point may carry the RGB colour of the pixel it came from
// (frontend/support_colours.h), packed 0xAARRGGBB, alpha 0 = uncoloured.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <unordered_set>
#include <vector>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/surface_distance.h"

namespace quadric_slam {

class QuadricReconstruction {
 public:
  struct Params {
    double voxel_size = 0.01;              // m: at most one point per cell of a surface, > 0
    int max_points_per_landmark = 100000;  // further points of a landmark are dropped, >= 1
    // Over the whole map, >= 1: memory stays bounded (about 100 bytes a point) even where the
    // observed area is not, e.g. a map grown over a whole building. Once full, further points
    // are dropped (full() says so); the landmarks themselves are still estimated and published.
    int max_points = 3000000;
    double max_surface_distance = 0.05;  // m: points farther from the surface are outliers, > 0
    void validate() const;  // throws std::invalid_argument naming the field and its range
  };

  QuadricReconstruction();
  explicit QuadricReconstruction(const Params& params);

  // Adds the supporting points (camera frame) of landmark `id` seen from T_map_camera, given the
  // landmark's current estimate in the map frame. Points that are not finite, or farther than
  // max_surface_distance from the surface (exact distance for the classes of revolution and planes,
  // first-order for general quadrics), are skipped, as are points in an occupied voxel and points
  // beyond max_points_per_landmark or max_points. Returns how many points were stored.
  // colours_rgba: one packed colour per point (alpha 0 = none), or empty for uncoloured points; a
  // voxel keeps the colour of the point that occupied it first.
  int addPoints(int id, const QuadricModel& landmark_map, const Eigen::Isometry3d& T_map_camera,
                const std::vector<Eigen::Vector3f>& points_camera,
                const std::vector<std::uint32_t>& colours_rgba = {});

  // Landmark `from` was merged into `to` (mapping/landmark_merger.h): its points join `to`'s,
  // re-expressed with T_to_from (from's quadric frame in to's), one per voxel of to's frame and
  // within max_points_per_landmark (a merge never adds points to the map, so max_points holds);
  // `from` has no points afterwards.
  void moveLandmark(int from, int to, const Eigen::Isometry3d& T_to_from);
  void removeLandmark(int id);
  void clear();

  std::size_t size() const;        // points stored over all landmarks
  bool full() const;               // size() reached max_points: new points are dropped
  std::size_t size(int id) const;  // points stored for one landmark (0 when unknown)

  // The stored points of every landmark in `landmarks_map` (id -> current estimate, map frame),
  // placed with that estimate and projected onto its surface, labelled with the landmark id, rgba
  // = the point's colour (alpha 0: uncoloured, the caller colours it per landmark).
  // Landmarks without points, and points whose projection fails (a general quadric far from
  // convergence), are left out.
  pcl::PointCloud<pcl::PointXYZRGBL> cloud(const std::map<int, QuadricModel>& landmarks_map) const;

 private:
  struct LandmarkPoints {
    QuadricClass quadric_class = QuadricClass::kGeneral;
    // Radius (sphere, cylinder; m) or half angle (cone; rad) when the first point came: it sets
    // the angular step of the cells for the landmark's whole life.
    double reference_size = 0.0;
    std::unordered_set<std::uint64_t> voxels;  // packed integer cell coordinates (cellKey)
    std::vector<Eigen::Vector3f> points_quadric;
    // rgba[i] is the colour of points_quadric[i]; it may be shorter (points beyond its end are
    // uncoloured), so code that appends points without colours keeps them aligned.
    std::vector<std::uint32_t> rgba;
  };
  // The cell of a surface point (quadric frame) of a landmark's stored points.
  std::uint64_t cellKey(const LandmarkPoints& stored, const Eigen::Vector3d& p_quadric) const;

  Params params_;
  SurfaceProjector projector_;
  std::map<int, LandmarkPoints> landmarks_;
  std::size_t total_points_ = 0;  // size(), kept as points come and go
};

}  // namespace quadric_slam
