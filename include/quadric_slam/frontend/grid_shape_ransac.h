// RANSAC for planes, spheres, cylinders and cones on a sub-sample of an organized cloud's pixels,
// with the same parameters and output as CgalShapeDetector (Schnabel et al. 2007's scheme: minimal
// sets of points with normals, sampled near each other; the largest connected support kept; the
// search stops when a shape of min_points is unlikely to have been missed). What it uses that CGAL
// cannot know: the points lie on an image grid, so neighbours are found and supports connected
// through the grid instead of an octree; on the few hundred points of one image component it
// scores candidates directly (CGAL's octrees and lazy scoring pay off on far larger clouds).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "quadric_slam/frontend/cgal_shape_detector.h"

namespace quadric_slam {

class GridShapeRansac {
 public:
  // CgalShapeDetector's parameters, with the same meaning; cluster_epsilon is not used (a support
  // is connected through the grid: cells at most kClusterCells apart).
  using Params = CgalShapeDetector::Params;
  using Shape = CgalShapeDetector::Shape;

  // Grid cells at most this far apart (in u or v) are neighbours of a support: gaps of two cells
  // (points without depth, or off the surface by the noise) do not split a surface. At 3 m the
  // depth noise exceeds a typical epsilon and only about a third of a surface's points fit it.
  static constexpr int kClusterCells = 3;

  explicit GridShapeRansac(const Params& params);

  // points, normals (unit, sign free) and each point's cell on the sample grid (distinct cells)
  // have the same length. Shapes in the order found, each the best on the points the earlier
  // ones left.
  std::vector<Shape> detect(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector3d>& normals,
                            const std::vector<Eigen::Vector2i>& cells) const;

 private:
  Params params_;
};

}  // namespace quadric_slam
