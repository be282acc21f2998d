#include "quadric_slam/mapping/landmark_merger.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>
#include <string>

#include "quadric_slam/mapping/association.h"
#include "quadric_slam/mapping/surface_fusion.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {

namespace {

ExtentBox extentOf(const QuadricLandmark& landmark) {
  return ExtentBox{landmark.extent_min, landmark.extent_max};
}

bool isCovariance(const Eigen::MatrixXd& covariance, int k) {
  return covariance.rows() == k && covariance.cols() == k && covariance.allFinite();
}

Eigen::MatrixXd inverseOf(const Eigen::MatrixXd& spd) {
  return spd.llt().solve(Eigen::MatrixXd::Identity(spd.rows(), spd.cols()));
}

}  // namespace

void recordMerge(int merged_id, int survivor_id, std::map<int, int>* merged_into) {
  for (auto& [id, into] : *merged_into)
    if (into == merged_id)
      into = survivor_id;
  (*merged_into)[merged_id] = survivor_id;
}

void LandmarkMerger::Params::validate() const {
  const ParamRangeCheck requireRange("LandmarkMerger::Params");
  requireRange(gate_probability > 0.0 && gate_probability < 1.0, "gate_probability", "(0, 1)");
  requireRange(floor_translation_sigma >= 0.0, "floor_translation_sigma", "[0, inf) m");
  requireRange(floor_rotation_sigma >= 0.0, "floor_rotation_sigma", "[0, inf) rad");
  requireRange(floor_scale_fraction >= 0.0, "floor_scale_fraction", "[0, inf)");
  requireRange(missing_translation_sigma > 0.0, "missing_translation_sigma", "(0, inf) m");
  requireRange(missing_rotation_sigma > 0.0, "missing_rotation_sigma", "(0, inf) rad");
  requireRange(missing_scale_fraction > 0.0, "missing_scale_fraction", "(0, inf)");
  requireRange(extent_margin >= 0.0, "extent_margin", "[0, inf) m");
}

LandmarkMerger::LandmarkMerger(const Params& params) : params_(params) {
  params_.validate();
  for (QuadricClass c : kAllQuadricClasses)
    gates_[static_cast<int>(c)] = chiSquareQuantile(minimalDimension(c), params_.gate_probability);
}

double LandmarkMerger::gate(QuadricClass quadric_class) const {
  return gates_.at(static_cast<int>(quadric_class));
}

Eigen::MatrixXd LandmarkMerger::covarianceOf(const QuadricLandmark& landmark) const {
  const QuadricModel& q = landmark.quadric_map;
  if (isCovariance(landmark.covariance, minimalDimension(q.quadricClass())))
    return landmark.covariance;
  return diagonalMinimalCovariance(q, params_.missing_translation_sigma,
                                   params_.missing_rotation_sigma, params_.missing_scale_fraction);
}

LandmarkMerger::Comparison LandmarkMerger::compare(const QuadricLandmark& a,
                                                   const QuadricLandmark& b,
                                                   const Eigen::MatrixXd* cross_ab) const {
  Comparison out;
  if (!sameKind(a.quadric_map, b.quadric_map))
    return out;
  const ExtentBox box_a = extentOf(a), box_b = extentOf(b);
  out.extents_touch = box_a.known() && box_b.known() &&
                      box_b.transformed(a.quadric_map.pose().inverse() * b.quadric_map.pose())
                          .overlaps(box_a, params_.extent_margin);

  // d^2 = x^T (C_a + C_b' - C_ab' - C_ab'^T + F)^-1 x with x = b' [-] a (surface_fusion.h).
  const AlignedSurface b_aligned = alignCovariance(b.quadric_map, covarianceOf(b), a.quadric_map);
  const Eigen::VectorXd x = b_aligned.quadric.minusMinimal(a.quadric_map);
  Eigen::MatrixXd S =
      covarianceOf(a) + b_aligned.matrix +
      diagonalMinimalCovariance(a.quadric_map, params_.floor_translation_sigma,
                                params_.floor_rotation_sigma, params_.floor_scale_fraction);
  if (cross_ab != nullptr && cross_ab->rows() == S.rows() && cross_ab->cols() == S.cols() &&
      cross_ab->allFinite()) {
    const Eigen::MatrixXd cross_aligned = *cross_ab * b_aligned.transform.transpose();
    S -= cross_aligned + cross_aligned.transpose();
  }
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success || !x.allFinite())
    return out;
  out.squared_distance = x.dot(llt.solve(x));
  out.within_gate = out.squared_distance <= gate(a.quadric_map.quadricClass());
  return out;
}

