// Least-squares refinement of a primitive on its supporting points: Levenberg-Marquardt on the
// geometric distances in the class's minimal coordinates (Table II, see primitive_shape.h), and the
// covariance of the fit in those coordinates.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "quadric_slam/frontend/primitive_shape.h"

namespace quadric_slam {

class ShapeRefiner {
 public:
  struct Params {
    // Levenberg-Marquardt iterations at most, [1, 100]. Default 10.
    int max_iterations = 10;
    // Stop when the step's relative cost decrease is below this, (0, 1). Default 1e-6.
    double relative_tolerance = 1e-6;
    // Or when a step lowered the cost by less than this many residual variances: the fit is then
    // within about sqrt(this) standard deviations of its optimum (convergedWithinNoise,
    // levenberg_marquardt.h); [0, 1], 0 = off. Default 0.1.
    double variance_tolerance = 0.1;
    // Points used at most (an even sub-sample beyond this; the covariance is scaled back to all
    // points), [10, 1e7]. Default 1000.
    int max_points = 1000;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Result {
    PrimitiveShape shape;
    // Covariance in the minimal coordinates of primitive_shape.h (minimalIndices order):
    // sigma^2 (J^T J)^-1 with sigma^2 the residual variance, J the Jacobian of the distances over
    // all points (m, rad, 1/m).
    Eigen::MatrixXd covariance;
    double rms = 0.0;  // RMS geometric distance of the points to the refined surface (m)
    bool ok = false;   // false when too few points or a degenerate normal matrix
  };

  ShapeRefiner() : ShapeRefiner(Params()) {}
  explicit ShapeRefiner(const Params& params);

  Result refine(const PrimitiveShape& initial, const std::vector<Eigen::Vector3d>& points) const;
  // The covariance and RMS of shape on points without iterating (for an exact least-squares
  // solution such as the PCA plane).
  Result evaluate(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points) const;

 private:
  Result refineUnchecked(const PrimitiveShape& initial,
                         const std::vector<Eigen::Vector3d>& points) const;

  Params params_;
};

// Jacobian (points x minimalDimension) of the signed distances of points to shape with respect to
// the minimal perturbation of primitive_shape.h (perturb, Table II order) at zero. Plane, sphere,
// cylinder, cone: analytic, per point PrimitiveShape::distanceGradient chained with the 7 x k
// derivative of (point, direction, size) in the perturbation (closed form at zero); general: the
// first-order distance's gradient in the 9 coordinates (pose step and scales), closed form too.
// Throws std::invalid_argument when the shape has no core quadric.
Eigen::MatrixXd distanceJacobian(const PrimitiveShape& shape,
                                 const std::vector<Eigen::Vector3d>& points);

// At most max_points of all_points, evenly spaced in their order (all of them when there are no
// more): on a segment's pixels in image order, an even spread over the surface patch.
std::vector<Eigen::Vector3d> evenSubsample(const std::vector<Eigen::Vector3d>& all_points,
                                           int max_points);

// Total least-squares plane through points (PCA); normal oriented towards the origin (the camera)
// and point = centroid. Requires >= 3 points.
PrimitiveShape fitPlane(const std::vector<Eigen::Vector3d>& points);
// Algebraic sphere fit (|p|^2 + a.p + b = 0 in least squares); requires >= 4 points.
PrimitiveShape fitSphereAlgebraic(const std::vector<Eigen::Vector3d>& points);
// RMS of the distances of points to shape (m).
double rmsDistance(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points);

}  // namespace quadric_slam
