#include "quadric_slam/odometry/quadric_motion_guess.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/odometry/pose_math.h"

namespace quadric_slam {
namespace {

enum class Kind { kPlane, kSphere, kCylinder, kCone };

// A surface reduced to what the guess compares, in its frame's camera coordinates.
struct Surface {
  Kind kind = Kind::kPlane;
  int index = 0;                                      // position in the frame's observations
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // plane normal (towards the camera), axis
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // sphere centre, axis point, cone apex
  double offset = 0.0;                              // plane: n.p = offset (< 0: camera in front)
  double size = 0.0;                                // radius (m) or cone half-angle (rad)
  double weight = 1.0;                              // sqrt(supporting points)
};

// A direction that can define a rotation: a plane normal or cone axis, or one of the two signs of a
// cylinder's axis (whose sign the fit does not fix).
struct DirectionFeature {
  int surface = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

std::vector<Surface> surfacesOf(const std::vector<QuadricMeasurement>& observations,
                                int min_plane_points) {
  std::vector<Surface> out;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const QuadricMeasurement& m = observations[i];
    Surface s;
    s.index = static_cast<int>(i);
    s.weight = std::sqrt(std::max(1, m.num_points));
    switch (m.quadric_camera.quadricClass()) {
      case QuadricClass::kPlane: {
        if (m.num_points < min_plane_points)
          continue;
        const PlaneShape plane = planeShape(m.quadric_camera);
        s.kind = Kind::kPlane;
        // A visible surface faces the camera, in every frame that sees it: orienting each normal
        // towards the camera makes the signs of the two frames agree.
        const double sign = plane.offset > 0 ? -1.0 : 1.0;
        s.direction = sign * plane.normal;
        s.offset = sign * plane.offset;
        break;
      }
      case QuadricClass::kSphere: {
        const SphereShape sphere = sphereShape(m.quadric_camera);
        s.kind = Kind::kSphere;
        s.point = sphere.center;
        s.size = sphere.radius;
        break;
      }
      case QuadricClass::kCylinder: {
        const CylinderShape cylinder = cylinderShape(m.quadric_camera);
        s.kind = Kind::kCylinder;
        s.direction = cylinder.axis;
        s.point = cylinder.point;
        s.size = cylinder.radius;
        break;
      }
      case QuadricClass::kCone: {
        const ConeShape cone = coneShape(m.quadric_camera);
        s.kind = Kind::kCone;
        s.direction = cone.axis;
        s.point = cone.apex;
        s.size = cone.half_angle;
        break;
      }
      default:
        continue;  // general quadrics: no invariant used here
    }
    if (s.direction.allFinite() && s.point.allFinite() && std::isfinite(s.offset))
      out.push_back(s);
  }
  return out;
}

// The largest surfaces with a direction, as features; cylinders give both signs when `both_signs`.
std::vector<DirectionFeature> directionFeatures(const std::vector<Surface>& surfaces, int max_count,
                                                bool both_signs) {
  std::vector<int> order;
  for (std::size_t i = 0; i < surfaces.size(); ++i)
    if (surfaces[i].kind != Kind::kSphere)
      order.push_back(static_cast<int>(i));
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return surfaces[a].weight > surfaces[b].weight; });
  if (static_cast<int>(order.size()) > max_count)
    order.resize(max_count);
  std::vector<DirectionFeature> out;
  for (int i : order) {
    out.push_back({i, surfaces[i].direction});
    if (both_signs && surfaces[i].kind == Kind::kCylinder)
      out.push_back({i, -surfaces[i].direction});
  }
  return out;
}

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

// A current surface and a reference surface that may be the same under a rotation.
struct Pair {
  int current = 0, reference = 0;
};

class Hypotheses {
 public:
  Hypotheses(const QuadricMotionGuesser::Params& params, const std::vector<Surface>& reference,
             const std::vector<Surface>& current, const Eigen::Isometry3d& prior)
      : p_(params), ref_(reference), cur_(current), prior_(prior) {}

  bool sameShape(const Surface& c, const Surface& r) const {
    if (c.kind != r.kind)
      return false;
    if (c.kind == Kind::kCone)
      return std::abs(c.size - r.size) <= p_.max_angle_difference;
    if (c.kind == Kind::kSphere || c.kind == Kind::kCylinder)
      return std::abs(c.size - r.size) <= p_.max_radius_fraction * std::max(c.size, r.size);
    return true;
  }

