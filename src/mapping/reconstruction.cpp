#include "quadric_slam/mapping/reconstruction.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace quadric_slam {

void QuadricReconstruction::Params::validate() const {
  if (!(voxel_size > 0.0 && std::isfinite(voxel_size)))
    throw std::invalid_argument("QuadricReconstruction::Params::voxel_size must be > 0 (m), got " +
                                std::to_string(voxel_size));
  if (max_points_per_landmark < 1)
    throw std::invalid_argument(
        "QuadricReconstruction::Params::max_points_per_landmark must be >= 1, got " +
        std::to_string(max_points_per_landmark));
  if (max_points < 1)
    throw std::invalid_argument("QuadricReconstruction::Params::max_points must be >= 1, got " +
                                std::to_string(max_points));
  if (!(max_surface_distance > 0.0))
    throw std::invalid_argument(
        "QuadricReconstruction::Params::max_surface_distance must be > 0 (m), got " +
        std::to_string(max_surface_distance));
}

QuadricReconstruction::QuadricReconstruction() : QuadricReconstruction(Params()) {}

QuadricReconstruction::QuadricReconstruction(const Params& params) : params_(params) {
  params_.validate();
}

namespace {

// 21 bits per index (two's complement, wrapped): unique within +-10 km at 1 cm cells.
std::uint64_t packCell(std::int64_t a, std::int64_t b, std::int64_t c) {
  constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
  return (static_cast<std::uint64_t>(a) & kMask) | (static_cast<std::uint64_t>(b) & kMask) << 21 |
         (static_cast<std::uint64_t>(c) & kMask) << 42;
}

// Cells are centred on zero (a plane's cells on its frame's origin, azimuth 0 in a cell's middle).
std::int64_t cellIndex(double value, double step) {
  return static_cast<std::int64_t>(std::floor(value / step + 0.5));
}

// The radius (sphere, cylinder) or half angle (cone) of a landmark estimate; 0 for the others.
double shapeSize(const QuadricModel& quadric) {
  switch (quadric.quadricClass()) {
    case QuadricClass::kSphere:
    case QuadricClass::kCylinder:
      return 1.0 / quadric.scale().x();
    case QuadricClass::kCone:
      return std::atan2(1.0, quadric.scale().x());
    default:
      return 0.0;
  }
}

}  // namespace

std::uint64_t QuadricReconstruction::cellKey(const LandmarkPoints& stored,
                                             const Eigen::Vector3d& p) const {
  const double v = params_.voxel_size;
  // The third index tells the 2D keys of the surface classes from each other's layouts; it is 0
  // for them (a landmark never changes class).
  switch (stored.quadric_class) {
    case QuadricClass::kPlane:  // the normal is the frame's x axis
      return packCell(cellIndex(p.y(), v), cellIndex(p.z(), v), 0);
    case QuadricClass::kCylinder: {  // axis = z
      const double azimuth_step = v / std::max(stored.reference_size, v);
      return packCell(cellIndex(std::atan2(p.y(), p.x()), azimuth_step), cellIndex(p.z(), v), 0);
    }
    case QuadricClass::kCone: {  // apex at the origin, axis = z: the circle at height z has
      // radius z tan(half angle), so the azimuth step follows the height's cell
      const std::int64_t height = cellIndex(p.z(), v);
      const double radius = std::abs(static_cast<double>(height)) * v *
                            std::tan(std::min(stored.reference_size, 1.5));
      return packCell(cellIndex(std::atan2(p.y(), p.x()), v / std::max(radius, v)), height, 0);
    }
    case QuadricClass::kSphere: {  // centre at the origin
      const double r = p.norm();
      if (r > 0.0) {
        const double step = v / std::max(stored.reference_size, v);
        const std::int64_t elevation = cellIndex(std::asin(std::clamp(p.z() / r, -1.0, 1.0)), step);
        // Circles of latitude shrink towards the poles: the azimuth step grows with them.
        const double circle =
            std::max(stored.reference_size, v) * std::cos(static_cast<double>(elevation) * step);
        return packCell(cellIndex(std::atan2(p.y(), p.x()), v / std::max(circle, v)), elevation, 0);
      }
      break;
    }
    default:
      break;
  }
  return packCell(cellIndex(p.x(), v), cellIndex(p.y(), v), cellIndex(p.z(), v));
}

