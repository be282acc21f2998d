#include "quadric_slam/eval/map_metrics.h"

#include "quadric_slam/mapping/extent_box.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace quadric_slam {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

const std::vector<double>& shapeValues(const MapFileQuadric& q, const std::string& key,
                                       std::size_t size) {
  const auto it = q.shape.find(key);
  if (it == q.shape.end()) {
    throw std::runtime_error("quadric " + std::to_string(q.id) + " (" + q.quadric_class +
                             "): missing shape key '" + key + "'");
  }
  if (it->second.size() != size) {
    throw std::runtime_error("quadric " + std::to_string(q.id) + " (" + q.quadric_class +
                             "): shape key '" + key + "' needs " + std::to_string(size) +
                             " values, got " + std::to_string(it->second.size()));
  }
  for (double v : it->second) {
    if (!std::isfinite(v)) {
      throw std::runtime_error("quadric " + std::to_string(q.id) + ": shape key '" + key +
                               "' is not finite");
    }
  }
  return it->second;
}

Eigen::Vector3d point(const MapFileQuadric& q, const std::string& key) {
  const std::vector<double>& v = shapeValues(q, key, 3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

Eigen::Vector3d direction(const MapFileQuadric& q, const std::string& key) {
  const Eigen::Vector3d d = point(q, key);
  if (!(d.norm() > 1e-12)) {
    throw std::runtime_error("quadric " + std::to_string(q.id) + ": shape key '" + key +
                             "' is a zero vector");
  }
  return d.normalized();
}

double scalar(const MapFileQuadric& q, const std::string& key) {
  return shapeValues(q, key, 1)[0];
}

void setPoint(MapFileQuadric& q, const std::string& key, const Eigen::Vector3d& p) {
  q.shape[key] = {p.x(), p.y(), p.z()};
}

// Angle between two lines (unsigned directions), degrees; atan2 keeps small angles accurate.
double lineAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b))) * kRadToDeg;
}

double distanceToLine(const Eigen::Vector3d& p, const Eigen::Vector3d& line_point,
                      const Eigen::Vector3d& unit_direction) {
  const Eigen::Vector3d v = p - line_point;
  return (v - v.dot(unit_direction) * unit_direction).norm();
}

// True unless both carry an extent and their boxes, grown by margin, do not meet (both in one
// frame; the estimate's box is moved into the truth's quadric frame).
bool extentsOverlap(const MapFileQuadric& truth, const MapFileQuadric& estimate, double margin) {
  if (!truth.has_extent || !estimate.has_extent)
    return true;
  const ExtentBox truth_box{truth.extent_min, truth.extent_max};
  const ExtentBox estimate_box{estimate.extent_min, estimate.extent_max};
  const Eigen::Isometry3d T_truth_estimate = truth.T_map_quadric.inverse() * estimate.T_map_quadric;
  return truth_box.overlaps(estimate_box.transformed(T_truth_estimate), margin);
}

void requirePositive(double value, const char* name) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw std::invalid_argument(std::string(name) + " must be in (0, inf), got " +
                                std::to_string(value));
  }
}

// An ellipsoid's semi-axes (1 / scale) and their directions (the columns of the quadric frame),
// longest first.
struct EllipsoidAxes {
  Eigen::Vector3d lengths;
  Eigen::Matrix3d directions;
};

EllipsoidAxes ellipsoidAxes(const MapFileQuadric& q) {
  if (!q.scale.allFinite() || !(q.scale.minCoeff() > 0.0))
    throw std::runtime_error("quadric " + std::to_string(q.id) +
                             " (ellipsoid): scale must be finite and > 0");
  const Eigen::Vector3d lengths = q.scale.cwiseInverse();
  std::array<int, 3> order = {0, 1, 2};
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return lengths[a] > lengths[b]; });
  EllipsoidAxes out;
  for (int j = 0; j < 3; ++j) {
    out.lengths[j] = lengths[order[j]];
    out.directions.col(j) = q.T_map_quadric.linear().col(order[j]);
  }
  return out;
}

}  // namespace

bool isEvaluatedClass(const std::string& quadric_class) {
  return quadric_class == "plane" || quadric_class == "sphere" || quadric_class == "cylinder" ||
         quadric_class == "cone" || quadric_class == "ellipsoid";
}

