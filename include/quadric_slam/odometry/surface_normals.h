// The ICP's normals from the frame's fitted surfaces (issue 12).
//
// Point-to-plane ICP takes its normals from the normal estimator, which fits a small window
// around each pixel. Beyond 2 m a Kinect v1's depth noise tilts such normals by 10-25 degrees,
// and those random tilts put information into the ICP's normal equations along every surface
// (a far floor seems to hold the camera along itself) that hides how little the real structure
// (a box face, a ball) holds the weak directions: the degeneracy test must then either trust the
// noise or discard the structure with it. The segmentation has already fitted every surface to
// thousands of points; its normal at a point is a far better estimate than the window's. So
// before tracking, every point that lies on one of the frame's observed surfaces (within its
// bounding box in the image, within max_distance_rms of the fit's RMS of the surface, and with its
// own normal within max_angle of the surface's) takes the surface's normal, oriented towards the
// camera. Points on no surface, and points without a normal, keep theirs.
//
// Needs only the observations (a QuadricObservationArray carries everything used), so the
// offline pipeline and the odometry nodelet apply it alike.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vector>

#include "quadric_slam/types/observation.h"

namespace quadric_slam {

struct SurfaceNormalParams {
  // false: the cloud's normals are used as they are.
  bool enabled = true;
  // A point is on a surface when its distance from it is at most this many times the fit's RMS
  // distance (QuadricMeasurement::fit_rms), (0, 100] ...
  double max_distance_rms = 3.0;
  // ... or at most this distance, whichever is larger (m), [0, 1]: a fit over near points has a
  // millimetre RMS that its own far edge exceeds.
  double min_max_distance = 0.01;
  // ... and its estimated normal is within this angle of the surface's (rad), (0, pi/2].
  double max_angle = 0.7854;
  // Only points at least this deep take a surface's normal (m), [0, 100]: nearer, the estimator's
  // window keeps its normals' noise small and they follow the surface's real shape.
  double min_depth = 0.0;

  // Throws std::invalid_argument naming the bad field and its allowed range.
  void validate() const;
};

// Replaces the normals of the points on the observed surfaces (see above); where two surfaces
// claim a point, the nearer one wins. observations are in the cloud's (camera) frame, their
// image_roi in the cloud's grid. Returns the number of points whose normal was replaced. Does
// nothing (returns 0) when params.enabled is false. Only every stride-th point in u and v (from
// (0, 0)) is looked at: the ICP reads no other (OdometryTracker::adoptSurfaceNormals). Throws
// std::invalid_argument when stride < 1. scratch, when given, keeps the per-point buffers from one
// call to the next (a frame's grid is the same size every time).
struct SurfaceNormalScratch {
  std::vector<float> claimed_distance;  // distance to the surface that claimed the point
  std::vector<int> claimed_by;          // that surface's index, -1: none
};
int adoptSurfaceNormals(const std::vector<QuadricMeasurement>& observations,
                        const SurfaceNormalParams& params, int stride,
                        pcl::PointCloud<pcl::PointNormal>& cloud,
                        SurfaceNormalScratch* scratch = nullptr);

}  // namespace quadric_slam
