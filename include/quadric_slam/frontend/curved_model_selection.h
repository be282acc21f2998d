// Model selection among the curved classes for one supported surface patch: given the refined fit
// of the patch's current class, try the other classes from starts built on the same points and
// keep a simpler class that fits almost as well (a thin cone is a cylinder; a wide cone or a
// cylinder on a sphere cap is a sphere), or a cone that fits clearly better than a cylinder and
// whose normals agree with the measured ones at least as well (clearly better for a cone started
// from the cylinder's axis tilted, which may lean against a cylinder by its half angle). Far from
// the camera, where depth cannot tell a cone's side from a cylinder, a cone that fits no worse and
// whose opening the segment's outline shows (frontend/silhouette_taper.h) is taken, and such a cone
// is not turned into a cylinder.
//
// The alternatives are screened on an even sub-sample of the support (kScreeningPoints): most of
// them are the wrong model (a sphere on a cylinder patch), and Levenberg-Marquardt on a wrong model
// creeps for all its iterations without getting near the current fit. Only a winner is refined on
// the whole support.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/frontend/shape_refiner.h"

namespace quadric_slam {

// Points an alternative class is screened on at most: enough for the RMS comparison (its
// relative standard error is about 1 / sqrt(2 n), under 5 %), a quarter of a full refinement.
constexpr int kScreeningPoints = 250;

// The best of fit (refined on points, class sphere, cylinder or cone) and the alternatives;
// normals are the measured unit normals of the points (the cone start from normals and the
// cones' normal agreement use them); cut flags the points on cut outlines (empty, or one per
// point: silhouette_taper.h).
// Planes and general quadrics are returned unchanged.
ShapeRefiner::Result selectCurvedModel(const ShapeRefiner::Result& fit,
                                       const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Vector3d>& normals,
                                       const std::vector<std::uint8_t>& cut,
                                       const QuadricSegmenter::Params& p,
                                       const ShapeRefiner& refiner);

}  // namespace quadric_slam