std::vector<ShapeError> shapeErrors(const MapFileQuadric& truth, const MapFileQuadric& estimate) {
  if (truth.quadric_class != estimate.quadric_class || !isEvaluatedClass(truth.quadric_class)) {
    throw std::invalid_argument(
        "shapeErrors compares two plane/sphere/cylinder/cone/ellipsoid quadrics of "
        "one class, got " +
        truth.quadric_class + " and " + estimate.quadric_class);
  }
  const std::string& c = truth.quadric_class;
  if (c == "plane") {
    const Eigen::Vector3d n_t = direction(truth, "normal");
    Eigen::Vector3d n_e = direction(estimate, "normal");
    double d_e = scalar(estimate, "offset") / point(estimate, "normal").norm();
    const double d_t = scalar(truth, "offset") / point(truth, "normal").norm();
    if (n_t.dot(n_e) < 0) {  // (n, d) and (-n, -d) are the same plane
      n_e = -n_e;
      d_e = -d_e;
    }
    return {{"normal_angle_deg", lineAngleDeg(n_t, n_e)}, {"offset_m", std::abs(d_t - d_e)}};
  }
  if (c == "sphere") {
    return {{"center_m", (point(truth, "center") - point(estimate, "center")).norm()},
            {"radius_m", std::abs(scalar(truth, "radius") - scalar(estimate, "radius"))}};
  }
  if (c == "cylinder") {
    const Eigen::Vector3d a_e = direction(estimate, "axis");
    return {
        {"axis_angle_deg", lineAngleDeg(direction(truth, "axis"), a_e)},
        {"axis_distance_m", distanceToLine(point(truth, "point"), point(estimate, "point"), a_e)},
        {"radius_m", std::abs(scalar(truth, "radius") - scalar(estimate, "radius"))}};
  }
  if (c == "ellipsoid") {
    // The frame's axis order is arbitrary (any relabelling is the same surface): compare the
    // semi-axes sorted by length, and the directions of the longest axes.
    const EllipsoidAxes t = ellipsoidAxes(truth), e = ellipsoidAxes(estimate);
    return {{"center_m",
             (truth.T_map_quadric.translation() - estimate.T_map_quadric.translation()).norm()},
            {"semi_axis_1_m", std::abs(t.lengths[0] - e.lengths[0])},
            {"semi_axis_2_m", std::abs(t.lengths[1] - e.lengths[1])},
            {"semi_axis_3_m", std::abs(t.lengths[2] - e.lengths[2])},
            {"axis_angle_deg", lineAngleDeg(t.directions.col(0), e.directions.col(0))}};
  }
  return {{"apex_m", (point(truth, "apex") - point(estimate, "apex")).norm()},
          {"axis_angle_deg", lineAngleDeg(direction(truth, "axis"), direction(estimate, "axis"))},
          {"half_angle_deg",
           std::abs(scalar(truth, "half_angle") - scalar(estimate, "half_angle")) * kRadToDeg}};
}

MapFileQuadric transformQuadric(const MapFileQuadric& quadric, const Eigen::Isometry3d& T_b_a) {
  MapFileQuadric q = quadric;
  q.T_map_quadric = T_b_a * quadric.T_map_quadric;
  const Eigen::Matrix3d R = T_b_a.linear();
  const std::string& c = quadric.quadric_class;
  if (c == "plane") {
    // n.p = d in a  =>  (R n).(R p + t) = d + (R n).t in b.
    const Eigen::Vector3d n = R * point(quadric, "normal");
    setPoint(q, "normal", n);
    q.shape["offset"] = {scalar(quadric, "offset") + n.dot(T_b_a.translation())};
  } else if (c == "sphere") {
    setPoint(q, "center", T_b_a * point(quadric, "center"));
  } else if (c == "cylinder") {
    setPoint(q, "point", T_b_a * point(quadric, "point"));
    setPoint(q, "axis", R * point(quadric, "axis"));
  } else if (c == "cone") {
    setPoint(q, "apex", T_b_a * point(quadric, "apex"));
    setPoint(q, "axis", R * point(quadric, "axis"));
  } else if (c == "ellipsoid" && q.shape.count("center")) {
    setPoint(q, "center", T_b_a * point(quadric, "center"));
  }
  return q;
}