  // Same class, same size and, under R, the same direction (a cylinder's axis up to its sign).
  bool compatible(const Surface& c, const Surface& r, const Eigen::Matrix3d& R) const {
    if (!sameShape(c, r))
      return false;
    if (c.kind == Kind::kSphere)
      return true;
    const Eigen::Vector3d d = R * c.direction;
    const double angle = c.kind == Kind::kCylinder ? std::acos(std::min(1.0, std::abs(d.dot(r.direction))))
                                                   : angleBetween(d, r.direction);
    return angle <= p_.max_angle_difference;
  }

  // Adds the linear constraints on t of a pair to A t = b (weight w per row).
  void addConstraints(const Surface& c, const Surface& r, const Eigen::Matrix3d& R, double w,
                      Eigen::Matrix3d& AtA, Eigen::Vector3d& Atb) const {
    switch (c.kind) {
      case Kind::kPlane: {
        // n_r . (R p_c + t) = d_r for every p_c with n_c . p_c = d_c  =>  n_r . t = d_r - d_c.
        const Eigen::Vector3d n = r.direction;
        AtA += w * n * n.transpose();
        Atb += w * n * (r.offset - c.offset);
        break;
      }
      case Kind::kSphere:
      case Kind::kCone:
        // R c_c + t = c_r (centre or apex).
        AtA += w * Eigen::Matrix3d::Identity();
        Atb += w * (r.point - R * c.point);
        break;
      case Kind::kCylinder: {
        // The axis points agree across the axis: P (R p_c + t - p_r) = 0, P = I - a a^T.
        const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - r.direction * r.direction.transpose();
        AtA += w * P;
        Atb += w * P * (r.point - R * c.point);
        break;
      }
    }
  }

