#include "quadric_slam/geometry/surface_matcher.h"

#include "quadric_slam/types/param_checks.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "quadric_slam/geometry/shapes.h"

namespace quadric_slam {
namespace {

using Kind = MatchableSurface::Kind;

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// The rotation R minimising sum w_i |v_i - R u_i|^2 (Kabsch).
Eigen::Matrix3d kabsch(const std::vector<Eigen::Vector3d>& u, const std::vector<Eigen::Vector3d>& v,
                       const std::vector<double>& w) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < u.size(); ++i)
    H += w[i] * u[i] * v[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixV() * D * svd.matrixU().transpose();
}

// The rotation taking the columns of U onto those of V (Kabsch with unit weights): the hypotheses'
// case of two directions and their cross product, without the vectors of the general one.
Eigen::Matrix3d kabsch(const Eigen::Matrix3d& U, const Eigen::Matrix3d& V) {
  const Eigen::Matrix3d H = U * V.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixV() * D * svd.matrixU().transpose();
}

// Two directions and their cross product as the columns of a frame.
Eigen::Matrix3d directionFrame(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Eigen::Matrix3d M;
  M << a, b, a.cross(b).normalized();
  return M;
}

// A direction that can define a rotation: a plane normal, or one of the two signs of a cylinder's
// or cone's axis (the fit does not fix a cylinder's sign; a cone's quadric is the double cone, and
// which nappe its frame names may differ between a frame and the map).
struct DirectionFeature {
  int surface = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

// Surfaces whose direction is an axis without a sign.
bool axial(Kind kind) {
  return kind == Kind::kCylinder || kind == Kind::kCone;
}

std::vector<DirectionFeature> directionFeatures(const std::vector<MatchableSurface>& surfaces,
                                                int max_count, bool both_cylinder_signs) {
  std::vector<int> order;
  for (std::size_t i = 0; i < surfaces.size(); ++i)
    if (surfaces[i].kind != Kind::kSphere)
      order.push_back(static_cast<int>(i));
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return surfaces[a].weight > surfaces[b].weight; });
  std::vector<DirectionFeature> out;
  int sources = 0, last_source = -1;
  for (int i : order) {
    // A two-sided plane is two surfaces of one source: both count as one feature.
    if (surfaces[i].source != last_source && ++sources > max_count)
      break;
    last_source = surfaces[i].source;
    out.push_back({i, surfaces[i].direction});
    if (both_cylinder_signs && axial(surfaces[i].kind))
      out.push_back({i, -surfaces[i].direction});
  }
  return out;
}

// Candidate (current, reference) pairs.
struct Pair {
  int current = 0, reference = 0;
};

class Hypotheses {
 public:
  Hypotheses(const SurfaceMatcher::Params& params, const std::vector<MatchableSurface>& reference,
             const std::vector<MatchableSurface>& current, const SurfaceMatcher::PairTest& test,
             const MotionPrior* prior)
      : p_(params),
        ref_(reference),
        cur_(current),
        test_(test),
        prior_(prior),
        cos_max_angle_(std::cos(params.max_angle_difference)) {}

  bool sameShape(const MatchableSurface& c, const MatchableSurface& r) const {
    if (c.kind != r.kind)
      return false;
    if (c.kind == Kind::kCone)
      return std::abs(c.size - r.size) <= p_.max_angle_difference;
    if (c.kind == Kind::kSphere || c.kind == Kind::kCylinder)
      return std::abs(c.size - r.size) <= p_.max_radius_fraction * std::max(c.size, r.size);
    return true;
  }

  // Same class, same size and, under R, the same direction (an axis up to its sign).
  bool compatible(const MatchableSurface& c, const MatchableSurface& r,
                  const Eigen::Matrix3d& R) const {
    if (!sameShape(c, r))
      return false;
    if (c.kind == Kind::kSphere)
      return true;
    // Within max_angle_difference, compared by cosines (unit directions; this runs for every pair
    // of surfaces under every rotation).
    const double cosine = (R * c.direction).dot(r.direction);
    return (axial(c.kind) ? std::abs(cosine) : cosine) >= cos_max_angle_;
  }

