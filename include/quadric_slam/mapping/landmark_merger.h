// "Each surface once": which landmarks of the map are the same surface, and what one landmark
// holding both is. A segmenter reports a large surface in fragments (a wall cut by an occluder, a
// floor split at a shadow), and a fragment that is not associated with the surface's landmark
// (another fragment took it, or its extent did not yet overlap) becomes a second landmark of the
// same surface. Two landmarks a, b are the same surface when
//   1. they are of the same kind (class, and signature for general quadrics);
//   2. their parameters agree within their joint covariance: with x = b' [-] a their difference
//      in the class's minimal space (mapping/surface_fusion.h; b' = b re-expressed by the symmetry
//      element closest to a),
//        d^2 = x^T (C_a + C_b' + F)^-1 x <= chi2_k(gate_probability),
//      (with their cross-covariance C_ab when the caller has it, the covariance of the difference
//      C_a + C_b' - C_ab' - C_ab'^T: landmarks seen from the same views share those views' pose
//      errors, which the marginals count twice; in a batch over a whole run, whose marginals hold
//      the drift from its first frame, that is most of them),
//      where C are the landmarks' marginal covariances (missing ones, e.g. of a candidate, a
//      loaded landmark or a window whose marginals failed, are replaced by the `missing_*`
//      covariance) and F is a model-error floor (the window's marginals only know the sensor noise
//      of the fitted points, not a surface's deviation from its ideal shape);
//   3. their extents touch: b's box of observed points, moved into a's quadric frame, overlaps
//      a's box once each is grown by extent_margin (mapping/extent_box.h). This is what keeps two
//      table tops at one height, far apart, as two landmarks: they pass 1 and 2. Landmarks with an
//      unknown extent never merge (no evidence that they touch).
// The survivor of a merge is the landmark with more observations (ties: the older, smaller id),
// except that a fixed landmark (a loaded, trusted map) always survives and keeps its estimate, and
// two fixed landmarks are never merged. The survivor's estimate is the information-weighted fusion
// of both (surface_fusion.h), whose covariance is no larger than either part's.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/mapping/extent_box.h"
#include "quadric_slam/mapping/landmark.h"

namespace quadric_slam {

// One landmark merged into another. T_survivor_merged is the merged landmark's quadric frame in
// the survivor's (at the estimates the merge used, the survivor's after fusion): things stored in
// the merged landmark's frame (reconstruction points) are re-expressed with it.
struct LandmarkMerge {
  int merged_id = 0;
  int survivor_id = 0;
  Eigen::Isometry3d T_survivor_merged = Eigen::Isometry3d::Identity();
};

// Records in `merged_into` (id merged away -> the landmark holding its surface) that merged_id went
// into survivor_id, resolving chains: ids that went into merged_id now go into survivor_id.
void recordMerge(int merged_id, int survivor_id, std::map<int, int>* merged_into);

// Two landmarks found to be the same surface, and their d^2.
struct DuplicatePair {
  int id_a = 0, id_b = 0;
  double squared_distance = 0.0;
};

// Cross-covariances Cov(a, b) (rows: a's minimal tangent, columns: b's) of pairs of landmarks,
// keyed by (id a, id b) with id a < id b.
using CrossCovariances = std::map<std::pair<int, int>, Eigen::MatrixXd>;

class LandmarkMerger {
 public:
  struct Params {
    // Merge at all (at promotion, after each window solve, before a map is saved).
    bool enabled = true;
    // Chi-square probability of the parameter test, (0, 1).
    double gate_probability = 0.999;
    // Model-error floor F (1-sigma) on translation (m, >= 0), rotation (rad, >= 0) and scale
    // (fraction of the landmark's scale, >= 0) entries of the minimal vector.
    double floor_translation_sigma = 0.005;
    double floor_rotation_sigma = 0.005;
    double floor_scale_fraction = 0.02;
    // Covariance assumed for an estimate without one (1-sigma; m, rad, fraction; each > 0): that
    // of a single measurement placed at a predicted pose (the association floor's values).
    double missing_translation_sigma = 0.02;
    double missing_rotation_sigma = 0.02;
    double missing_scale_fraction = 0.05;
    // Each extent box is grown by this before the touch test (m, >= 0): the noise of a box edge
    // (depth noise, and the points a segmenter loses along a surface's boundary).
    double extent_margin = 0.05;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Comparison {
    double squared_distance = std::numeric_limits<double>::infinity();  // d^2 (inf: other kind)
    bool within_gate = false;
    bool extents_touch = false;
    bool sameSurface() const { return within_gate && extents_touch; }
  };

  LandmarkMerger() : LandmarkMerger(Params{}) {}
  explicit LandmarkMerger(const Params& params);

  // The chi-square bound for the class's minimal dimension.
  double gate(QuadricClass quadric_class) const;
  // The covariance the tests use for `landmark`: its own when it is k x k, else the missing one.
  Eigen::MatrixXd covarianceOf(const QuadricLandmark& landmark) const;

  // Tests 1-3 above (symmetric up to the linearisation); cross_ab = Cov(a, b) when known.
  Comparison compare(const QuadricLandmark& a, const QuadricLandmark& b,
                     const Eigen::MatrixXd* cross_ab = nullptr) const;

  // The pairs (id a < id b) of the same kind whose extent boxes, in the map frame and grown by
  // extent_margin, overlap, with at least one member in `subset` (every landmark when null): the
  // only pairs that can be the same surface.
  std::vector<std::pair<int, int>> nearPairs(const std::map<int, QuadricLandmark>& landmarks,
                                             const std::set<int>* subset = nullptr) const;
  // Every pair of landmarks that are the same surface and have at least one member in `subset`
  // (every landmark when subset is null), by increasing d^2; with `cross`, the pairs it holds are
  // tested with their cross-covariance. The cheap box test of nearPairs() comes first, so the cost
  // is one box test per pair and one chi-square test per near pair.
  std::vector<DuplicatePair> findDuplicates(const std::map<int, QuadricLandmark>& landmarks,
                                            const std::set<int>* subset = nullptr,
                                            const CrossCovariances* cross = nullptr) const;

  // The survivor after absorbing `merged`: its id; the fusion of both estimates (quadric and k x k
  // covariance in its minimal tangent; with keep_estimate, a fixed survivor's own); the union of
  // both extents in the new quadric frame; the summed observation counts; the later stamp.
  // Throws std::invalid_argument for different kinds.
  QuadricLandmark fused(const QuadricLandmark& survivor, const QuadricLandmark& merged,
                        bool keep_estimate = false) const;
  // The survivor rule above without fixed landmarks: true when `a` survives a merge with `b`.
  static bool survives(const QuadricLandmark& a, const QuadricLandmark& b);
  // One merge of a and b (a_fixed, b_fixed: held fixed, a loaded, trusted map) when they are the
  // same surface, tested again (an earlier merge may have changed one) and not both fixed: the
  // survivor by the rule above, after absorbing the other (fused(); a fixed survivor keeps its
  // estimate), with `merge` filled in. nullopt when they are not merged.
  std::optional<QuadricLandmark> mergePair(const QuadricLandmark& a, bool a_fixed,
                                           const QuadricLandmark& b, bool b_fixed,
                                           LandmarkMerge* merge,
                                           const Eigen::MatrixXd* cross_ab = nullptr) const;

  const Params& params() const { return params_; }

 private:
  Params params_;
  std::array<double, 5> gates_{};
};

}  // namespace quadric_slam