  // Distance of the pair under (R, t) in the quantity the class is compared by (m).
  double residual(const Surface& c, const Surface& r, const Eigen::Matrix3d& R,
                  const Eigen::Vector3d& t) const {
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

  // Solves the accumulated constraints, the prior's translation filling the directions they leave
  // free (a small weight: it only decides where the data says nothing).
  Eigen::Vector3d solve(Eigen::Matrix3d AtA, Eigen::Vector3d Atb, bool* prior_used) const {
    const double scale = std::max(1.0, AtA.trace());
    const double prior_weight = 1e-6 * scale;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(AtA);
    if (prior_used)
      *prior_used = eig.eigenvalues()(0) < 1e-3 * scale;
    AtA += prior_weight * Eigen::Matrix3d::Identity();
    Atb += prior_weight * prior_.translation();
    return AtA.ldlt().solve(Atb);
  }

  struct Score {
    int count = 0;
    double weight = 0.0;
    std::vector<Pair> inliers;  // the best reference surface of each supporting current surface
  };

  Score score(const std::vector<Pair>& candidates, const Eigen::Matrix3d& R,
              const Eigen::Vector3d& t) const {
    Score s;
    std::vector<double> best(cur_.size(), std::numeric_limits<double>::infinity());
    std::vector<int> best_ref(cur_.size(), -1);
    for (const Pair& pair : candidates) {
      const double r = residual(cur_[pair.current], ref_[pair.reference], R, t);
      if (r <= p_.max_offset_difference && r < best[pair.current]) {
        best[pair.current] = r;
        best_ref[pair.current] = pair.reference;
      }
    }
    for (std::size_t i = 0; i < cur_.size(); ++i) {
      if (best_ref[i] < 0)
        continue;
      ++s.count;
      s.weight += cur_[i].weight;
      s.inliers.push_back({static_cast<int>(i), best_ref[i]});
    }
    return s;
  }

  double distanceFromPrior(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
    return (t - prior_.translation()).norm() +
           angleBetweenRotations(R, prior_.linear()) * 1.0;  // 1 m per rad
  }
  static double angleBetweenRotations(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
    return Eigen::AngleAxisd(a * b.transpose()).angle();
  }

  QuadricMotionGuess run() const;

 private:
  const QuadricMotionGuesser::Params& p_;
  const std::vector<Surface>& ref_;
  const std::vector<Surface>& cur_;
  Eigen::Isometry3d prior_;
};

QuadricMotionGuess Hypotheses::run() const {
  QuadricMotionGuess out;
  out.usable_surfaces = static_cast<int>(cur_.size());
  const std::vector<DirectionFeature> cur_dirs =
      directionFeatures(cur_, p_.max_direction_features, /*both_signs=*/true);
  const std::vector<DirectionFeature> ref_dirs =
      directionFeatures(ref_, p_.max_direction_features, /*both_signs=*/false);

  Score best;
  double best_prior_distance = 0.0;
  Eigen::Matrix3d best_R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d best_t = Eigen::Vector3d::Zero();
  int hypotheses = 0;
  // Fragments of one surface and repeated parallel surfaces propose the same rotation many times:
  // each distinct rotation is scored once.
  std::vector<Eigen::Quaterniond> tried;
  const auto alreadyTried = [&](const Eigen::Matrix3d& R) {
    const Eigen::Quaterniond q(R);
    for (const Eigen::Quaterniond& other : tried)
      if (q.angularDistance(other) < 0.5 * p_.max_angle_difference)
        return true;
    tried.push_back(q);
    return false;
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
      for (const DirectionFeature& ra : ref_dirs) {
        if (!sameShape(cur_[ca.surface], ref_[ra.surface]))
          continue;
        for (const DirectionFeature& rb : ref_dirs) {
          if (rb.surface == ra.surface || !sameShape(cur_[cb.surface], ref_[rb.surface]))
            continue;
          if (std::abs(angleBetween(ra.direction, rb.direction) - cur_angle) >
              p_.max_angle_difference)
            continue;
          const Eigen::Matrix3d R =
              kabsch({ca.direction, cb.direction, ca.direction.cross(cb.direction).normalized()},
                     {ra.direction, rb.direction, ra.direction.cross(rb.direction).normalized()},
                     {1.0, 1.0, 1.0});
          if (angleBetweenRotations(R, prior_.linear()) > p_.max_rotation_from_prior)
            continue;
          ++hypotheses;
          if (alreadyTried(R))
            continue;
          // Every pair the rotation makes possible.
          std::vector<Pair> candidates;
          for (std::size_t i = 0; i < cur_.size(); ++i)
            for (std::size_t j = 0; j < ref_.size(); ++j)
              if (compatible(cur_[i], ref_[j], R))
                candidates.push_back({static_cast<int>(i), static_cast<int>(j)});
          // The two defining pairs, then each candidate in turn as the third constraint.
          Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
          Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
          addConstraints(cur_[ca.surface], ref_[ra.surface], R, 1.0, AtA, Atb);
          addConstraints(cur_[cb.surface], ref_[rb.surface], R, 1.0, AtA, Atb);
          std::vector<Eigen::Vector3d> translations = {solve(AtA, Atb, nullptr)};
          for (const Pair& third : candidates) {
            if (third.current == ca.surface || third.current == cb.surface)
              continue;
            Eigen::Matrix3d A3 = AtA;
            Eigen::Vector3d b3 = Atb;
            addConstraints(cur_[third.current], ref_[third.reference], R, 1.0, A3, b3);
            translations.push_back(solve(A3, b3, nullptr));
          }
          for (const Eigen::Vector3d& t : translations) {
            if ((t - prior_.translation()).norm() > p_.max_translation_from_prior)
              continue;
            Score s = score(candidates, R, t);
            const double prior_distance = distanceFromPrior(R, t);
            // More agreeing surface (by weight); among equals, the one nearer the prior.
            const bool better = s.weight > best.weight * 1.02 ||
                                (s.weight >= best.weight * 0.98 && s.count >= best.count &&
                                 prior_distance < best_prior_distance);
            if (best.count == 0 || better) {
              best = std::move(s);
              best_prior_distance = prior_distance;
              best_R = R;
              best_t = t;
            }
          }
        }
      }
    }
  }
  if (hypotheses == 0) {
    out.message = "no pair of non-parallel surfaces seen in both frames";
    return out;
  }
  if (best.count < p_.min_supporting_surfaces) {
    std::ostringstream why;
    why << "best of " << hypotheses << " hypotheses agrees with " << best.count
        << " surfaces, fewer than " << p_.min_supporting_surfaces;
    out.message = why.str();
    return out;
  }

