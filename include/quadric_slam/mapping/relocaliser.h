// Relocalisation against the quadric map: where is the camera in `map`, from one frame's quadric
// observations and the map's landmarks alone, with no pose prior. Used after a loss of tracking
// (mapping/tracking_recovery.h), when the camera may have moved anywhere while the odometry was
// blind (a covered lens, a gap in a bag): the odometry's pose then associates with nothing.
//
// The frame's surfaces (camera frame, planes facing the camera) are aligned with the landmarks'
// (map frame, planes of either side) by geometry/surface_matcher.h; a candidate pair must also
// have overlapping observed extents under the pose (a wall's fragment must lie on the mapped part
// of that wall, grown by extent_margin), which removes most symmetric solutions of a box-like room.
// The best alignment is refined by least squares and accepted only when
//   - at least min_supporting_surfaces observations coincide with landmarks, from at least two
//     non-parallel directions (the rotation) and with the translation fixed in all three
//     directions (>= 3 non-degenerate constraints);
//   - it is not ambiguous: the best alignment at a different pose (further than 0.15 m or 0.15
//     rad) explains fewer than max_ambiguity of its surfaces, or less than max_ambiguity of its
//     support weight (sqrt of supporting points). Both must be close for an ambiguity: a shift
//     along the large planes (floor, walls) keeps them matched, but loses the bounded surfaces,
//     while the symmetric poses of a room explain nearly as many surfaces of nearly the same
//     size.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

#include "quadric_slam/mapping/landmark.h"
#include "quadric_slam/geometry/surface_matcher.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

struct Relocalisation {
  bool found = false;
  Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  int supporting_surfaces = 0;  // observations that coincide with a landmark under the pose
  int usable_observations = 0;  // observations of a class the matcher uses
  int usable_landmarks = 0;
  double support_weight = 0.0;     // sum of sqrt(supporting points) of the supporting observations
  double runner_up_weight = 0.0;   // the same for the best alignment at another pose
  int runner_up_surfaces = 0;      // and its supporting observations
  Eigen::Isometry3d runner_up_T_map_camera = Eigen::Isometry3d::Identity();
  std::vector<std::pair<int, int>> matches;  // (observation index, landmark id)
  std::string message;  // why nothing was found (empty when found)
};

class Relocaliser {
 public:
  struct Params {
    // Relocalise while recovering from a loss (false: wait for the view to return to where the
    // odometry believes it is).
    bool enabled = true;
    SurfaceMatcher::Params matcher;
    // Observations that must coincide with landmarks, [3, 100].
    int min_supporting_surfaces = 4;
    // Runner-up over the best, by surfaces and by support weight, (0, 1]: at or above it in both
    // the solution is ambiguous.
    double max_ambiguity = 0.7;
    // Extents of a matched observation and landmark must overlap when both are grown by this (m),
    // [0, 10].
    double extent_margin = 0.2;
    // Planes with fewer supporting points do not take part, >= 0.
    int min_plane_points = 300;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  Relocaliser() : Relocaliser(Params{}) {}
  explicit Relocaliser(const Params& params);

  // observations: one frame's, camera frame. landmarks: the map's (map frame).
  Relocalisation relocalise(const std::vector<QuadricMeasurement>& observations,
                            const std::map<int, QuadricLandmark>& landmarks) const;

  const Params& params() const { return params_; }

 private:
  Params params_;
  SurfaceMatcher matcher_;
};

}  // namespace quadric_slam
