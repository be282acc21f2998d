// Data association (the paper's Section IV, "Data association"): each observed quadric is matched
// to the map quadric of the same class with the lowest error of the observation cost (eqs. 20-22)
// at the predicted camera pose (the previous estimate composed with the latest odometry), accepted
// under a chi-square gate for the class's minimal dimension k.
//
// The gate. With r0 the unwhitened residual of QuadricObservationCost (eq. 22 with L = I: the
// measurement-frame minimal error) and J_c, J_q its Jacobians w.r.t. the camera and landmark
// tangents, the error is the Mahalanobis distance under the innovation covariance
//   S = Sigma_z + Sigma_floor + J_c P_c J_c^T + J_q P_q J_q^T,     d^2 = r0^T S^-1 r0,
// gated at chi2_k(gate_probability). Sigma_z is the front-end's fit covariance: from thousands of
// points it is tiny (sub-mm, sub-0.1 deg), so on its own a 1 deg pose error would fail every
// gate. Hence (parameters below): P_c = the caller's prediction covariance (odometry since the last
// optimised pose) plus a pose floor, which the camera Jacobian turns into the lever-arm-correct
// error in each minimal entry (a rotation error moves a distant plane's offset more); P_q = the
// landmark's marginal covariance when known; Sigma_floor = a model-error floor in the minimal space
// (translation entries, rotation entries, and scale entries relative to the target's scale).
//
// Sigma_z counts the depth noise of the n supporting points as independent. A depth camera's noise
// is not: a structured-light camera matches its pattern over a window of pixels, so most of its
// noise is shared by neighbouring pixels over a cell of about noise_correlation_angle seen from
// the camera. Over a support of area A at depth z that share averages over the
// n_c = clamp(A / (noise_correlation_angle z)^2, 1, n) cells the support covers, not over its n
// points, so the fit's covariance rms^2 (J^T J)^-1 understates it by n / n_c along the fit's own
// directions; the gate uses
//   Sigma_z' = Sigma_z (1 + f (n / n_c - 1)),     f = correlated_noise_fraction,
// (the least-squares covariance of a noise whose share f is correlated over cells). This matters
// most along a fit's weak direction: a band of a cone seen from one side fixes the radius where it
// is seen but hardly how it splits into half-angle, apex height along the axis and axis tilt, and
// that combination scatters from frame to frame far beyond what n independent points would allow.
// (A candidate keeps its measurement's Sigma_z: inflating it too let more one-off detections of a
// real room reach five observations, 130 -> 143 landmarks on the first 300 kitchen frames.)
// Spheres, cylinders and cones only. A plane's fit has no such weak combination of parameters, and
// its gate is already held open by the floor and the pose terms; inflating it as well let close
// parallel surfaces of a real kitchen (doors, drawer fronts) share landmarks: 1000 frames, SLAM
// ATE 2.8 -> 3.8 cm. General quadrics carry their model error in Sigma_z already.
//
// Across classes: a measurement no landmark of its class takes may still lie on a landmark of
// another class (a cone's band fitted as a cylinder): mapping/association_cross_class.h, applied by
// the registry (cross_class_distance below).
//
// Extents: a match must also let the observed box of supporting points (moved into the target's
// quadric frame through the predicted pose) overlap the target's box, grown by extent_margin: a
// second table top at the same height is the same infinite plane, but not the same surface.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <vector>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/mapping/extent_box.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

// Something a measurement can be associated with (a landmark or a candidate), in the map frame.
struct AssociationTarget {
  int id = 0;                  // landmark or candidate id (reported back, never interpreted)
  QuadricModel quadric_map;    // T_map_quadric, S, class
  Eigen::MatrixXd covariance;  // k x k in the class's minimal space at quadric_map, or empty
  ExtentBox extent;            // box of supporting points in the target's quadric frame (m)
};

enum class AssociationOutcome {
  kMatched,          // target_index names the match
  kNoTargetOfClass,  // no target of its class (and signature, for kGeneral) within max_range
  kOutsideGate,      // the best target's d^2 is above the gate
  kNoOverlap,        // targets inside the gate exist, but none whose extent overlaps
  kTakenByBetter,    // every acceptable target went to another measurement with a lower d^2
};

struct Association {
  AssociationOutcome outcome = AssociationOutcome::kNoTargetOfClass;
  int target_index = -1;                                           // into the targets, when matched
  double squared_error = std::numeric_limits<double>::infinity();  // d^2 of the best target
};

