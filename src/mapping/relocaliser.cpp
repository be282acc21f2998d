#include "quadric_slam/mapping/relocaliser.h"

#include "quadric_slam/types/param_checks.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "quadric_slam/mapping/extent_box.h"

namespace quadric_slam {
namespace {

// Two alignments are the same solution when their poses are this close (m, rad): well inside the
// matcher's gates, well outside the distance between the symmetric solutions of a room.
constexpr double kDistinctTranslation = 0.15;
constexpr double kDistinctRotation = 0.15;
// The supporting surfaces must fix the translation in every direction: the smallest eigenvalue
// of its normal equations at least this share of the largest.
constexpr double kMinTranslationConditioning = 0.02;
// ... and give the rotation two directions: the second eigenvalue of the directions' scatter at
// least this share of the largest.
constexpr double kMinDirectionSpread = 0.05;

bool samePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm() < kDistinctTranslation &&
         Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() < kDistinctRotation;
}

ExtentBox boxOf(const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  ExtentBox box;
  box.min = min;
  box.max = max;
  return box;
}

}  // namespace

void Relocaliser::Params::validate() const {
  matcher.validate();
  const ParamRangeCheck check("Relocaliser::Params");
  if (min_supporting_surfaces < 3 || min_supporting_surfaces > 100)
    check.fail("min_supporting_surfaces", "[3, 100]", min_supporting_surfaces);
  if (!(max_ambiguity > 0 && max_ambiguity <= 1))
    check.fail("max_ambiguity", "(0, 1]", max_ambiguity);
  if (!(extent_margin >= 0 && extent_margin <= 10))
    check.fail("extent_margin", "[0, 10] m", extent_margin);
  if (min_plane_points < 0)
    check.fail("min_plane_points", "[0, inf)", min_plane_points);
}

Relocaliser::Relocaliser(const Params& params)
    : params_((params.validate(), params)), matcher_(params.matcher) {}

Relocalisation Relocaliser::relocalise(const std::vector<QuadricMeasurement>& observations,
                                       const std::map<int, QuadricLandmark>& landmarks) const {
  Relocalisation out;
  // The frame's surfaces, planes facing the camera; weight sqrt(points) as in the motion guess.
  std::vector<MatchableSurface> current;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const QuadricMeasurement& m = observations[i];
    if (m.quadric_camera.quadricClass() == QuadricClass::kPlane &&
        m.num_points < params_.min_plane_points)
      continue;
    out.usable_observations += appendMatchableSurface(m.quadric_camera, static_cast<int>(i),
                                                      std::sqrt(std::max(1, m.num_points)),
                                                      /*plane_towards_origin=*/true, &current);
  }
  // The map's surfaces: a plane of either side; the larger its observed extent, the earlier it
  // proposes rotations (weight = the extent's diagonal, 1 m when unknown).
  std::vector<MatchableSurface> reference;
  std::vector<const QuadricLandmark*> landmark_of;
  for (const auto& [id, landmark] : landmarks) {
    const ExtentBox box = boxOf(landmark.extent_min, landmark.extent_max);
    const double size = box.known() ? (box.max - box.min).norm() : 1.0;
    const int added =
        appendMatchableSurface(landmark.quadric_map, static_cast<int>(landmark_of.size()), size,
                               /*plane_towards_origin=*/false, &reference);
    if (added > 0) {
      ++out.usable_landmarks;
      landmark_of.push_back(&landmark);
    }
  }
  if (out.usable_observations < params_.min_supporting_surfaces ||
      out.usable_landmarks < params_.min_supporting_surfaces) {
    std::ostringstream why;
    why << out.usable_observations << " usable observations and " << out.usable_landmarks
        << " usable landmarks: fewer than " << params_.min_supporting_surfaces;
    out.message = why.str();
    return out;
  }

  // A pair counts only when the observation's extent, moved into the landmark's quadric frame,
  // overlaps the landmark's (unknown extents always overlap).
  const SurfaceMatcher::PairTest extents_overlap = [&](int c, int r,
                                                       const Eigen::Isometry3d& T_map_camera) {
    const QuadricMeasurement& m = observations[current[c].source];
    const QuadricLandmark& l = *landmark_of[reference[r].source];
    const Eigen::Isometry3d T_landmark_observation =
        l.quadric_map.pose().inverse() * T_map_camera * m.quadric_camera.pose();
    return boxOf(m.extent_min, m.extent_max)
        .transformed(T_landmark_observation)
        .overlaps(boxOf(l.extent_min, l.extent_max), params_.extent_margin);
  };
  const std::vector<SurfaceAlignment> alignments =
      matcher_.align(reference, current, extents_overlap);
  if (alignments.empty()) {
    out.message = "no pair of non-parallel surfaces matches the map";
    return out;
  }
  const SurfaceAlignment best =
      matcher_.refine(reference, current, alignments.front(), extents_overlap);
  for (const SurfaceAlignment& other : alignments) {
    if (!samePose(other.T_reference_current, best.T_reference_current) &&
        !samePose(other.T_reference_current, alignments.front().T_reference_current)) {
      out.runner_up_weight = other.weight;
      out.runner_up_surfaces = other.supporting;
      out.runner_up_T_map_camera = other.T_reference_current;
      break;
    }
  }
  out.supporting_surfaces = best.supporting;
  out.support_weight = best.weight;
  out.T_map_camera = best.T_reference_current;

  std::ostringstream why;
  if (best.supporting < params_.min_supporting_surfaces) {
    why << "best alignment has " << best.supporting << " supporting surfaces, fewer than "
        << params_.min_supporting_surfaces;
  } else if (best.translation_conditioning < kMinTranslationConditioning) {
    why << "the supporting surfaces leave a direction of the position free (conditioning "
        << best.translation_conditioning << ")";
  } else if (out.runner_up_surfaces >= params_.max_ambiguity * best.supporting &&
             out.runner_up_weight >= params_.max_ambiguity * best.weight) {
    why << "ambiguous: another pose explains " << out.runner_up_surfaces << " of "
        << best.supporting << " surfaces (support " << out.runner_up_weight << " of " << best.weight
        << ")";
  } else {
    Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
    for (const auto& [c, r] : best.pairs)
      if (current[c].kind != MatchableSurface::Kind::kSphere)
        spread += current[c].weight * current[c].direction * current[c].direction.transpose();
    const Eigen::Vector3d eig =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread).eigenvalues();
    if (eig(1) < kMinDirectionSpread * eig(2))
      why << "the supporting surfaces share one direction: the rotation about it is free";
  }
  out.message = why.str();
  if (!out.message.empty())
    return out;
  out.found = true;
  for (const auto& [c, r] : best.pairs)
    out.matches.emplace_back(current[c].source, landmark_of[reference[r].source]->id);
  return out;
}

}  // namespace quadric_slam
