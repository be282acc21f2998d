// Point-to-quadric distances and projection onto the surface (for fitting residuals, inlier tests
// and the reconstruction). All points are in the frame the quadric lives in (metres).
#pragma once

#include <Eigen/Core>

#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

// f(p) = (S p_Q)^T D(sigma_1..3) (S p_Q) + sigma_4 with p_Q = T_frame_quadric^-1 p: the algebraic
// value p~^T Q p~ of eqs. 2 and 4 (zero on the surface).
double algebraicDistance(const QuadricModel& quadric, const Eigen::Vector3d& p);
// grad f in the quadric's frame: 2 R S D(sigma_1..3) S p_Q.
Eigen::Vector3d algebraicGradient(const QuadricModel& quadric, const Eigen::Vector3d& p);
// f(p) and |grad f(p)| at once, with a single change of frame (the gradient's norm needs no rotation
// back): what a Sampson distance f / |grad f| needs per point, at a fraction of the two calls above.
struct AlgebraicValue {
  double value = 0.0;          // f(p)
  double gradient_norm = 0.0;  // |grad f(p)|
};
AlgebraicValue algebraicValueAndSlope(const QuadricModel& quadric, const Eigen::Vector3d& p);
// First-order geometric distance |f| / |grad f| (infinite where grad f = 0 off the surface; 0 on
// it). Exact to first order near a surface whose f vanishes to first order; for the double plane
// (alpha x)^2 = 0, f vanishes to second order and this gives half the true distance.
double firstOrderDistance(const QuadricModel& quadric, const Eigen::Vector3d& p);
// Exact Euclidean distance for plane, sphere, cylinder and (double) cone; throws
// std::invalid_argument for kGeneral.
double exactDistance(const QuadricModel& quadric, const Eigen::Vector3d& p);
// Distance from the surface for any class: exact for plane, sphere, cylinder and cone, the
// first-order (Sampson) distance for general quadrics.
double surfaceDistance(const QuadricModel& quadric, const Eigen::Vector3d& p);

// Projection of a point onto the surface. Exact closest point for plane, sphere, cylinder and
// cone; for a general quadric, Newton steps along the gradient p <- p - f grad f / |grad f|^2
// (a nearby surface point, first-order closest).
class SurfaceProjector {
 public:
  struct Params {
    int max_iterations = 30;   // Newton steps for general quadrics, >= 1
    double tolerance = 1e-12;  // stop when |f| / |grad f| < tolerance (m), > 0
    void validate() const;     // throws std::invalid_argument naming the field and its range
  };
  SurfaceProjector();
  explicit SurfaceProjector(const Params& params);
  // Throws std::invalid_argument when a general quadric's projection does not converge.
  Eigen::Vector3d project(const QuadricModel& quadric, const Eigen::Vector3d& p) const;

 private:
  Params params_;
};

}  // namespace quadric_slam
