#include "quadric_slam/mapping/association.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/mapping/measurement_model_error.h"
#include "quadric_slam/mapping/observation_linearization.h"
#include "quadric_slam/mapping/surface_fusion.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {

namespace {

// Diagonal model-error floor in the class's minimal space (translation, rotation and scale
// entries of Table II's minimal vector).
Eigen::MatrixXd floorCovariance(const QuadricAssociator::Params& p, const QuadricModel& target) {
  return diagonalMinimalCovariance(target, p.floor_translation_sigma, p.floor_rotation_sigma,
                                   p.floor_scale_fraction);
}

// Regularised lower incomplete gamma P(a, x) by its power series (converges for every x > 0; the
// gates need x < ~200).
double gammaP(double a, double x) {
  if (x <= 0.0)
    return 0.0;
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 100000 && term > sum * 1e-16; ++n) {
    term *= x / (a + n);
    sum += term;
  }
  return std::min(1.0, std::exp(-x + a * std::log(x) - std::lgamma(a)) * sum);
}

}  // namespace

// Bisection on the chi-square CDF P(k/2, x/2). (boost::math's inverse returns NaN for most k under
// the -frounding-math that CGAL requires, so the project computes its own.)
double chiSquareQuantile(int degrees_of_freedom, double probability) {
  if (degrees_of_freedom < 1 || !(probability > 0.0 && probability < 1.0))
    throw std::invalid_argument("chiSquareQuantile: needs k >= 1 and probability in (0, 1)");
  double lo = 0.0, hi = 1.0;
  while (gammaP(0.5 * degrees_of_freedom, 0.5 * hi) < probability)
    hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (gammaP(0.5 * degrees_of_freedom, 0.5 * mid) < probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

bool sameKind(const QuadricModel& a, const QuadricModel& b) {
  if (a.quadricClass() != b.quadricClass())
    return false;
  return a.quadricClass() != QuadricClass::kGeneral || a.signature() == b.signature();
}

void QuadricAssociator::Params::validate() const {
  const ParamRangeCheck requireRange("QuadricAssociator::Params");
  requireRange(gate_probability > 0.0 && gate_probability < 1.0, "gate_probability", "(0, 1)");
  requireRange(floor_translation_sigma >= 0.0, "floor_translation_sigma", "[0, inf) m");
  requireRange(floor_rotation_sigma >= 0.0, "floor_rotation_sigma", "[0, inf) rad");
  requireRange(floor_scale_fraction >= 0.0, "floor_scale_fraction", "[0, inf)");
  requireRange(pose_translation_sigma >= 0.0, "pose_translation_sigma", "[0, inf) m");
  requireRange(pose_rotation_sigma >= 0.0, "pose_rotation_sigma", "[0, inf) rad");
  requireRange(correlated_noise_fraction >= 0.0 && correlated_noise_fraction <= 1.0,
               "correlated_noise_fraction", "[0, 1]");
  requireRange(noise_correlation_angle > 0.0 && noise_correlation_angle <= 0.5,
               "noise_correlation_angle", "(0, 0.5] rad");
  requireRange(extent_margin >= 0.0, "extent_margin", "[0, inf) m");
  requireRange(max_range > 0.0, "max_range", "(0, inf) m");
  requireRange(cross_class_distance >= 0.0, "cross_class_distance", "[0, inf) m");
  requireRange(cross_class_rms_factor >= 0.0, "cross_class_rms_factor", "[0, inf)");
}

double QuadricAssociator::Params::crossClassGate(double fit_rms) const {
  if (cross_class_distance <= 0.0)
    return 0.0;  // the test is off
  return std::max(cross_class_distance, cross_class_rms_factor * std::max(0.0, fit_rms));
}

QuadricAssociator::QuadricAssociator(const Params& params) : params_(params) {
  params_.validate();
  for (QuadricClass c : kAllQuadricClasses) {
    gates_[static_cast<int>(c)] = chiSquareQuantile(minimalDimension(c), params_.gate_probability);
  }
}

double QuadricAssociator::gate(QuadricClass quadric_class) const {
  return gates_.at(static_cast<int>(quadric_class));
}

double QuadricAssociator::correlatedNoiseFactor(const QuadricMeasurement& measurement) const {
  const double f = params_.correlated_noise_fraction;
  const double n = static_cast<double>(measurement.num_points);
  const QuadricClass c = measurement.quadric_camera.quadricClass();
  if (f == 0.0 || n < 2.0 || c == QuadricClass::kGeneral || c == QuadricClass::kPlane)
    return 1.0;
  const Eigen::Vector3d sides = (measurement.extent_max - measurement.extent_min).cwiseAbs();
  if (!sides.allFinite() || sides.maxCoeff() <= 0.0)
    return 1.0;  // no extent to count correlation cells on
  MeasurementModelError::Params cells_of;
  cells_of.correlation_angle = params_.noise_correlation_angle;
  const double cells = MeasurementModelError::independentCells(measurement, cells_of);
  return 1.0 + f * (n / cells - 1.0);
}

Eigen::MatrixXd QuadricAssociator::associationCovariance(
    const QuadricMeasurement& measurement) const {
  return measurement.covariance * correlatedNoiseFactor(measurement);
}

double QuadricAssociator::squaredError(const QuadricMeasurement& measurement,
                                       const Eigen::Isometry3d& T_map_camera,
                                       const Matrix6d& pose_covariance,
                                       const AssociationTarget& target) const {
  return squaredError(measurement, associationCovariance(measurement), T_map_camera,
                      pose_covariance, target);
}

double QuadricAssociator::squaredError(const QuadricMeasurement& measurement,
                                       const Eigen::MatrixXd& measurement_covariance,
                                       const Eigen::Isometry3d& T_map_camera,
                                       const Matrix6d& pose_covariance,
                                       const AssociationTarget& target) const {
  const QuadricModel& z = measurement.quadric_camera;
  if (!sameKind(z, target.quadric_map))
    throw std::invalid_argument("QuadricAssociator: measurement and target of different classes");
  const QuadricClass c = z.quadricClass();
  const int k = minimalDimension(c);
  if (measurement.covariance.rows() != k || measurement.covariance.cols() != k)
    throw std::invalid_argument("QuadricAssociator: measurement covariance is not k x k");
  if (target.covariance.size() != 0 &&
      (target.covariance.rows() != k || target.covariance.cols() != k))
    throw std::invalid_argument("QuadricAssociator: target covariance is not k x k");

  const ObservationLinearization lin = linearizeObservation(z, T_map_camera, target.quadric_map);
  if (!lin.valid)
    return std::numeric_limits<double>::infinity();
  // k <= 9: S and its factor on the stack (d^2 is computed for every overlapping pair).
  using MatrixKK = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 9, 9>;
  using MatrixK6 = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::ColMajor, 9, 6>;
  const MatrixK6& J_c = lin.J_camera;
  const MatrixKK& J_q = lin.J_quadric;

  Matrix6d P = pose_covariance;
  const double st = params_.pose_translation_sigma, sr = params_.pose_rotation_sigma;
  P.diagonal() += (Vector6d() << st * st, st * st, st * st, sr * sr, sr * sr, sr * sr).finished();
  const MatrixK6 J_c_P = J_c.lazyProduct(P);
  MatrixKK S = measurement_covariance + floorCovariance(params_, target.quadric_map);
  S += J_c_P.lazyProduct(J_c.transpose());
  if (target.covariance.size() != 0) {
    const MatrixKK J_q_C = J_q.lazyProduct(target.covariance);
    S += J_q_C.lazyProduct(J_q.transpose());
  }
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<MatrixKK> llt(S);
  if (llt.info() != Eigen::Success)
    throw std::invalid_argument("QuadricAssociator: innovation covariance not positive definite");
  return lin.residual.dot(llt.solve(lin.residual));
}

bool QuadricAssociator::inRange(const QuadricModel& quadric_map, const ExtentBox& extent,
                                const Eigen::Isometry3d& T_map_camera) const {
  if (!extent.known())
    return true;
  const Eigen::Vector3d c = quadric_map.pose().inverse() * T_map_camera.translation();
  const Eigen::Vector3d outside = (extent.min - c).cwiseMax(c - extent.max).cwiseMax(0.0);
  return outside.norm() <= params_.max_range;
}

std::vector<Association> QuadricAssociator::associate(
    const std::vector<QuadricMeasurement>& measurements, const Eigen::Isometry3d& T_map_camera,
    const Matrix6d& pose_covariance, const std::vector<AssociationTarget>& targets) const {
  struct Pair {
    double d2;
    int measurement, target;
  };
  std::vector<Association> out(measurements.size());
  std::vector<Pair> acceptable;
  // Targets near enough to be compared: distance from the camera centre to the extent box.
  std::vector<bool> near(targets.size(), true);
  for (size_t t = 0; t < targets.size(); ++t)
    near[t] = inRange(targets[t].quadric_map, targets[t].extent, T_map_camera);
  // The extent test (a box transform) is much cheaper than d^2 (a linearised observation and a
  // k x k solve), and most pairs in a room fail it: pairs whose extents do not overlap are
  // deferred, and their d^2 is computed only for the measurements left unmatched, where it decides
  // between kOutsideGate and kNoOverlap and the reported best d^2. Same outcomes as testing every
  // pair, at a fraction of the cost.
  std::vector<std::vector<int>> deferred(measurements.size());
  // Each measurement's gate covariance once, not once per target it is compared with.
  std::vector<Eigen::MatrixXd> measurement_covariance;
  measurement_covariance.reserve(measurements.size());
  for (const QuadricMeasurement& measurement : measurements)
    measurement_covariance.push_back(associationCovariance(measurement));
  // d^2 of a pair, kept as the measurement's best; the pair's d^2 when inside the gate, else NaN.
  auto evaluate = [&](size_t m, size_t t) {
    const double d2 = squaredError(measurements[m], measurement_covariance[m], T_map_camera,
                                   pose_covariance, targets[t]);
    if (d2 < out[m].squared_error)
      out[m].squared_error = d2;
    if (out[m].outcome == AssociationOutcome::kNoTargetOfClass)
      out[m].outcome = AssociationOutcome::kOutsideGate;
    return d2 <= gate(measurements[m].quadric_camera.quadricClass())
               ? d2
               : std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<bool> any_in_gate(measurements.size(), false);
  for (size_t m = 0; m < measurements.size(); ++m) {
    const QuadricMeasurement& measurement = measurements[m];
    const ExtentBox observed{measurement.extent_min, measurement.extent_max};
    const Eigen::Isometry3d T_map_observed = T_map_camera * measurement.quadric_camera.pose();
    for (size_t t = 0; t < targets.size(); ++t) {
      if (!near[t] || !sameKind(measurement.quadric_camera, targets[t].quadric_map))
        continue;
      if (params_.check_extent) {
        const ExtentBox moved =
            observed.transformed(targets[t].quadric_map.pose().inverse() * T_map_observed);
        if (!moved.overlaps(targets[t].extent, params_.extent_margin)) {
          deferred[m].push_back(static_cast<int>(t));
          if (out[m].outcome == AssociationOutcome::kNoTargetOfClass)
            out[m].outcome = AssociationOutcome::kOutsideGate;
          continue;
        }
      }
      const double d2 = evaluate(m, t);
      if (std::isnan(d2))
        continue;
      any_in_gate[m] = true;
      acceptable.push_back({d2, static_cast<int>(m), static_cast<int>(t)});
    }
  }
  for (const Pair& pair : acceptable)
    out[pair.measurement].outcome = AssociationOutcome::kTakenByBetter;
  std::sort(acceptable.begin(), acceptable.end(), [](const Pair& a, const Pair& b) {
    return a.d2 < b.d2 || (a.d2 == b.d2 && a.target < b.target);
  });
  std::vector<bool> target_taken(targets.size(), false);
  std::vector<bool> measurement_done(measurements.size(), false);
  for (const Pair& pair : acceptable) {
    if (measurement_done[pair.measurement] || target_taken[pair.target])
      continue;
    measurement_done[pair.measurement] = target_taken[pair.target] = true;
    Association& a = out[pair.measurement];
    a.outcome = AssociationOutcome::kMatched;
    a.target_index = pair.target;
    a.squared_error = pair.d2;
  }
  // The deferred (non-overlapping) pairs of the unmatched measurements: the best d^2, and
  // kNoOverlap for a measurement whose only targets inside the gate do not overlap.
  for (size_t m = 0; m < measurements.size(); ++m) {
    if (out[m].outcome == AssociationOutcome::kMatched)
      continue;
    for (int t : deferred[m])
      if (!std::isnan(evaluate(m, static_cast<size_t>(t))))
        any_in_gate[m] = true;
    if (any_in_gate[m] && out[m].outcome == AssociationOutcome::kOutsideGate)
      out[m].outcome = AssociationOutcome::kNoOverlap;
  }
  return out;
}

}  // namespace quadric_slam
