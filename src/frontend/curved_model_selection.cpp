#include "quadric_slam/frontend/curved_model_selection.h"

#include <algorithm>

#include "quadric_slam/frontend/curved_shape_starts.h"
#include "quadric_slam/frontend/curved_verification.h"
#include "quadric_slam/frontend/silhouette_taper.h"

namespace quadric_slam {

namespace {

// Whether a cone explains n points significantly better than a cylinder (one parameter more): the
// drop in the residual sum of squares against the cone's residual variance, over the independent
// points among them (neighbouring depths are correlated: about one in correlatedGridPoints() is
// independent), above chi^2(1) at 99.9 % (10.83). On a wide patch of a cone a cylinder leaves
// residuals barely above the far depth noise (RMS ratio 1.1), yet over a thousand points the
// difference is decisive; the RMS ratio alone (cylinder_rms_ratio) misses it.
constexpr double kConeChiSquare = 10.83;

// Tilt (rad) of the cylinder's axis for the cone starts beside it: from generated cones of half
// angle 0.32 seen from one side at 2.4-2.8 m, the refinement reached the cone's optimum from any
// tilt of 0.2-0.6 towards the right side, and a thin cone from the untilted axis.
constexpr double kConeStartTilt = 0.3;

// Share of the cylinder's normal disagreement (AlternativeScreen::normalDisagreement) that a cone
// from a tilted start may keep. On generated cones seen from one side at 2-3 m such cones cut it
// by 12-27 %; on the real mOSD cups and bowls (upright cylinders) the tilted cones that fitted
// their points significantly better cut it by 1-6 %.
constexpr double kTiltedConeNormalGain = 0.9;

// Correlated points of the grid the shapes are fitted on: a quarter of those the plane statistics
// count (PlaneRegionGrower::Params::correlated_points), the ratio tuned on the grid decimated by 2
// (16 there, 4 here), so that the test's power does not change with the grid's decimation.
double correlatedGridPoints(const QuadricSegmenter::Params& p) {
  return std::max(1.0, p.planes.correlated_points / 4.0);
}

// Smallest taper of a silhouette taken as a cone's (k = tan(half angle), 5 deg): below it a
// segment's outline, cut by occluders and the segmenter's borders, says nothing.
constexpr double kMinConeTaper = 0.09;

// Whether a measured slope is a cone's predicted one: significant (significantSlope with
// kMinConeTaper), of the same sign, 0.4 to 2 times as large. The segmenter drops a curved surface's
// grazing edges, so the measured width is a fraction of the true one; on the generated room's cone
// 2.6 m away the measured taper was 0.43-1.2 times the predicted.
bool slopeMatches(double measured, double sigma, double predicted) {
  return significantSlope(measured, sigma, kMinConeTaper) && predicted * measured > 0.0 &&
         std::abs(measured) > 0.4 * std::abs(predicted) &&
         std::abs(measured) < 2.0 * std::abs(predicted);
}

// Whether the outline measured on both sides rules a cone out: its predicted taper is clear (over
// twice kMinConeTaper) and the measured one is under kContradictedTaperShare of it and more than
// kContradictionSigmas standard errors away, so the width stays about constant where the cone's
// would change. On the generated desk, a wide cone proposed on a lying tube with its flat end cap
// (the flare takes in the cap) predicted 0.6, and the outline measured 0.01-0.02 +- 0.005. A cone
// proposed far too wide on a true cone 2.8 m away (1.2 rad against 0.32: 0.71 against 0.15) is
// ruled out too; the cone the outline shows is then found from the cylinder.
constexpr double kContradictedTaperShare = 0.25;
constexpr double kContradictionSigmas = 5.0;
bool outlineRulesOutCone(const PrimitiveShape& cone, const PrimitiveShape& cylinder,
                         const SilhouetteTaper& taper) {
  if (taper.bins < kMinTaperBins)
    return false;
  const double predicted = predictedTaper(cone, cylinder.direction);
  return std::abs(predicted) > 2.0 * kMinConeTaper &&
         std::abs(taper.slope) < kContradictedTaperShare * std::abs(predicted) &&
         std::abs(predicted - taper.slope) > kContradictionSigmas * taper.slope_sigma;
}

// Least uncut bins of a side whose edge alone is compared with a cone's (the other side cut all
// along): the slope of one edge also carries the error of the fitted axis's direction, which the
// difference of two edges cancels.
constexpr int kMinOneSidedBins = 6;
// Least length (m) along the axis of a support whose one edge is compared with a cone's: the
// fitted axis's direction error grows as the support shortens (on the generated desk, a partly
// hidden cylinder's side 0.33 m long had an edge slope of 0.37 against its fitted axis).
constexpr double kMinOneSidedLength = 0.4;
// How much worse than the cylinder (RMS on the screening sample) a cone whose one silhouette edge
// matches may fit: where an occluder hides one side, the visible strip is narrow, and on the
// generated room's cone at 2.9 m the cone from a tilted start fitted it 7 % worse than the
// cylinder there.
constexpr double kOneSidedRmsAllowance = 1.1;

// The silhouette edge that alone stands for the outline: -1 none, 0 low, 1 high. Only when the
// other side is cut all along, this one has kMinOneSidedBins, and the support kMinOneSidedLength.
int loneEdge(const SilhouetteTaper& taper) {
  if (taper.bins >= kMinTaperBins || taper.length < kMinOneSidedLength)
    return -1;
  if (taper.low_edge.bins >= kMinOneSidedBins && taper.high_edge.bins == 0)
    return 0;
  if (taper.high_edge.bins >= kMinOneSidedBins && taper.low_edge.bins == 0)
    return 1;
  return -1;
}

// The outline of the support along the cylinder's axis. Where its edges are cut (cut: flags of
// cutOutline), each side's silhouette: both sides' taper, or with lone_edge one side's edge alone
// (loneEdge). When neither is measured, across the support's extremes as if nothing were cut.
// lone_edge needs the patch's own cylinder: a cylinder screened from a cone's start may keep an
// axis a tenth of a radian off (on the generated desk a partly hidden cylinder's edge ran at 0.22
// to such an axis), which one edge's slope carries.
SilhouetteTaper outlineAlong(const PrimitiveShape& cylinder,
                             const std::vector<Eigen::Vector3d>& points,
                             const std::vector<std::uint8_t>& cut, bool lone_edge) {
  const SilhouetteTaper taper =
      measureSilhouetteTaper(cylinder.point, cylinder.direction, points, cut);
  if (cut.empty() || taper.bins >= kMinTaperBins || (lone_edge && loneEdge(taper) >= 0))
    return taper;
  return measureSilhouetteTaper(cylinder.point, cylinder.direction, points);
}

// Whether the cone's predicted outline along the cylinder's axis is the measured one
// (outlineAlong): the taper when both sides are measured, else a lone edge's slope against the
// cone's generator on that side (the cylinder predicts it parallel to its axis).
bool coneMatchesTaper(const PrimitiveShape& cone, const PrimitiveShape& cylinder,
                      const SilhouetteTaper& taper) {
  if (taper.bins >= kMinTaperBins)
    return slopeMatches(taper.slope, taper.slope_sigma, predictedTaper(cone, cylinder.direction));
  const int side = loneEdge(taper);
  if (side < 0)
    return false;
  const SilhouetteEdge& edge = side == 1 ? taper.high_edge : taper.low_edge;
  return slopeMatches(edge.slope, edge.slope_sigma, predictedEdgeSlope(cone, taper, side == 1));
}

bool coneSignificantlyBetter(double cone_rms, double cylinder_rms, std::size_t n,
                             const QuadricSegmenter::Params& p) {
  if (!(cone_rms > 0) || cylinder_rms <= cone_rms)
    return false;
  const double independent = static_cast<double>(n) / correlatedGridPoints(p);
  return independent * (cylinder_rms * cylinder_rms - cone_rms * cone_rms) / (cone_rms * cone_rms) >
         kConeChiSquare;
}

// The alternatives of one patch, screened on the same sub-sample; the current fit's RMS on it is
// the yardstick, so that sampling noise does not decide between two classes.
class AlternativeScreen {
 public:
  AlternativeScreen(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Eigen::Vector3d>& normals, const QuadricSegmenter::Params& p,
                    const ShapeRefiner& refiner)
      : points_(points),
        sample_(evenSubsample(points, kScreeningPoints)),
        sample_normals_(normals.size() == points.size() ? evenSubsample(normals, kScreeningPoints)
                                                        : std::vector<Eigen::Vector3d>()),
        p_(p),
        refiner_(refiner) {}