  // Adds the linear constraints on t of a pair (weight w) to the normal equations.
  static void addConstraints(const MatchableSurface& c, const MatchableSurface& r,
                             const Eigen::Matrix3d& R, double w, Eigen::Matrix3d& AtA,
                             Eigen::Vector3d& Atb) {
    switch (c.kind) {
      case Kind::kPlane: {
        // n_r . (R p_c + t) = d_r for every p_c with n_c . p_c = d_c  =>  n_r . t = d_r - d_c.
        AtA += w * r.direction * r.direction.transpose();
        Atb += w * r.direction * (r.offset - c.offset);
        break;
      }
      case Kind::kSphere:
      case Kind::kCone:
        AtA += w * Eigen::Matrix3d::Identity();  // R c_c + t = c_r (centre or apex)
        Atb += w * (r.point - R * c.point);
        break;
      case Kind::kCylinder: {
        // The axis points agree across the axis: P (R p_c + t - p_r) = 0, P = I - a a^T.
        const Eigen::Matrix3d P =
            Eigen::Matrix3d::Identity() - r.direction * r.direction.transpose();
        AtA += w * P;
        Atb += w * P * (r.point - R * c.point);
        break;
      }
    }
  }

  // Distance of the pair under (R, t) in the quantity the class is compared by (m).
  static double residual(const MatchableSurface& c, const MatchableSurface& r,
                         const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
    switch (c.kind) {
      case Kind::kPlane:
        return std::abs(r.direction.dot(t) + c.offset - r.offset);
      case Kind::kSphere:
      case Kind::kCone:
        return (R * c.point + t - r.point).norm();
      case Kind::kCylinder: {
        const Eigen::Vector3d d = R * c.point + t - r.point;
        return (d - r.direction * r.direction.dot(d)).norm();
      }
    }
    return 0.0;
  }

  // Least-squares translation; a direction the constraints leave free takes the prior's
  // translation (zero without a prior) through a small regulariser, and the conditioning says so.
  Eigen::Vector3d solve(Eigen::Matrix3d AtA, Eigen::Vector3d Atb, double* conditioning) const {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(AtA);
    const double largest = std::max(eig.eigenvalues()(2), 1e-12);
    if (conditioning)
      *conditioning = std::max(0.0, eig.eigenvalues()(0)) / largest;
    // A prior is trusted a little where the data is weak, not only where it says nothing.
    const double weight = (prior_ ? 1e-6 : 1e-9) * largest;
    AtA += weight * Eigen::Matrix3d::Identity();
    if (prior_)
      Atb += weight * prior_->T_reference_current.translation();
    return AtA.ldlt().solve(Atb);
  }

  bool withinPrior(const Eigen::Matrix3d& R) const {
    return !prior_ ||
           rotationAngle(R, prior_->T_reference_current.linear()) <= prior_->max_rotation;
  }
  bool withinPrior(const Eigen::Vector3d& t) const {
    return !prior_ ||
           (t - prior_->T_reference_current.translation()).norm() <= prior_->max_translation;
  }
  // Distance of a pose from the prior: 1 m per rad (0 without a prior).
  double distanceFromPrior(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
    if (!prior_)
      return 0.0;
    return (t - prior_->T_reference_current.translation()).norm() +
           rotationAngle(R, prior_->T_reference_current.linear());
  }
  static double rotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
    return Eigen::AngleAxisd(a * b.transpose()).angle();
  }
  // More agreeing surface (by weight); with a prior, among nearly equal supports, the proposal
  // nearer the prior.
  bool better(const SurfaceAlignment& s, double s_distance, const SurfaceAlignment& best,
              double best_distance) const {
    if (best.supporting == 0)
      return s.supporting > 0;
    if (!prior_)
      return s.weight > best.weight;
    return s.weight > best.weight * 1.02 ||
           (s.weight >= best.weight * 0.98 && s.supporting >= best.supporting &&
            s_distance < best_distance);
  }

  SurfaceAlignment score(const std::vector<Pair>& candidates, const Eigen::Matrix3d& R,
                         const Eigen::Vector3d& t) const {
    SurfaceAlignment s;
    s.T_reference_current.linear() = R;
    s.T_reference_current.translation() = t;
    std::vector<double> best(cur_.size(), std::numeric_limits<double>::infinity());
    std::vector<int> best_ref(cur_.size(), -1);
    for (const Pair& pair : candidates) {
      const double r = residual(cur_[pair.current], ref_[pair.reference], R, t);
      if (r > p_.max_offset_difference || r >= best[pair.current])
        continue;
      if (test_ && !test_(pair.current, pair.reference, s.T_reference_current))
        continue;
      best[pair.current] = r;
      best_ref[pair.current] = pair.reference;
    }
    for (std::size_t i = 0; i < cur_.size(); ++i) {
      if (best_ref[i] < 0)
        continue;
      ++s.supporting;
      s.weight += cur_[i].weight;
      s.pairs.emplace_back(static_cast<int>(i), best_ref[i]);
    }
    return s;
  }

  std::vector<Pair> candidatesUnder(const Eigen::Matrix3d& R) const {
    std::vector<Pair> out;
    for (std::size_t i = 0; i < cur_.size(); ++i)
      for (std::size_t j = 0; j < ref_.size(); ++j)
        if (compatible(cur_[i], ref_[j], R))
          out.push_back({static_cast<int>(i), static_cast<int>(j)});
    return out;
  }

  std::vector<SurfaceAlignment> run() const;

 private:
  const SurfaceMatcher::Params& p_;
  const std::vector<MatchableSurface>& ref_;
  const std::vector<MatchableSurface>& cur_;
  const SurfaceMatcher::PairTest& test_;
  const MotionPrior* prior_;  // may be null
  double cos_max_angle_;
};

