// Map evaluation against a truth map (the generator's quadrics_gt.yaml), from the human-readable
// `shape` keys of the map schema (io/map_yaml.h):
//   plane normal + offset, sphere center + radius, cylinder point + axis + radius,
//   cone apex + axis + half_angle; an ellipsoid (the general class with the ellipsoid signature)
//   from its pose and scale (semi-axes 1 / scale along the quadric axes).
// The estimated map is first moved into the truth frame (T_truth_estimate, e.g. the ATE alignment
// of the estimated trajectory onto the ground truth). Each estimate is assigned to the nearest true
// primitive of its class whose every shape error is within that class's gate; per true primitive
// the nearest assigned estimate is its match, further assigned estimates are duplicates, and a true
// primitive without any is a miss. Estimates assigned to no truth are counted as unmatched.
// Two more conditions tell coplanar truths apart (a floor and the disc of a column standing on it,
// two desk tops at one height), which the shape errors alone cannot:
//   - where both carry an extent (map schema extent_min/extent_max), the estimate's box must
//     overlap the truth's, each grown by extent_margin_m;
//   - where the truth file counts the frames that saw each truth (`observations`, as the
//     generator writes), a truth seen in no frame takes no estimate.
// A truth's `observations` is also its seen_frames: the misses among truths seen in at least
// min_seen_frames frames are reported apart (a surface seen in a handful of frames at a grazing
// angle is not expected in the map), and so are those among truths with that many large views
// (the truth's `large_views`: frames in which it covered 2000 pixels or more).
// Classes other than plane, sphere, cylinder, cone and ellipsoid (e.g. "general": a hyperboloid)
// are not evaluated (counted as skipped).
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "quadric_slam/io/map_yaml.h"

namespace quadric_slam {

// One named shape error of a matched pair, in the unit its name ends with (_deg or _m).
struct ShapeError {
  std::string name;  // e.g. "normal_angle_deg", "offset_m"
  double value = 0;
};

// Shape errors of an estimate against a truth of the same class (both in the truth frame), in a
// fixed order per class:
//   plane:    normal_angle_deg (unsigned normal), offset_m (|d_t - d_e| after orienting n_e like
//   n_t) sphere:   center_m, radius_m cylinder: axis_angle_deg (unsigned axis), axis_distance_m
//   (truth point to estimated axis line),
//             radius_m
//   cone:     apex_m, axis_angle_deg (unsigned: the quadric is a double cone), half_angle_deg
//   ellipsoid: center_m, semi_axis_1_m, semi_axis_2_m, semi_axis_3_m (the semi-axes of both
//             sorted longest first: the frame's axis order is arbitrary), axis_angle_deg (unsigned,
//             between the longest axes)
// Throws std::runtime_error naming the quadric id and key when a shape key is missing or malformed,
// std::invalid_argument when the classes differ or are not evaluated.
std::vector<ShapeError> shapeErrors(const MapFileQuadric& truth, const MapFileQuadric& estimate);

// The quadric's shape keys moved by T_b_a (from frame a into frame b); pose moved too.
MapFileQuadric transformQuadric(const MapFileQuadric& quadric, const Eigen::Isometry3d& T_b_a);

// True for the classes map evaluation understands (plane, sphere, cylinder, cone, ellipsoid).
bool isEvaluatedClass(const std::string& quadric_class);

struct TruthResult {
  int truth_id = 0;
  std::string quadric_class;
  bool matched = false;
  int estimate_id = -1;            // the match, when matched
  double distance = 0;             // normalised shape distance of the match (see Params)
  std::vector<ShapeError> errors;  // of the match, when matched
  std::vector<int> duplicate_ids;  // further estimates assigned to this truth
  int seen_frames = 0;             // the truth's `observations`: frames it was visible in
  int large_views = 0;             // the truth's `large_views`: frames it covered >= 2000 px in
};

struct ClassSummary {
  int truths = 0, matched = 0, misses = 0, duplicates = 0, unmatched_estimates = 0;
  std::vector<ShapeError> mean_errors;  // mean over matched truths, same names/order as errors
};

struct MapReport {
  std::vector<TruthResult> truths;              // in truth-file order (evaluated classes only)
  std::map<std::string, ClassSummary> classes;  // keyed by class name
  int matched = 0, misses = 0, duplicates = 0, unmatched_estimates = 0;
  int skipped_truths = 0, skipped_estimates = 0;  // classes not evaluated
  // Misses among the truths seen in at least min_seen_frames frames (0 when the truth file counts
  // no views), and that threshold.
  int seen_misses = 0;
  int min_seen_frames = 0;
  // Misses among the truths with at least min_seen_frames large views (2000 pixels or more).
  int large_view_misses = 0;
};

class MapEvaluator {
 public:
  // Gates: an estimate can match a truth only when every shape error is within its gate. The
  // normalised distance used to pick the nearest is sqrt(sum (error / gate)^2).
  struct Params {
    double plane_angle_gate_deg = 15.0;
    double plane_offset_gate_m = 0.15;
    double sphere_center_gate_m = 0.2;
    double sphere_radius_gate_m = 0.1;
    double cylinder_angle_gate_deg = 15.0;
    double cylinder_axis_distance_gate_m = 0.15;
    double cylinder_radius_gate_m = 0.1;
    double cone_apex_gate_m = 0.2;
    double cone_angle_gate_deg = 15.0;
    double cone_half_angle_gate_deg = 10.0;
    double ellipsoid_center_gate_m = 0.2;
    double ellipsoid_semi_axis_gate_m = 0.1;  // each of the three sorted semi-axes
    double ellipsoid_angle_gate_deg = 30.0;   // the longest axes
    // Each extent box is grown by this before the overlap test (m): the noise of an estimated
    // box's edges and the points a segmenter loses along a surface's boundary.
    double extent_margin_m = 0.1;
    // A truth seen in at least this many frames is expected in the map (its miss is reported
    // as seen_misses), >= 1.
    int min_seen_frames = 30;