void MapEvaluator::Params::validate() const {
  requirePositive(plane_angle_gate_deg, "plane_angle_gate_deg");
  requirePositive(plane_offset_gate_m, "plane_offset_gate_m");
  requirePositive(sphere_center_gate_m, "sphere_center_gate_m");
  requirePositive(sphere_radius_gate_m, "sphere_radius_gate_m");
  requirePositive(cylinder_angle_gate_deg, "cylinder_angle_gate_deg");
  requirePositive(cylinder_axis_distance_gate_m, "cylinder_axis_distance_gate_m");
  requirePositive(cylinder_radius_gate_m, "cylinder_radius_gate_m");
  requirePositive(cone_apex_gate_m, "cone_apex_gate_m");
  requirePositive(cone_angle_gate_deg, "cone_angle_gate_deg");
  requirePositive(cone_half_angle_gate_deg, "cone_half_angle_gate_deg");
  requirePositive(ellipsoid_center_gate_m, "ellipsoid_center_gate_m");
  requirePositive(ellipsoid_semi_axis_gate_m, "ellipsoid_semi_axis_gate_m");
  requirePositive(ellipsoid_angle_gate_deg, "ellipsoid_angle_gate_deg");
  requirePositive(extent_margin_m, "extent_margin_m");
  requirePositive(min_seen_frames, "min_seen_frames");
}

MapEvaluator::MapEvaluator(const Params& params) : params_(params) {
  params_.validate();
}

std::vector<double> MapEvaluator::gates(const std::string& quadric_class) const {
  const Params& p = params_;
  if (quadric_class == "plane")
    return {p.plane_angle_gate_deg, p.plane_offset_gate_m};
  if (quadric_class == "sphere")
    return {p.sphere_center_gate_m, p.sphere_radius_gate_m};
  if (quadric_class == "cylinder") {
    return {p.cylinder_angle_gate_deg, p.cylinder_axis_distance_gate_m, p.cylinder_radius_gate_m};
  }
  if (quadric_class == "cone") {
    return {p.cone_apex_gate_m, p.cone_angle_gate_deg, p.cone_half_angle_gate_deg};
  }
  if (quadric_class == "ellipsoid") {
    return {p.ellipsoid_center_gate_m, p.ellipsoid_semi_axis_gate_m, p.ellipsoid_semi_axis_gate_m,
            p.ellipsoid_semi_axis_gate_m, p.ellipsoid_angle_gate_deg};
  }
  throw std::invalid_argument("no gates for class '" + quadric_class + "'");
}