std::vector<SurfaceAlignment> Hypotheses::run() const {
  const std::vector<DirectionFeature> cur_dirs =
      directionFeatures(cur_, p_.max_current_features, /*both_cylinder_signs=*/true);
  const std::vector<DirectionFeature> ref_dirs =
      directionFeatures(ref_, p_.max_reference_features, /*both_cylinder_signs=*/false);
  std::vector<SurfaceAlignment> out;
  // Fragments of one surface and repeated parallel surfaces propose the same rotation many times,
  // and the same line of translations: each distinct rotation's candidate pairs are found once,
  // each distinct line under it is tried once. (Only the line, not the rotation, may be skipped:
  // a table top and the floor give the same rotation, but only the floor's line holds the truth.)
  struct TriedRotation {
    Eigen::Quaterniond q;
    std::vector<Pair> candidates;
    std::vector<Eigen::Vector3d> lines;  // a point of each tried line (the one solve() picks)
  };
  std::vector<TriedRotation> tried;
  // Rotations closer than half the angle tolerance count as one: angularDistance(q, q') =
  // 2 acos(|q.q'|), compared through the cosine (this runs for every hypothesis and every rotation
  // tried before it).
  const double cos_same_rotation = std::cos(0.25 * p_.max_angle_difference);
  const auto rotationEntry = [&](const Eigen::Matrix3d& R) -> TriedRotation& {
    const Eigen::Quaterniond q(R);
    for (TriedRotation& other : tried)
      if (std::abs(q.dot(other.q)) > cos_same_rotation)
        return other;
    tried.push_back({q, candidatesUnder(R), {}});
    return tried.back();
  };
  // The angles between reference directions, once (the loops below visit each pair many times).
  const std::size_t n_ref = ref_dirs.size();
  std::vector<double> ref_angle(n_ref * n_ref);
  for (std::size_t i = 0; i < n_ref; ++i)
    for (std::size_t j = 0; j < n_ref; ++j)
      ref_angle[i * n_ref + j] = angleBetween(ref_dirs[i].direction, ref_dirs[j].direction);
  // With a prior, a current direction can only be matched to a reference direction within the
  // prior's rotation bound (plus the matching tolerance) of where the prior rotation puts it.
  const double cos_prior_reach =
      prior_ ? std::cos(std::min(M_PI, prior_->max_rotation + p_.max_angle_difference)) : -1.0;
  const auto reachable = [&](const DirectionFeature& c, const DirectionFeature& r) {
    return !prior_ ||
           (prior_->T_reference_current.linear() * c.direction).dot(r.direction) >= cos_prior_reach;
  };
  for (std::size_t a = 0; a < cur_dirs.size(); ++a) {
    for (std::size_t b = a + 1; b < cur_dirs.size(); ++b) {
      const DirectionFeature& ca = cur_dirs[a];
      const DirectionFeature& cb = cur_dirs[b];
      if (ca.surface == cb.surface)
        continue;
      const double cur_angle = angleBetween(ca.direction, cb.direction);
      if (cur_angle < p_.min_pair_angle || cur_angle > M_PI - p_.min_pair_angle)
        continue;
      const Eigen::Matrix3d cur_frame = directionFrame(ca.direction, cb.direction);
      for (std::size_t i = 0; i < n_ref; ++i) {
        const DirectionFeature& ra = ref_dirs[i];
        if (!sameShape(cur_[ca.surface], ref_[ra.surface]) || !reachable(ca, ra))
          continue;
        for (std::size_t j = 0; j < n_ref; ++j) {
          const DirectionFeature& rb = ref_dirs[j];
          if (ref_[rb.surface].source == ref_[ra.surface].source ||
              !sameShape(cur_[cb.surface], ref_[rb.surface]))
            continue;
          if (std::abs(ref_angle[i * n_ref + j] - cur_angle) > p_.max_angle_difference ||
              !reachable(cb, rb))
            continue;
          const Eigen::Matrix3d R = kabsch(cur_frame, directionFrame(ra.direction, rb.direction));
          if (!withinPrior(R))
            continue;
          TriedRotation& entry = rotationEntry(R);
          const std::vector<Pair>& candidates = entry.candidates;
          // The two defining pairs, then each other candidate in turn as the third constraint.
          Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
          Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
          addConstraints(cur_[ca.surface], ref_[ra.surface], R, 1.0, AtA, Atb);
          addConstraints(cur_[cb.surface], ref_[rb.surface], R, 1.0, AtA, Atb);
          // The line's point nearest the prior's translation (the origin without a prior).
          const Eigen::Vector3d line = solve(AtA, Atb, nullptr);
          bool line_tried = false;
          for (const Eigen::Vector3d& other : entry.lines)
            line_tried = line_tried || (other - line).norm() < p_.max_offset_difference;
          if (line_tried)
            continue;
          entry.lines.push_back(line);
          SurfaceAlignment best;
          double best_distance = 0.0;
          const auto consider = [&](const Eigen::Vector3d& t) {
            if (!withinPrior(t))
              return;
            SurfaceAlignment s = score(candidates, R, t);
            const double distance = distanceFromPrior(R, t);
            if (better(s, distance, best, best_distance)) {
              best = std::move(s);
              best_distance = distance;
            }
          };
          if (prior_)
            consider(line);  // the line's point nearest the prior: what two surfaces say
          for (const Pair& third : candidates) {
            if (third.current == ca.surface || third.current == cb.surface)
              continue;
            Eigen::Matrix3d A3 = AtA;
            Eigen::Vector3d b3 = Atb;
            addConstraints(cur_[third.current], ref_[third.reference], R, 1.0, A3, b3);
            double conditioning = 0.0;
            const Eigen::Vector3d t = solve(A3, b3, &conditioning);
            if (conditioning < 1e-3 && !prior_)
              continue;  // the three leave a direction free: no position from them
            consider(t);
          }
          if (best.supporting > 0)
            out.push_back(std::move(best));
        }
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const SurfaceAlignment& a, const SurfaceAlignment& b) {
    return a.weight > b.weight;
  });
  return out;
}

}  // namespace

