// A motion guess between two frames from their quadric observations alone, for steps too large for
// ICP's basin (frames far apart in time, a busy pipeline that drops frames).
//
// The two frames' surfaces are aligned by geometry/surface_matcher.h, which uses what does not
// depend on the pose (the angle between two surfaces' directions, radii, cone angles): a pair of
// non-parallel directions seen in both frames gives a rotation, the pair's surfaces a line of
// translations, and each other compatible pair a translation on it, scored by the surfaces that
// then coincide. The proposal most surfaces agree with is refined by least squares over all of
// them and returned.
//
// Hypotheses are confined to rotations within max_rotation_from_prior of the prior (the
// constant-velocity prediction), which removes the symmetric solutions of a box-like room (a
// 90-degree turn maps its walls onto each other as well as the true motion does); the prior also
// fills a translation direction the surfaces leave free, and decides between proposals of equal
// support.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "quadric_slam/geometry/surface_matcher.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

struct QuadricMotionGuess {
  bool found = false;
  // Pose of the current camera in the reference camera's frame.
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
  int supporting_surfaces = 0;  // current observations consistent with the guess
  int usable_surfaces = 0;      // current observations that could have been matched
  double support_weight = 0.0;  // sum over the supporting observations of sqrt(num_points)
  bool translation_from_prior = false;  // the data left one direction free: the prior filled it
  std::string message;                  // why nothing was found (empty when found)
};

class QuadricMotionGuesser {
 public:
  struct Params {
    // Two directions agree when the angle between them is below this (rad). (0, 0.5]
    double max_angle_difference = 0.06;
    // Plane offsets, centres and axis distances agree within this (m). (0, 1]
    double max_offset_difference = 0.04;
    // Radii agree within this fraction of the larger one; cone half-angles within
    // max_angle_difference. (0, 1)
    double max_radius_fraction = 0.15;
    // Directions at least this far from parallel define a rotation (rad). (0, pi/2)
    double min_pair_angle = 0.35;
    // Planes with fewer supporting points are not used. >= 0
    int min_plane_points = 500;
    // Only the largest observations of each frame are used to make hypotheses (cost: the square
    // of this times the square of this). [2, 64]
    int max_direction_features = 12;
    // Hypotheses whose rotation is further than this from the prior's are not considered (rad).
    // (0, pi]
    double max_rotation_from_prior = 0.7;
    // ... nor translations further than this from the prior's (m). > 0
    double max_translation_from_prior = 1.0;
    // A guess needs this many current surfaces that agree with it (the two that define the
    // rotation count). [2, 1000]
    int min_supporting_surfaces = 3;
    void validate() const;  // throws std::invalid_argument naming the field and its range
  };

  QuadricMotionGuesser();
  explicit QuadricMotionGuesser(const Params& params);

  // reference and current: the observations of the two frames, each in its own camera frame.
  // T_reference_current_prior: the predicted motion (e.g. constant velocity); it limits the search
  // (see the header comment) and fills a translation direction the surfaces leave free.
  QuadricMotionGuess guess(const std::vector<QuadricMeasurement>& reference,
                           const std::vector<QuadricMeasurement>& current,
                           const Eigen::Isometry3d& T_reference_current_prior) const;

  const Params& params() const { return params_; }

 private:
  Params params_;
  SurfaceMatcher matcher_;
};

}  // namespace quadric_slam