  // How far the shape's normals are from the measured ones on the screening sample: the mean of
  // 1 - |cos| of the angle between them (0 without normals).
  double normalDisagreement(const PrimitiveShape& shape) const {
    if (sample_normals_.empty())
      return 0.0;
    double sum = 0.0;
    for (std::size_t i = 0; i < sample_.size(); ++i)
      sum += 1.0 - std::abs(shape.normalAt(sample_[i]).dot(sample_normals_[i]));
    return sum / static_cast<double>(sample_.size());
  }

  // The fit's RMS on the screening sample.
  double sampleRms(const ShapeRefiner::Result& fit) const {
    return rmsDistance(fit.shape, sample_);
  }

  // The alternative from start refined on the sample; none when start or the result is
  // implausible.
  std::optional<ShapeRefiner::Result> screen(const PrimitiveShape& start) const {
    if (!plausibleShape(start, p_))
      return std::nullopt;
    ShapeRefiner::Result result = refiner_.refine(start, sample_);
    if (!plausibleShape(result.shape, p_))
      return std::nullopt;
    return result;
  }

  // A screened winner refined on the whole support; none when that leaves the plausible sizes.
  std::optional<ShapeRefiner::Result> confirm(const ShapeRefiner::Result& screened) const {
    ShapeRefiner::Result result = refiner_.refine(screened.shape, points_);
    if (!plausibleShape(result.shape, p_))
      return std::nullopt;
    return result;
  }