int appendMatchableSurface(const QuadricModel& quadric, int source, double weight,
                           bool plane_towards_origin, std::vector<MatchableSurface>* out) {
  MatchableSurface s;
  s.source = source;
  s.weight = weight;
  try {
    switch (quadric.quadricClass()) {
      case QuadricClass::kPlane: {
        const PlaneShape plane = planeShape(quadric);
        s.kind = Kind::kPlane;
        // n.p = d with d <= 0: the origin lies on the side the normal points to.
        const double sign = plane.offset > 0 ? -1.0 : 1.0;
        s.direction = sign * plane.normal;
        s.offset = sign * plane.offset;
        break;
      }
      case QuadricClass::kSphere: {
        const SphereShape sphere = sphereShape(quadric);
        s.kind = Kind::kSphere;
        s.point = sphere.center;
        s.size = sphere.radius;
        break;
      }
      case QuadricClass::kCylinder: {
        const CylinderShape cylinder = cylinderShape(quadric);
        s.kind = Kind::kCylinder;
        s.direction = cylinder.axis;
        s.point = cylinder.point;
        s.size = cylinder.radius;
        break;
      }
      case QuadricClass::kCone: {
        const ConeShape cone = coneShape(quadric);
        s.kind = Kind::kCone;
        s.direction = cone.axis;
        s.point = cone.apex;
        s.size = cone.half_angle;
        break;
      }
      default:
        return 0;  // general quadrics: no invariant used here
    }
  } catch (const std::invalid_argument&) {
    return 0;  // a degenerate shape
  }
  if (!s.direction.allFinite() || !s.point.allFinite() || !std::isfinite(s.offset) ||
      !std::isfinite(s.size) || !std::isfinite(s.weight))
    return 0;
  out->push_back(s);
  if (s.kind != Kind::kPlane || plane_towards_origin)
    return 1;
  s.direction = -s.direction;
  s.offset = -s.offset;
  out->push_back(s);
  return 2;
}

