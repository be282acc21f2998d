#include "quadric_slam/mapping/reconstruction.h"

#include <cmath>
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

std::uint64_t QuadricReconstruction::voxelKey(const Eigen::Vector3d& p_quadric) const {
  // 21 bits per axis (two's complement, wrapped): unique within +-10 km at 1 cm voxels. Voxels
  // are centred on the quadric frame's axes, so a plane (z = 0 in its frame) lies in the middle
  // of one layer of voxels rather than on the boundary between two.
  const auto axis = [&](double value) {
    return static_cast<std::uint64_t>(
               static_cast<std::int64_t>(std::floor(value / params_.voxel_size + 0.5))) &
           ((std::uint64_t{1} << 21) - 1);
  };
  return axis(p_quadric.x()) | axis(p_quadric.y()) << 21 | axis(p_quadric.z()) << 42;
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
    const double distance =
        exact ? exactDistance(landmark_map, p_map) : firstOrderDistance(landmark_map, p_map);
    if (!(distance <= params_.max_surface_distance))
      continue;
    // Stored on the surface: the sensor's noise along the normal would otherwise spread one
    // patch of surface over a stack of voxels, and every pass over it would add points (the map
    // grows over time without seeing anything new).
    Eigen::Vector3d p_quadric;
    try {
      p_quadric = T_quadric_map * projector_.project(landmark_map, p_map);
    } catch (const std::invalid_argument&) {
      continue;  // a general quadric whose projection does not converge from here
    }
    if (!stored.voxels.insert(voxelKey(p_quadric)).second)
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
  total_points_ -= moved.points_quadric.size() + target.points_quadric.size();
  for (std::size_t i = 0; i < moved.points_quadric.size(); ++i) {
    if (static_cast<int>(target.points_quadric.size()) >= params_.max_points_per_landmark)
      break;
    const Eigen::Vector3d p_to = T_to_from * moved.points_quadric[i].cast<double>();
    if (!target.voxels.insert(voxelKey(p_to)).second)
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