    // Throws std::invalid_argument naming the bad field and its allowed range (0, inf).
    void validate() const;
  };

  MapEvaluator() : MapEvaluator(Params{}) {}
  explicit MapEvaluator(const Params& params);

  // Gates of a class, in the order of shapeErrors().
  std::vector<double> gates(const std::string& quadric_class) const;

  MapReport evaluate(const MapFile& truth, const MapFile& estimate,
                     const Eigen::Isometry3d& T_truth_estimate) const;

 private:
  Params params_;
};

// --- Accuracy by range: near surfaces are measured better than far ones (the sensor's noise
// grows with the square of depth), so a map's errors are also reported per band of range.
//
// A true primitive's range: the median over the camera positions (truth frame) of the distance
// from the camera to its surface (plane: perpendicular; sphere, cylinder: exact; cone: to the
// nearest of its lines in the camera's axial plane; ellipsoid: to its surface along the line to
// its centre). Keyed by truth id; classes not evaluated are
// left out. Throws std::invalid_argument when there are no camera positions.
std::map<int, double> truthRanges(const MapFile& truth,
                                  const std::vector<Eigen::Vector3d>& camera_positions);
// The band a range falls in, for ascending edges (m): "0-2m", "2-4m", "4m+" for {2, 4}.
std::string rangeBand(double range_m, const std::vector<double>& edges);
// Per "<class> <band>" summaries of the report's truths (their matches, misses, duplicates and
// mean errors); truths without a range are left out; unmatched estimates belong to no truth and
// are not counted here.
std::map<std::string, ClassSummary> summariseByRange(const MapReport& report,
                                                     const std::map<int, double>& ranges,
                                                     const std::vector<double>& edges);

// Human-readable report: one line per true primitive, one per class, one per class and range band
// (when by_range is given: "class_range plane 0-2m truths N ..."), and a final summary line
// "map_summary matched N misses N duplicates N unmatched_estimates N".
std::string formatMapReport(const MapReport& report,
                            const std::map<std::string, ClassSummary>* by_range = nullptr);

}  // namespace quadric_slam