MapReport MapEvaluator::evaluate(const MapFile& truth, const MapFile& estimate,
                                 const Eigen::Isometry3d& T_truth_estimate) const {
  MapReport report;
  report.min_seen_frames = params_.min_seen_frames;
  const bool counts_views = std::any_of(truth.quadrics.begin(), truth.quadrics.end(),
                                        [](const MapFileQuadric& q) { return q.observations > 0; });
  std::vector<const MapFileQuadric*> truths;
  for (const MapFileQuadric& q : truth.quadrics) {
    if (!isEvaluatedClass(q.quadric_class)) {
      ++report.skipped_truths;
      continue;
    }
    truths.push_back(&q);
    TruthResult r;
    r.truth_id = q.id;
    r.quadric_class = q.quadric_class;
    r.seen_frames = q.observations;
    r.large_views = q.large_views;
    report.truths.push_back(r);
    ++report.classes[q.quadric_class].truths;
  }

  // Each estimate goes to the nearest gated truth of its class.
  struct Assignment {
    double distance;
    int estimate_id;
    std::vector<ShapeError> errors;
  };
  std::vector<std::vector<Assignment>> assigned(truths.size());
  for (const MapFileQuadric& raw : estimate.quadrics) {
    if (!isEvaluatedClass(raw.quadric_class)) {
      ++report.skipped_estimates;
      continue;
    }
    const MapFileQuadric e = transformQuadric(raw, T_truth_estimate);
    const std::vector<double> gate = gates(e.quadric_class);
    int best = -1;
    Assignment best_assignment{0, e.id, {}};
    for (std::size_t k = 0; k < truths.size(); ++k) {
      if (truths[k]->quadric_class != e.quadric_class)
        continue;
      if (counts_views && truths[k]->observations == 0)
        continue;
      if (!extentsOverlap(*truths[k], e, params_.extent_margin_m))
        continue;
      std::vector<ShapeError> errors = shapeErrors(*truths[k], e);
      bool inside = true;
      double sum = 0;
      for (std::size_t i = 0; i < errors.size(); ++i) {
        inside = inside && errors[i].value <= gate[i];
        sum += (errors[i].value / gate[i]) * (errors[i].value / gate[i]);
      }
      const double distance = std::sqrt(sum);
      if (inside && (best < 0 || distance < best_assignment.distance)) {
        best = static_cast<int>(k);
        best_assignment = {distance, e.id, std::move(errors)};
      }
    }
    if (best < 0) {
      ++report.unmatched_estimates;
      ++report.classes[e.quadric_class].unmatched_estimates;
    } else {
      assigned[static_cast<std::size_t>(best)].push_back(std::move(best_assignment));
    }
  }

  std::map<std::string, std::vector<double>> error_sums;
  for (std::size_t k = 0; k < truths.size(); ++k) {
    TruthResult& r = report.truths[k];
    ClassSummary& summary = report.classes[r.quadric_class];
    std::vector<Assignment>& list = assigned[k];
    if (list.empty()) {
      ++summary.misses;
      ++report.misses;
      if (counts_views && r.seen_frames >= params_.min_seen_frames)
        ++report.seen_misses;
      if (r.large_views >= params_.min_seen_frames)
        ++report.large_view_misses;
      continue;
    }
    std::stable_sort(list.begin(), list.end(), [](const Assignment& a, const Assignment& b) {
      return a.distance < b.distance;
    });
    r.matched = true;
    r.estimate_id = list[0].estimate_id;
    r.distance = list[0].distance;
    r.errors = list[0].errors;
    for (std::size_t i = 1; i < list.size(); ++i)
      r.duplicate_ids.push_back(list[i].estimate_id);
    ++summary.matched;
    ++report.matched;
    summary.duplicates += static_cast<int>(r.duplicate_ids.size());
    report.duplicates += static_cast<int>(r.duplicate_ids.size());
    std::vector<double>& sums = error_sums[r.quadric_class];
    sums.resize(r.errors.size(), 0.0);
    if (summary.mean_errors.empty()) {
      for (const ShapeError& error : r.errors)
        summary.mean_errors.push_back({error.name, 0.0});
    }
    for (std::size_t i = 0; i < r.errors.size(); ++i)
      sums[i] += r.errors[i].value;
  }
  for (auto& [name, summary] : report.classes) {
    for (std::size_t i = 0; i < summary.mean_errors.size(); ++i) {
      summary.mean_errors[i].value = error_sums[name][i] / summary.matched;
    }
  }
  return report;
}

std::map<int, double> truthRanges(const MapFile& truth,
                                  const std::vector<Eigen::Vector3d>& camera_positions) {
  if (camera_positions.empty())
    throw std::invalid_argument("truthRanges: no camera positions");
  std::map<int, double> out;
  for (const MapFileQuadric& q : truth.quadrics) {
    if (!isEvaluatedClass(q.quadric_class))
      continue;
    std::vector<double> distances;
    distances.reserve(camera_positions.size());
    for (const Eigen::Vector3d& p : camera_positions) {
      if (q.quadric_class == "plane") {
        distances.push_back(std::abs(direction(q, "normal").dot(p) - scalar(q, "offset")));
      } else if (q.quadric_class == "sphere") {
        distances.push_back(std::abs((p - point(q, "center")).norm() - scalar(q, "radius")));
      } else if (q.quadric_class == "ellipsoid") {
        // Along the line to the centre: the surface is 1 / |S R^T u| from it in direction u.
        const Eigen::Vector3d v = p - q.T_map_quadric.translation();
        const double radius =
            v.norm() > 0.0
                ? 1.0 / q.scale.cwiseProduct(q.T_map_quadric.linear().transpose() * v.normalized())
                            .norm()
                : 0.0;
        distances.push_back(std::abs(v.norm() - radius));
      } else {
        // Axial and radial coordinates of the camera about the axis.
        const bool cone = q.quadric_class == "cone";
        const Eigen::Vector3d a = direction(q, "axis");
        const Eigen::Vector3d v = p - point(q, cone ? "apex" : "point");
        const double axial = a.dot(v);
        const double radial = (v - axial * a).norm();
        if (!cone) {
          distances.push_back(std::abs(radial - scalar(q, "radius")));
        } else {
          // Distance to the line at half_angle from the axis (the double cone: |axial|).
          const double alpha = scalar(q, "half_angle");
          distances.push_back(
              std::abs(radial * std::cos(alpha) - std::abs(axial) * std::sin(alpha)));
        }
      }
    }
    std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
    out[q.id] = distances[distances.size() / 2];
  }
  return out;
}

