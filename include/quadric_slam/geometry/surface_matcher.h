// Rigid alignment of two sets of quadric surfaces without known correspondences: a frame's
// observations (camera frame) against a reference set (another frame's observations, or the map's
// landmarks in the map frame). Used without a pose prior to relocalise in a map
// (mapping/relocaliser.h) and with the constant-velocity prediction as a prior to guess the motion
// between two frames too far apart for ICP (odometry/quadric_motion_guess.h).
//
// It compares what does not depend on the pose: the class, radii and cone angles, and the angle
// between two surfaces' directions (plane normals, cylinder and cone axes). Each pair of
// non-parallel current directions and each reference pair with the same angle between them gives
// a rotation (Kabsch on the two directions and their cross product). Under that rotation the two
// defining surfaces fix the translation up to a line; every other compatible pair added as a
// third constraint proposes a translation (a plane by its offset n.t = d_r - d_c, a sphere centre
// or cone apex by R c + t = c_r, a cylinder by its axis across the axis), and each proposal is
// scored by the current surfaces that then coincide with a reference surface (sum of their
// weights). Returns the best proposal per distinct rotation and line of translations, best
// first, so that the caller can see how far the runner-up is behind (a box-like room has
// symmetric solutions: a 90-degree turn maps its walls onto each other).
//
// A rotation shared by parallel surfaces (a table top and the floor) is tried with each distinct
// line of translations its defining pair gives: deduplicating by the rotation alone can skip the
// one line that holds the truth.
//
// With a MotionPrior, hypotheses far from it are not considered (which removes the symmetric
// solutions), a translation direction the surfaces leave free is filled from the prior, and among
// proposals of equal support the one nearer the prior wins.
//
// A map's planes have no viewing side: a reference plane whose side is unknown enters twice, once
// per normal sign; a frame's planes are oriented towards its camera. Cylinder and cone axes are
// compared up to their sign (a cone's quadric is the double cone: which nappe its frame names may
// differ between a frame and the map).
//
// Cost: grows with the number of surfaces (squared, in both sets); about 130 ms for a frame
// against a kitchen map of about 90 landmarks (mostly parallel cabinet faces) on a loaded 2-core
// machine, 0.2 ms median for the odometry's frame-to-frame guess (bounded by its prior).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

struct MatchableSurface {
  enum class Kind { kPlane, kSphere, kCylinder, kCone };
  Kind kind = Kind::kPlane;
  int source = 0;  // index into the caller's list (observations, landmarks)
  // Plane normal, cylinder or cone axis (unit).
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // sphere centre, axis point, cone apex
  double offset = 0.0;  // plane: n.p = offset
  double size = 0.0;    // radius (m) or cone half-angle (rad)
  double weight = 1.0;  // how much the surface counts (e.g. sqrt of its supporting points)
};

// Appends the surface of `quadric` (plane, sphere, cylinder, cone; other classes and non-finite
// shapes are skipped). plane_towards_origin: the plane is seen from the frame's origin (a
// camera's observation), its normal is turned towards it; false (a map's plane): both signs are
// appended. Returns how many surfaces were appended (0, 1 or 2).
int appendMatchableSurface(const QuadricModel& quadric, int source, double weight,
                           bool plane_towards_origin, std::vector<MatchableSurface>* out);

struct SurfaceAlignment {
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
  // (current, reference) indices into the surface lists: each supporting current surface with the
  // reference surface it coincides with.
  std::vector<std::pair<int, int>> pairs;
  int supporting = 0;    // current surfaces that coincide with a reference surface
  double weight = 0.0;   // their summed weights
  // Smallest eigenvalue of the translation's normal equations over the largest (0: a direction
  // of the translation is left free by the supporting surfaces, e.g. only parallel planes and one
  // cylinder along them).
  double translation_conditioning = 0.0;
};

// What is known of the pose before matching (e.g. a constant-velocity prediction).
struct MotionPrior {
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
  double max_rotation = M_PI;  // rad: rotations further from the prior's are not considered
  double max_translation = std::numeric_limits<double>::infinity();  // m: nor translations
};

class SurfaceMatcher {
 public:
  struct Params {
    // Two directions agree when the angle between them is below this (rad). (0, 0.5]
    double max_angle_difference = 0.06;
    // Plane offsets, centres and axis distances agree within this (m). (0, 1]
    double max_offset_difference = 0.05;
    // Radii agree within this fraction of the larger one; cone half-angles within
    // max_angle_difference. (0, 1)
    double max_radius_fraction = 0.15;
    // Directions at least this far from parallel define a rotation (rad). (0, pi/2)
    double min_pair_angle = 0.35;
    // Only the largest surfaces of each set propose rotations: the cost grows with the square of
    // the current count times the square of the reference count. [2, 64]
    int max_current_features = 12;
    int max_reference_features = 24;
    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // An extra test of a candidate pair under a pose (e.g. that the surfaces' observed extents
  // overlap); empty: every geometrically compatible pair counts.
  using PairTest = std::function<bool(int current, int reference, const Eigen::Isometry3d&)>;

  SurfaceMatcher() : SurfaceMatcher(Params{}) {}
  explicit SurfaceMatcher(const Params& params);

  // The best alignment per distinct rotation and line of translations, best (largest weight)
  // first; empty when no pair of non-parallel directions appears in both sets (within the prior's
  // bounds, when one is given).
  std::vector<SurfaceAlignment> align(const std::vector<MatchableSurface>& reference,
                                      const std::vector<MatchableSurface>& current,
                                      const PairTest& test = {},
                                      const MotionPrior* prior = nullptr) const;

  // Least squares over the alignment's pairs (the rotation from all directions when they span
  // more than one, then the translation; a direction they leave free from the prior's
  // translation, or zero), re-scored with `test`.
  SurfaceAlignment refine(const std::vector<MatchableSurface>& reference,
                          const std::vector<MatchableSurface>& current,
                          const SurfaceAlignment& alignment, const PairTest& test = {},
                          const MotionPrior* prior = nullptr) const;

  const Params& params() const { return params_; }

 private:
  Params params_;
};

}  // namespace quadric_slam