  // Refinement over every supporting pair: the rotation from all directions (when they span more
  // than one), then the translation from all constraints.
  std::vector<Eigen::Vector3d> u, v;
  std::vector<double> w;
  for (const Pair& pair : best.inliers) {
    const Surface& c = cur_[pair.current];
    const Surface& r = ref_[pair.reference];
    if (c.kind == Kind::kSphere)
      continue;
    Eigen::Vector3d dc = c.direction;
    if (c.kind == Kind::kCylinder && (best_R * dc).dot(r.direction) < 0)
      dc = -dc;
    u.push_back(dc);
    v.push_back(r.direction);
    w.push_back(c.weight);
  }
  Eigen::Matrix3d R = best_R;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < u.size(); ++i)
    spread += w[i] * u[i] * u[i].transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread_eig(spread);
  if (spread_eig.eigenvalues()(1) > 0.05 * spread_eig.eigenvalues()(2))
    R = kabsch(u, v, w);
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
  for (const Pair& pair : best.inliers)
    addConstraints(cur_[pair.current], ref_[pair.reference], R, cur_[pair.current].weight, AtA,
                   Atb);
  bool prior_used = false;
  const Eigen::Vector3d t = solve(AtA, Atb, &prior_used);

  out.found = true;
  out.T_reference_current.linear() = R;
  out.T_reference_current.translation() = t;
  out.T_reference_current = pose_math::orthonormalized(out.T_reference_current);
  out.supporting_surfaces = best.count;
  out.support_weight = best.weight;
  out.translation_from_prior = prior_used;
  return out;
}

}  // namespace

void QuadricMotionGuesser::Params::validate() const {
  auto fail = [](const std::string& field, const std::string& range, double value) {
    std::ostringstream why;
    why << field << " must be in " << range << ", got " << value;
    throw std::invalid_argument(why.str());
  };
  if (!(max_angle_difference > 0 && max_angle_difference <= 0.5))
    fail("max_angle_difference", "(0, 0.5] rad", max_angle_difference);
  if (!(max_offset_difference > 0 && max_offset_difference <= 1))
    fail("max_offset_difference", "(0, 1] m", max_offset_difference);
  if (!(max_radius_fraction > 0 && max_radius_fraction < 1))
    fail("max_radius_fraction", "(0, 1)", max_radius_fraction);
  if (!(min_pair_angle > 0 && min_pair_angle < M_PI / 2))
    fail("min_pair_angle", "(0, pi/2) rad", min_pair_angle);
  if (min_plane_points < 0)
    fail("min_plane_points", "[0, inf)", min_plane_points);
  if (max_direction_features < 2 || max_direction_features > 64)
    fail("max_direction_features", "[2, 64]", max_direction_features);
  if (!(max_rotation_from_prior > 0 && max_rotation_from_prior <= M_PI))
    fail("max_rotation_from_prior", "(0, pi] rad", max_rotation_from_prior);
  if (!(max_translation_from_prior > 0 && std::isfinite(max_translation_from_prior)))
    fail("max_translation_from_prior", "(0, inf) m", max_translation_from_prior);
  if (min_supporting_surfaces < 2 || min_supporting_surfaces > 1000)
    fail("min_supporting_surfaces", "[2, 1000]", min_supporting_surfaces);
}

QuadricMotionGuesser::QuadricMotionGuesser() : QuadricMotionGuesser(Params{}) {}

QuadricMotionGuesser::QuadricMotionGuesser(const Params& params)
    : params_((params.validate(), params)) {}

QuadricMotionGuess QuadricMotionGuesser::guess(
    const std::vector<QuadricMeasurement>& reference,
    const std::vector<QuadricMeasurement>& current,
    const Eigen::Isometry3d& T_reference_current_prior) const {
  const std::vector<Surface> ref = surfacesOf(reference, params_.min_plane_points);
  const std::vector<Surface> cur = surfacesOf(current, params_.min_plane_points);
  return Hypotheses(params_, ref, cur, T_reference_current_prior).run();
}

}  // namespace quadric_slam
