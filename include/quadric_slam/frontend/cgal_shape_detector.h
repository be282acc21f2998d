// A thin wrapper around CGAL 5.5's Efficient RANSAC (Shape_detection; Schnabel et al. 2007) on
// points + normals: which shape types, its parameters, and the shapes as PrimitiveShape with the
// indices of their assigned points.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "quadric_slam/frontend/primitive_shape.h"

namespace quadric_slam {

class CgalShapeDetector {
 public:
  struct Params {
    bool planes = false, spheres = true, cylinders = true, cones = true;
    double probability = 0.05;       // chance of missing the largest candidate, (0, 1)
    int min_points = 60;             // minimum support (points), >= 4
    double epsilon = 0.008;          // max point-to-surface distance (m), > 0
    double cluster_epsilon = 0.03;   // max spacing of connected points (m), > 0
    double normal_threshold = 0.85;  // min |cos| between point and surface normals, (0, 1)
    unsigned int random_seed = 1;    // CGAL's random generator is seeded with this

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Shape {
    PrimitiveShape shape;      // cone axis oriented into the opening (towards the inliers)
    std::vector<int> indices;  // into the input vectors
  };

  explicit CgalShapeDetector(const Params& params);

  // points and normals have the same length; normals unit (sign free). Shapes in detection order.
  std::vector<Shape> detect(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector3d>& normals) const;

 private:
  Params params_;
};

}  // namespace quadric_slam