std::string rangeBand(double range_m, const std::vector<double>& edges) {
  const auto label = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  double lower = 0.0;
  for (double edge : edges) {
    if (range_m < edge)
      return label(lower) + "-" + label(edge) + "m";
    lower = edge;
  }
  return label(lower) + "m+";
}

std::map<std::string, ClassSummary> summariseByRange(const MapReport& report,
                                                     const std::map<int, double>& ranges,
                                                     const std::vector<double>& edges) {
  std::map<std::string, ClassSummary> out;
  std::map<std::string, std::vector<std::vector<ShapeError>>> errors;
  for (const TruthResult& r : report.truths) {
    const auto range = ranges.find(r.truth_id);
    if (range == ranges.end())
      continue;
    const std::string key = r.quadric_class + " " + rangeBand(range->second, edges);
    ClassSummary& s = out[key];
    ++s.truths;
    s.duplicates += static_cast<int>(r.duplicate_ids.size());
    if (r.matched) {
      ++s.matched;
      errors[key].push_back(r.errors);
    } else {
      ++s.misses;
    }
  }
  for (auto& [key, list] : errors) {
    std::vector<ShapeError>& mean = out[key].mean_errors;
    mean = list.front();
    for (std::size_t i = 0; i < mean.size(); ++i) {
      double sum = 0.0;
      for (const std::vector<ShapeError>& e : list)
        sum += e[i].value;
      mean[i].value = sum / static_cast<double>(list.size());
    }
  }
  return out;
}

std::string formatMapReport(const MapReport& report,
                            const std::map<std::string, ClassSummary>* by_range) {
  std::ostringstream out;
  char number[64];
  auto fmt = [&](double v) {
    std::snprintf(number, sizeof(number), "%.6f", v);
    return std::string(number);
  };
  for (const TruthResult& r : report.truths) {
    out << "truth " << r.truth_id << " " << r.quadric_class;
    if (!r.matched) {
      out << " missed seen_frames " << r.seen_frames << " large_views " << r.large_views << "\n";
      continue;
    }
    out << " matched estimate " << r.estimate_id;
    for (const ShapeError& e : r.errors)
      out << " " << e.name << " " << fmt(e.value);
    out << " distance " << fmt(r.distance);
    if (!r.duplicate_ids.empty()) {
      out << " duplicates";
      for (std::size_t i = 0; i < r.duplicate_ids.size(); ++i) {
        out << (i == 0 ? " " : ",") << r.duplicate_ids[i];
      }
    }
    out << "\n";
  }
  for (const auto& [name, s] : report.classes) {
    out << "class " << name << " truths " << s.truths << " matched " << s.matched << " misses "
        << s.misses << " duplicates " << s.duplicates << " unmatched_estimates "
        << s.unmatched_estimates;
    for (const ShapeError& e : s.mean_errors)
      out << " mean_" << e.name << " " << fmt(e.value);
    out << "\n";
  }
  if (by_range) {
    for (const auto& [key, s] : *by_range) {
      out << "class_range " << key << " truths " << s.truths << " matched " << s.matched
          << " misses " << s.misses << " duplicates " << s.duplicates;
      for (const ShapeError& e : s.mean_errors)
        out << " mean_" << e.name << " " << fmt(e.value);
      out << "\n";
    }
  }
  out << "map_summary matched " << report.matched << " misses " << report.misses << " duplicates "
      << report.duplicates << " unmatched_estimates " << report.unmatched_estimates
      << " misses_seen_" << report.min_seen_frames << " " << report.seen_misses << " misses_large_"
      << report.min_seen_frames << " " << report.large_view_misses;
  if (report.skipped_truths + report.skipped_estimates > 0) {
    out << " skipped_truths " << report.skipped_truths << " skipped_estimates "
        << report.skipped_estimates;
  }
  out << "\n";
  return out.str();
}

}  // namespace quadric_slam