class QuadricAssociator {
 public:
  struct Params {
    // Chi-square probability of the gate, (0, 1): 0.999 accepts 99.9% of true matches.
    double gate_probability = 0.999;
    // Model-error floor Sigma_floor (1-sigma) on the translation entries of the minimal vector
    // (m, >= 0), the rotation entries (rad, >= 0) and the scale entries as a fraction of the
    // target's scale (>= 0).
    double floor_translation_sigma = 0.02;
    double floor_rotation_sigma = 0.02;
    double floor_scale_fraction = 0.05;
    // Floor of the predicted camera pose uncertainty P_c (1-sigma, body frame), added to the
    // caller's prediction covariance: m and rad, >= 0. The defaults tolerate ~3 deg / 10 cm of
    // pose error at the 99.9% gate.
    double pose_translation_sigma = 0.03;
    double pose_rotation_sigma = 0.02;
    // The depth noise's spatially correlated share f ([0, 1]; 0 treats the points as independent)
    // and the angle over which it is correlated, seen from the camera (rad, (0, 0.5]): see above.
    // The defaults are those of the Kinect v1 model calibrated on real frames (85% of the noise
    // variance low-passed over 4 px, a cell of 2 sqrt(pi) 4 px ~ 14 px at f = 580 px).
    double correlated_noise_fraction = 0.85;
    double noise_correlation_angle = 0.025;
    // Reject matches whose extents (grown by extent_margin, m, >= 0) do not overlap.
    bool check_extent = true;
    double extent_margin = 0.25;
    // Targets whose (known) extent box is farther than this from the camera centre are not
    // compared at all (m, > 0): keeps the per-frame cost to the landmarks around the camera as the
    // map grows. Targets without a known extent are always compared.
    double max_range = 10.0;
    // A measurement left unmatched by the landmarks of its class is counted on a landmark of
    // another class whose surface lies within this RMS distance of the observed surface over its
    // box (m, >= 0; 0 turns the test off; pairs in mapping/association_cross_class.h: cylinder <->
    // cone, sphere -> cylinder, cone, general, ellipsoid -> any curved landmark; and cylinders,
    // cones and spheres with their own class: a partial view whose parameters the gate refused),
    // extents overlapping as above. It gives no factor (the observation cost compares one class;
    // a general measurement the gate refused would pull its landmark's poorly determined shape).
    double cross_class_distance = 0.02;
    // ... or within this many times the measurement's own fit RMS, when that is larger (>= 0; 0:
    // the fixed distance alone). At 2-3 m a depth camera's points scatter by 1-2 cm about their
    // fit, and a cylinder fitted to the visible band of a cone there leans by 10-25 deg and lies
    // 3-9 cm from the cone over its box: one frame cannot tell the two surfaces apart closer than
    // its points' scatter allows.
    double cross_class_rms_factor = 3.0;

    // The cross-class distance gate for a measurement whose fit has RMS fit_rms (m).
    double crossClassGate(double fit_rms) const;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  QuadricAssociator() : QuadricAssociator(Params{}) {}
  explicit QuadricAssociator(const Params& params);

  // The gate chi2_k(gate_probability) for the class's minimal dimension k.
  double gate(QuadricClass quadric_class) const;

  // d^2 of a measurement against one target of the same class at T_map_camera, with
  // pose_covariance the 6x6 prediction covariance of T_map_camera (body tangent [rho; phi]) to
  // which the pose floor is added. Throws std::invalid_argument when the classes differ or a
  // covariance has the wrong size or is not positive definite.
  double squaredError(const QuadricMeasurement& measurement, const Eigen::Isometry3d& T_map_camera,
                      const Matrix6d& pose_covariance, const AssociationTarget& target) const;

  // The measurement's covariance as the gate uses it (Sigma_z' above; planes, the general class,
  // whose covariance already holds the segmenter's model error, and measurements without points
  // or extent keep Sigma_z).
  Eigen::MatrixXd associationCovariance(const QuadricMeasurement& measurement) const;
  // The factor 1 + f (n / n_c - 1) of Sigma_z' (1 when it does not apply: planes, general
  // quadrics, f = 0).
  double correlatedNoiseFactor(const QuadricMeasurement& measurement) const;

  // False when the box `extent` (in the frame of quadric_map) is known and farther than max_range
  // from the camera centre: such a target is not compared (callers may skip building it).
  bool inRange(const QuadricModel& quadric_map, const ExtentBox& extent,
               const Eigen::Isometry3d& T_map_camera) const;

  // One association per measurement, one-to-one: all acceptable (gate and extent) pairs are taken
  // in order of increasing d^2. Classes never mix; general quadrics also need equal signatures.
  std::vector<Association> associate(const std::vector<QuadricMeasurement>& measurements,
                                     const Eigen::Isometry3d& T_map_camera,
                                     const Matrix6d& pose_covariance,
                                     const std::vector<AssociationTarget>& targets) const;

  const Params& params() const { return params_; }

 private:
  // squaredError with the measurement's gate covariance (associationCovariance) given.
  double squaredError(const QuadricMeasurement& measurement,
                      const Eigen::MatrixXd& measurement_covariance,
                      const Eigen::Isometry3d& T_map_camera, const Matrix6d& pose_covariance,
                      const AssociationTarget& target) const;
  Params params_;
  std::array<double, 5> gates_{};
};

// The chi-square quantile: x with P(chi2_k <= x) = probability. Throws std::invalid_argument for
// k < 1 or a probability outside (0, 1).
double chiSquareQuantile(int degrees_of_freedom, double probability);

// True when a measurement may be compared with a target: same class, and for kGeneral the same
// signature.
bool sameKind(const QuadricModel& a, const QuadricModel& b);

}  // namespace quadric_slam