std::vector<std::pair<int, int>> LandmarkMerger::nearPairs(
    const std::map<int, QuadricLandmark>& landmarks, const std::set<int>* subset) const {
  // Landmarks with a known extent, with their boxes in the map frame (grown below).
  struct Entry {
    const QuadricLandmark* landmark;
    ExtentBox box_map;
  };
  std::vector<Entry> entries;
  entries.reserve(landmarks.size());
  for (const auto& [id, landmark] : landmarks) {
    const ExtentBox box = extentOf(landmark);
    if (box.known())
      entries.push_back({&landmark, box.transformed(landmark.quadric_map.pose())});
  }
  auto inSubset = [&](int id) { return subset == nullptr || subset->count(id) > 0; };
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < entries.size(); ++i) {
    const QuadricLandmark& a = *entries[i].landmark;
    const bool a_in = inSubset(a.id);
    for (size_t j = i + 1; j < entries.size(); ++j) {
      const QuadricLandmark& b = *entries[j].landmark;
      if ((a_in || inSubset(b.id)) && sameKind(a.quadric_map, b.quadric_map) &&
          entries[i].box_map.overlaps(entries[j].box_map, params_.extent_margin))
        pairs.emplace_back(a.id, b.id);
    }
  }
  return pairs;
}

std::vector<DuplicatePair> LandmarkMerger::findDuplicates(
    const std::map<int, QuadricLandmark>& landmarks, const std::set<int>* subset,
    const CrossCovariances* cross) const {
  std::vector<DuplicatePair> pairs;
  for (const auto& [id_a, id_b] : nearPairs(landmarks, subset)) {
    const Eigen::MatrixXd* cross_ab = nullptr;
    if (cross != nullptr) {
      const auto it = cross->find({id_a, id_b});
      if (it != cross->end())
        cross_ab = &it->second;
    }
    const Comparison c = compare(landmarks.at(id_a), landmarks.at(id_b), cross_ab);
    if (c.sameSurface())
      pairs.push_back({id_a, id_b, c.squared_distance});
  }
  std::sort(pairs.begin(), pairs.end(), [](const DuplicatePair& p, const DuplicatePair& q) {
    return p.squared_distance < q.squared_distance ||
           (p.squared_distance == q.squared_distance &&
            std::make_pair(p.id_a, p.id_b) < std::make_pair(q.id_a, q.id_b));
  });
  return pairs;
}

bool LandmarkMerger::survives(const QuadricLandmark& a, const QuadricLandmark& b) {
  return a.observations > b.observations || (a.observations == b.observations && a.id < b.id);
}

std::optional<QuadricLandmark> LandmarkMerger::mergePair(const QuadricLandmark& a, bool a_fixed,
                                                         const QuadricLandmark& b, bool b_fixed,
                                                         LandmarkMerge* merge,
                                                         const Eigen::MatrixXd* cross_ab) const {
  if ((a_fixed && b_fixed) || !compare(a, b, cross_ab).sameSurface())
    return std::nullopt;
  const bool a_survives = a_fixed || (!b_fixed && survives(a, b));
  const QuadricLandmark& survivor = a_survives ? a : b;
  const QuadricLandmark& merged = a_survives ? b : a;
  QuadricLandmark out = fused(survivor, merged, a_fixed || b_fixed);
  *merge = {merged.id, survivor.id,
            Eigen::Isometry3d(out.quadric_map.pose().inverse() * merged.quadric_map.pose())};
  return out;
}

QuadricLandmark LandmarkMerger::fused(const QuadricLandmark& survivor,
                                      const QuadricLandmark& merged, bool keep_estimate) const {
  if (!sameKind(survivor.quadric_map, merged.quadric_map))
    throw std::invalid_argument("LandmarkMerger::fused: landmarks " + std::to_string(survivor.id) +
                                " and " + std::to_string(merged.id) + " are of different kinds");
  QuadricLandmark out = survivor;
  if (!keep_estimate) {
    const SurfaceInformation fusion =
        fuseSurfaces({survivor.quadric_map, inverseOf(covarianceOf(survivor))},
                     {merged.quadric_map, inverseOf(covarianceOf(merged))});
    out.quadric_map = fusion.mean;
    // A covariance made up for a missing one is a weight, not a result: the fused covariance is
    // reported only when both parts had one (the next window solve computes it otherwise).
    const int k = minimalDimension(survivor.quadric_map.quadricClass());
    if (isCovariance(survivor.covariance, k) && isCovariance(merged.covariance, k)) {
      out.covariance = inverseOf(fusion.information);
      out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
    } else {
      out.covariance.resize(0, 0);
    }
  }
  const Eigen::Isometry3d T_new_map = out.quadric_map.pose().inverse();
  const ExtentBox box =
      extentOf(survivor)
          .transformed(T_new_map * survivor.quadric_map.pose())
          .merged(extentOf(merged).transformed(T_new_map * merged.quadric_map.pose()));
  out.extent_min = box.min;
  out.extent_max = box.max;
  out.observations = survivor.observations + merged.observations;
  out.last_observed = std::max(survivor.last_observed, merged.last_observed);
  return out;
}

}  // namespace quadric_slam
