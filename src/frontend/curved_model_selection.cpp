#include "quadric_slam/frontend/curved_model_selection.h"

#include <algorithm>

#include "quadric_slam/frontend/curved_shape_starts.h"
#include "quadric_slam/frontend/curved_verification.h"

namespace quadric_slam {

namespace {

// Whether a cone explains n points significantly better than a cylinder (one parameter more): the
// drop in the residual sum of squares against the cone's residual variance, over the independent
// points among them (neighbouring depths are correlated: about one in correlatedGridPoints() is
// independent), above chi^2(1) at 99.9 % (10.83). On a wide patch of a cone a cylinder leaves
// residuals barely above the far depth noise (RMS ratio 1.1), yet over a thousand points the
// difference is decisive; the RMS ratio alone (cylinder_rms_ratio) misses it.
constexpr double kConeChiSquare = 10.83;

// Correlated points of the grid the shapes are fitted on: a quarter of those the plane statistics
// count (PlaneRegionGrower::Params::correlated_points), the ratio tuned on the grid decimated by 2
// (16 there, 4 here), so that the test's power does not change with the grid's decimation.
double correlatedGridPoints(const QuadricSegmenter::Params& p) {
  return std::max(1.0, p.planes.correlated_points / 4.0);
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
  AlternativeScreen(const std::vector<Eigen::Vector3d>& points, const QuadricSegmenter::Params& p,
                    const ShapeRefiner& refiner)
      : points_(points),
        sample_(evenSubsample(points, kScreeningPoints)),
        p_(p),
        refiner_(refiner) {}

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
  const QuadricSegmenter::Params& p_;
  const ShapeRefiner& refiner_;
};

}  // namespace

ShapeRefiner::Result selectCurvedModel(const ShapeRefiner::Result& refined,
                                       const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Vector3d>& normals,
                                       const QuadricSegmenter::Params& p,
                                       const ShapeRefiner& refiner) {
  ShapeRefiner::Result fit = refined;
  const QuadricClass c = fit.shape.quadric_class;
  if (c != QuadricClass::kSphere && c != QuadricClass::kCylinder && c != QuadricClass::kCone)
    return fit;
  const AlternativeScreen alternatives(points, p, refiner);
  const double ratio = p.cylinder_rms_ratio;

  // A thin cone is a cylinder when the cylinder fits almost as well, unless the cone is
  // significantly better over all the points.
  if (fit.shape.quadric_class == QuadricClass::kCone) {
    const auto as_cylinder = alternatives.screen(cylinderFromCone(fit.shape, points));
    const double cone_rms = alternatives.sampleRms(fit);
    if (as_cylinder && as_cylinder->rms < ratio * cone_rms &&
        !coneSignificantlyBetter(cone_rms, as_cylinder->rms, points.size(), p))
      if (const auto confirmed = alternatives.confirm(*as_cylinder))
        fit = *confirmed;
  }
  // A cylinder is a cone when a cone, started from the cylinder or from the normals, fits clearly
  // better (by the RMS ratio, or significantly over all the points).
  if (fit.shape.quadric_class == QuadricClass::kCylinder && p.detect_cones) {
    const double cylinder_rms = alternatives.sampleRms(fit);
    std::optional<ShapeRefiner::Result> best_cone;
    for (const PrimitiveShape& start :
         {coneFromCylinder(fit.shape, points), coneFromNormals(points, normals)}) {
      const auto as_cone = alternatives.screen(start);
      if (as_cone &&
          (ratio * as_cone->rms < cylinder_rms ||
           coneSignificantlyBetter(as_cone->rms, cylinder_rms, points.size(), p)) &&
          (!best_cone || as_cone->rms < best_cone->rms))
        best_cone = as_cone;
    }
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