int QuadricReconstruction::addPoints(int id, const QuadricModel& landmark_map,
                                     const Eigen::Isometry3d& T_map_camera,
                                     const std::vector<Eigen::Vector3f>& points_camera,
                                     const std::vector<std::uint32_t>& colours_rgba) {
  if (!colours_rgba.empty() && colours_rgba.size() != points_camera.size())
    throw std::invalid_argument(
        "QuadricReconstruction::addPoints: " + std::to_string(colours_rgba.size()) +
        " colours for " + std::to_string(points_camera.size()) + " points");
  LandmarkPoints& stored = landmarks_[id];
  if (stored.points_quadric.empty()) {
    stored.quadric_class = landmark_map.quadricClass();
    stored.reference_size = shapeSize(landmark_map);
  }
  const Eigen::Isometry3d T_quadric_map = landmark_map.pose().inverse();
  const bool exact = landmark_map.quadricClass() != QuadricClass::kGeneral;
  int added = 0;
  for (std::size_t i = 0; i < points_camera.size(); ++i) {
    const Eigen::Vector3f& point = points_camera[i];
    if (static_cast<int>(stored.points_quadric.size()) >= params_.max_points_per_landmark ||
        total_points_ + added >= static_cast<std::size_t>(params_.max_points))
      break;
    if (!point.allFinite())
      continue;
    const Eigen::Vector3d p_map = T_map_camera * point.cast<double>();
    // Stored on the surface: the sensor's noise along the normal would otherwise spread one
    // patch of surface over a stack of voxels, and every pass over it would add points (the map
    // grows over time without seeing anything new). For the exact classes the projection is the
    // closest surface point, so it gives the distance too; a general quadric is tested with the
    // first-order distance before its (iterative) projection.
    if (!exact && !(firstOrderDistance(landmark_map, p_map) <= params_.max_surface_distance))
      continue;
    Eigen::Vector3d p_surface;
    try {
      p_surface = projector_.project(landmark_map, p_map);
    } catch (const std::invalid_argument&) {
      continue;  // a general quadric whose projection does not converge from here
    }
    if (exact && !((p_map - p_surface).norm() <= params_.max_surface_distance))
      continue;
    const Eigen::Vector3d p_quadric = T_quadric_map * p_surface;
    if (!stored.voxels.insert(cellKey(stored, p_quadric)).second)
      continue;
    if (!colours_rgba.empty() && (colours_rgba[i] >> 24) != 0) {
      stored.rgba.resize(stored.points_quadric.size(), 0u);  // earlier points stay uncoloured
      stored.rgba.push_back(colours_rgba[i]);
    }
    stored.points_quadric.push_back(p_quadric.cast<float>());
    ++added;
  }
  total_points_ += added;
  if (stored.points_quadric.empty())
    landmarks_.erase(id);
  return added;
}

void QuadricReconstruction::moveLandmark(int from, int to, const Eigen::Isometry3d& T_to_from) {
  const auto source = landmarks_.find(from);
  if (from == to || source == landmarks_.end())
    return;
  LandmarkPoints& target = landmarks_[to];
  const LandmarkPoints& moved = source->second;
  if (target.points_quadric.empty()) {  // the same surface: its cells as the moved landmark's
    target.quadric_class = moved.quadric_class;
    target.reference_size = moved.reference_size;
  }
  total_points_ -= moved.points_quadric.size() + target.points_quadric.size();
  for (std::size_t i = 0; i < moved.points_quadric.size(); ++i) {
    if (static_cast<int>(target.points_quadric.size()) >= params_.max_points_per_landmark)
      break;
    const Eigen::Vector3d p_to = T_to_from * moved.points_quadric[i].cast<double>();
    if (!target.voxels.insert(cellKey(target, p_to)).second)
      continue;
    // The colour travels with its point (rgba may be shorter than the points: the tail is
    // uncoloured).
    if (i < moved.rgba.size() && (moved.rgba[i] >> 24) != 0) {
      target.rgba.resize(target.points_quadric.size(), 0u);
      target.rgba.push_back(moved.rgba[i]);
    }
    target.points_quadric.push_back(p_to.cast<float>());
  }
  total_points_ += target.points_quadric.size();
  landmarks_.erase(from);
  if (landmarks_[to].points_quadric.empty())
    landmarks_.erase(to);
}

void QuadricReconstruction::removeLandmark(int id) {
  total_points_ -= size(id);
  landmarks_.erase(id);
}

void QuadricReconstruction::clear() {
  landmarks_.clear();
  total_points_ = 0;
}

std::size_t QuadricReconstruction::size() const {
  return total_points_;
}

bool QuadricReconstruction::full() const {
  return total_points_ >= static_cast<std::size_t>(params_.max_points);
}

std::size_t QuadricReconstruction::size(int id) const {
  const auto it = landmarks_.find(id);
  return it == landmarks_.end() ? 0 : it->second.points_quadric.size();
}

pcl::PointCloud<pcl::PointXYZRGBL> QuadricReconstruction::cloud(
    const std::map<int, QuadricModel>& landmarks_map) const {
  pcl::PointCloud<pcl::PointXYZRGBL> out;
  for (const auto& [id, landmark] : landmarks_map) {
    const auto stored = landmarks_.find(id);
    if (stored == landmarks_.end())
      continue;
    const std::vector<Eigen::Vector3f>& points = stored->second.points_quadric;
    const std::vector<std::uint32_t>& rgba = stored->second.rgba;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3f& p_quadric = points[i];
      Eigen::Vector3d on_surface;
      try {
        on_surface = projector_.project(landmark, landmark.pose() * p_quadric.cast<double>());
      } catch (const std::invalid_argument&) {
        continue;  // a general quadric whose projection does not converge from here
      }
      pcl::PointXYZRGBL point;
      point.rgba = i < rgba.size() ? rgba[i] : 0u;
      point.x = static_cast<float>(on_surface.x());
      point.y = static_cast<float>(on_surface.y());
      point.z = static_cast<float>(on_surface.z());
      point.label = static_cast<std::uint32_t>(id);
      out.push_back(point);
    }
  }
  return out;
}

}  // namespace quadric_slam