void SurfaceMatcher::Params::validate() const {
  const ParamRangeCheck check("SurfaceMatcher::Params");
  if (!(max_angle_difference > 0 && max_angle_difference <= 0.5))
    check.fail("max_angle_difference", "(0, 0.5] rad", max_angle_difference);
  if (!(max_offset_difference > 0 && max_offset_difference <= 1))
    check.fail("max_offset_difference", "(0, 1] m", max_offset_difference);
  if (!(max_radius_fraction > 0 && max_radius_fraction < 1))
    check.fail("max_radius_fraction", "(0, 1)", max_radius_fraction);
  if (!(min_pair_angle > 0 && min_pair_angle < M_PI / 2))
    check.fail("min_pair_angle", "(0, pi/2) rad", min_pair_angle);
  if (max_current_features < 2 || max_current_features > 64)
    check.fail("max_current_features", "[2, 64]", max_current_features);
  if (max_reference_features < 2 || max_reference_features > 64)
    check.fail("max_reference_features", "[2, 64]", max_reference_features);
}

SurfaceMatcher::SurfaceMatcher(const Params& params) : params_((params.validate(), params)) {}

std::vector<SurfaceAlignment> SurfaceMatcher::align(const std::vector<MatchableSurface>& reference,
                                                    const std::vector<MatchableSurface>& current,
                                                    const PairTest& test,
                                                    const MotionPrior* prior) const {
  return Hypotheses(params_, reference, current, test, prior).run();
}

SurfaceAlignment SurfaceMatcher::refine(const std::vector<MatchableSurface>& reference,
                                        const std::vector<MatchableSurface>& current,
                                        const SurfaceAlignment& alignment, const PairTest& test,
                                        const MotionPrior* prior) const {
  const Hypotheses hypotheses(params_, reference, current, test, prior);
  const Eigen::Matrix3d R0 = alignment.T_reference_current.linear();
  std::vector<Eigen::Vector3d> u, v;
  std::vector<double> w;
  for (const auto& [c_index, r_index] : alignment.pairs) {
    const MatchableSurface& c = current[c_index];
    const MatchableSurface& r = reference[r_index];
    if (c.kind == Kind::kSphere)
      continue;
    Eigen::Vector3d dc = c.direction;
    if (axial(c.kind) && (R0 * dc).dot(r.direction) < 0)
      dc = -dc;
    u.push_back(dc);
    v.push_back(r.direction);
    w.push_back(c.weight);
  }
  // The rotation from all directions only when they span more than one direction.
  Eigen::Matrix3d R = R0;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < u.size(); ++i)
    spread += w[i] * u[i] * u[i].transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread_eig(spread);
  if (spread_eig.eigenvalues()(1) > 0.05 * spread_eig.eigenvalues()(2))
    R = kabsch(u, v, w);
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
  for (const auto& [c_index, r_index] : alignment.pairs)
    Hypotheses::addConstraints(current[c_index], reference[r_index], R, current[c_index].weight,
                               AtA, Atb);
  double conditioning = 0.0;
  const Eigen::Vector3d t = hypotheses.solve(AtA, Atb, &conditioning);
  // Re-score under the refined pose; the rotation may have moved a direction out of the gate.
  std::vector<Pair> candidates;
  for (std::size_t i = 0; i < current.size(); ++i)
    for (std::size_t j = 0; j < reference.size(); ++j)
      if (hypotheses.compatible(current[i], reference[j], R))
        candidates.push_back({static_cast<int>(i), static_cast<int>(j)});
  SurfaceAlignment out = hypotheses.score(candidates, R, t);
  out.translation_conditioning = conditioning;
  return out;
}

}  // namespace quadric_slam