 private:
  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector3d> sample_;
  const std::vector<Eigen::Vector3d> sample_normals_;
  const QuadricSegmenter::Params& p_;
  const ShapeRefiner& refiner_;
};

}  // namespace

ShapeRefiner::Result selectCurvedModel(const ShapeRefiner::Result& refined,
                                       const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Vector3d>& normals,
                                       const std::vector<std::uint8_t>& cut,
                                       const QuadricSegmenter::Params& p,
                                       const ShapeRefiner& refiner) {
  ShapeRefiner::Result fit = refined;
  const QuadricClass c = fit.shape.quadric_class;
  if (c != QuadricClass::kSphere && c != QuadricClass::kCylinder && c != QuadricClass::kCone)
    return fit;
  const AlternativeScreen alternatives(points, normals, p, refiner);
  const double ratio = p.cylinder_rms_ratio;

  // A thin cone is a cylinder when the cylinder fits almost as well, unless the cone is
  // significantly better over all the points. Any cone is a cylinder when its outline rules it
  // out, however it fits: its support may hold a surface beside the cylinder that the cone bends
  // into (a tube's flat end cap), and the cylinder's own support is found again in the second
  // assignment.
  bool cone_ruled_out = false;
  if (fit.shape.quadric_class == QuadricClass::kCone) {
    // From the cone's axis, and from the normals alone: a wide cone fitted to a cylinder's strip
    // has its axis far from the cylinder's, where the first start cannot find it.
    std::optional<ShapeRefiner::Result> as_cylinder =
        alternatives.screen(cylinderFromCone(fit.shape, points));
    const auto from_normals = alternatives.screen(
        cylinderFromNormals(points, normals, cylinderCurvatureFromNormals(points, normals)));
    if (from_normals && (!as_cylinder || from_normals->rms < as_cylinder->rms))
      as_cylinder = from_normals;
    const double cone_rms = alternatives.sampleRms(fit);
    if (as_cylinder) {
      const SilhouetteTaper outline = outlineAlong(as_cylinder->shape, points, cut, false);
      cone_ruled_out = outlineRulesOutCone(fit.shape, as_cylinder->shape, outline);
      if (cone_ruled_out ||
          (as_cylinder->rms < ratio * cone_rms &&
           !coneSignificantlyBetter(cone_rms, as_cylinder->rms, points.size(), p) &&
           !coneMatchesTaper(fit.shape, as_cylinder->shape, outline)))
        if (const auto confirmed = alternatives.confirm(*as_cylinder))
          fit = *confirmed;
      cone_ruled_out = cone_ruled_out && fit.shape.quadric_class == QuadricClass::kCylinder;
    }
  }
  // A cylinder is a cone when a cone, started from the cylinder or from the normals, fits clearly
  // better (by the RMS ratio, or significantly over all the points).
  if (fit.shape.quadric_class == QuadricClass::kCylinder && p.detect_cones) {
    const double cylinder_rms = alternatives.sampleRms(fit);
    const SilhouetteTaper taper = outlineAlong(fit.shape, points, cut, true);
    std::optional<ShapeRefiner::Result> best_cone;
    const double rms_allowance = loneEdge(taper) >= 0 ? kOneSidedRmsAllowance : 1.0;
    // The cylinder's axis tilted both ways by kConeStartTilt: a cylinder on one side of a cone
    // lies along a generator (coneFromTiltedCylinder).
    const PrimitiveShape starts[] = {
        coneFromCylinder(fit.shape, points), coneFromNormals(points, normals),
        coneFromTiltedCylinder(fit.shape, points, kConeStartTilt, 1.0),
        coneFromTiltedCylinder(fit.shape, points, kConeStartTilt, -1.0)};
    for (int k = 0; k < 4; ++k) {
      const auto as_cone = alternatives.screen(starts[k]);
      if (!as_cone)
        continue;
      // After an outline ruled a cone out, only a cone the outline shows.
      const bool shown = coneMatchesTaper(as_cone->shape, fit.shape, taper);
      if (cone_ruled_out && !shown)
        continue;
      // Far away the depth cannot tell them apart, the outline can: a cone that fits no worse
      // than the cylinder and whose opening the silhouette shows.
      const bool outlined = as_cone->rms <= rms_allowance * cylinder_rms && shown;
      if (!(ratio * as_cone->rms < cylinder_rms ||
            coneSignificantlyBetter(as_cone->rms, cylinder_rms, points.size(), p) || outlined))
        continue;
      // A cone from a tilted axis must also follow the measured normals clearly better: tilted
      // against a cylinder by its half angle, a cone hugs the visible side about as closely as the
      // cylinder does (over many points a little closer), but its normals turn across the visible
      // arc where the measured ones do not.
      const bool tilted = k >= 2;
      if (tilted && !outlined &&
          alternatives.normalDisagreement(as_cone->shape) >
              kTiltedConeNormalGain * alternatives.normalDisagreement(fit.shape))
        continue;
      if (!best_cone || as_cone->rms < best_cone->rms)
        best_cone = as_cone;
    }
    // Whatever its start, no cone whose normals agree worse than the cylinder's (see above),
    // unless the outline shows its opening.
    if (best_cone && !coneMatchesTaper(best_cone->shape, fit.shape, taper) &&
        alternatives.normalDisagreement(best_cone->shape) >
            alternatives.normalDisagreement(fit.shape))
      best_cone.reset();
    if (best_cone)
      if (const auto confirmed = alternatives.confirm(*best_cone))
        fit = *confirmed;
  }
  // A wide cone or a cylinder on a sphere cap is a sphere when the sphere fits almost as well.
  if (fit.shape.quadric_class != QuadricClass::kSphere && p.detect_spheres) {
    const auto as_sphere = alternatives.screen(fitSphereAlgebraic(points));
    if (as_sphere && as_sphere->rms < ratio * alternatives.sampleRms(fit))
      if (const auto confirmed = alternatives.confirm(*as_sphere))
        fit = *confirmed;
  }
  return fit;
}

}  // namespace quadric_slam
