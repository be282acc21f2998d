#include "quadric_slam/odometry/quadric_motion_guess.h"

#include "quadric_slam/types/param_checks.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "quadric_slam/odometry/pose_math.h"

namespace quadric_slam {
namespace {

// The frame's surfaces as the matcher compares them (planes oriented towards the camera: a
// visible surface faces it in every frame that sees it), weighted by sqrt(supporting points);
// planes with fewer than min_plane_points points are left out.
std::vector<MatchableSurface> surfacesOf(const std::vector<QuadricMeasurement>& observations,
                                         int min_plane_points) {
  std::vector<MatchableSurface> out;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const QuadricMeasurement& m = observations[i];
    if (m.quadric_camera.quadricClass() == QuadricClass::kPlane && m.num_points < min_plane_points)
      continue;
    appendMatchableSurface(m.quadric_camera, static_cast<int>(i),
                           std::sqrt(std::max(1, m.num_points)), /*plane_towards_origin=*/true,
                           &out);
  }
  return out;
}

SurfaceMatcher::Params matcherParams(const QuadricMotionGuesser::Params& p) {
  SurfaceMatcher::Params m;
  m.max_angle_difference = p.max_angle_difference;
  m.max_offset_difference = p.max_offset_difference;
  m.max_radius_fraction = p.max_radius_fraction;
  m.min_pair_angle = p.min_pair_angle;
  m.max_current_features = p.max_direction_features;
  m.max_reference_features = p.max_direction_features;
  return m;
}

// Of the proposals that nearly tie with the best (support weight within 2%, as many surfaces),
// the one nearest the prior: equal evidence, and the prior is where the camera probably went.
const SurfaceAlignment& nearestOfTheBest(const std::vector<SurfaceAlignment>& proposals,
                                         const Eigen::Isometry3d& prior) {
  const auto distance = [&](const SurfaceAlignment& a) {
    const Eigen::Isometry3d difference = prior.inverse() * a.T_reference_current;
    return difference.translation().norm() + pose_math::rotationAngle(difference);  // 1 m per rad
  };
  const SurfaceAlignment* chosen = &proposals.front();
  for (const SurfaceAlignment& a : proposals) {
    if (a.weight < 0.98 * proposals.front().weight)
      break;  // sorted by weight
    if (a.supporting >= proposals.front().supporting && distance(a) < distance(*chosen))
      chosen = &a;
  }
  return *chosen;
}

}  // namespace

void QuadricMotionGuesser::Params::validate() const {
  const ParamRangeCheck check("QuadricMotionGuesser::Params");
  if (min_plane_points < 0)
    check.fail("min_plane_points", "[0, inf)", min_plane_points);
  if (max_direction_features < 2 || max_direction_features > 64)
    check.fail("max_direction_features", "[2, 64]", max_direction_features);
  if (!(max_rotation_from_prior > 0 && max_rotation_from_prior <= M_PI))
    check.fail("max_rotation_from_prior", "(0, pi] rad", max_rotation_from_prior);
  if (!(max_translation_from_prior > 0 && std::isfinite(max_translation_from_prior)))
    check.fail("max_translation_from_prior", "(0, inf) m", max_translation_from_prior);
  if (min_supporting_surfaces < 2 || min_supporting_surfaces > 1000)
    check.fail("min_supporting_surfaces", "[2, 1000]", min_supporting_surfaces);
  // The matching tolerances (angles, offsets, radii, pair angle) are the matcher's to check.
  matcherParams(*this).validate();
}

QuadricMotionGuesser::QuadricMotionGuesser() : QuadricMotionGuesser(Params{}) {}

QuadricMotionGuesser::QuadricMotionGuesser(const Params& params)
    : params_((params.validate(), params)), matcher_(matcherParams(params_)) {}

QuadricMotionGuess QuadricMotionGuesser::guess(
    const std::vector<QuadricMeasurement>& reference,
    const std::vector<QuadricMeasurement>& current,
    const Eigen::Isometry3d& T_reference_current_prior) const {
  const std::vector<MatchableSurface> ref = surfacesOf(reference, params_.min_plane_points);
  const std::vector<MatchableSurface> cur = surfacesOf(current, params_.min_plane_points);
  QuadricMotionGuess out;
  out.usable_surfaces = static_cast<int>(cur.size());
  MotionPrior prior;
  prior.T_reference_current = T_reference_current_prior;
  prior.max_rotation = params_.max_rotation_from_prior;
  prior.max_translation = params_.max_translation_from_prior;
  const std::vector<SurfaceAlignment> proposals = matcher_.align(ref, cur, {}, &prior);
  if (proposals.empty()) {
    out.message = "no pair of non-parallel surfaces seen in both frames";
    return out;
  }
  const SurfaceAlignment& best = nearestOfTheBest(proposals, T_reference_current_prior);
  if (best.supporting < params_.min_supporting_surfaces) {
    std::ostringstream why;
    why << "best of " << proposals.size() << " hypotheses agrees with " << best.supporting
        << " surfaces, fewer than " << params_.min_supporting_surfaces;
    out.message = why.str();
    return out;
  }
  // Least squares over every supporting pair; the prior fills a direction they leave free.
  const SurfaceAlignment refined = matcher_.refine(ref, cur, best, {}, &prior);
  out.found = true;
  out.T_reference_current = pose_math::orthonormalized(refined.T_reference_current);
  out.supporting_surfaces = best.supporting;
  out.support_weight = best.weight;
  out.translation_from_prior = refined.translation_conditioning < 1e-3;
  return out;
}

}  // namespace quadric_slam
