#include "quadric_slam/ros/map_files.h"

#include "quadric_slam/io/pcd_header.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl_conversions/pcl_conversions.h>

#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/io/landmark_map_file.h"

namespace quadric_slam {

namespace fs = std::filesystem;

std::string reconstructionPathFor(const std::string& map_path) {
  return fs::path(map_path).replace_extension(".pcd").string();
}

void saveMapFiles(const std::string& map_path, const std::vector<QuadricLandmark>& landmarks,
                  const std::string& frame_id, const sensor_msgs::PointCloud2& reconstruction,
                  const std::map<int, int>& merged_into) {
  const fs::path parent = fs::path(map_path).parent_path();
  std::error_code error;
  if (!parent.empty() && !fs::exists(parent) && !fs::create_directories(parent, error))
    throw std::runtime_error("cannot create the directory " + parent.string() + ": " +
                             error.message());
  writeMapYaml(mapFileFromLandmarks(landmarks, frame_id, merged_into), map_path);
  const std::string pcd_path = reconstructionPathFor(map_path);
  if (reconstruction.width * reconstruction.height == 0) {
    fs::remove(pcd_path, error);  // no stale reconstruction beside the new map
    return;
  }
  pcl::PCLPointCloud2 cloud;
  pcl_conversions::toPCL(reconstruction, cloud);
  if (pcl::io::savePCDFile(pcd_path, cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(),
                           true) != 0)
    throw std::runtime_error("cannot write the reconstruction " + pcd_path);
}

QuadricLandmark landmarkFromMapFile(const MapFileQuadric& entry) {
  QuadricLandmark landmark;
  landmark.id = entry.id;
  landmark.observations = entry.observations;
  if (entry.has_extent) {  // the reconstruction's points, when there are any, replace it
    landmark.extent_min = entry.extent_min;
    landmark.extent_max = entry.extent_max;
  }
  if (entry.quadric_class == "ellipsoid") {
    landmark.quadric_map = QuadricModel(QuadricClass::kGeneral, entry.T_map_quadric, entry.scale,
                                        Eigen::Vector4d(1, 1, 1, -1));
    return landmark;
  }
  const QuadricClass quadric_class = quadricClassFromString(entry.quadric_class);
  if (quadric_class == QuadricClass::kGeneral)
    throw std::invalid_argument(
        "class 'general' cannot be loaded: the map schema does not hold its signature");
  landmark.quadric_map = QuadricModel(quadric_class, entry.T_map_quadric, entry.scale);
  return landmark;
}

LoadedMap loadMapFiles(const std::string& map_path) {
  LoadedMap loaded;
  const MapFile file = readMapYaml(map_path);
  loaded.frame_id = file.frame_id;
  std::map<int, std::size_t> index;  // id -> position in loaded.landmarks
  for (const MapFileQuadric& entry : file.quadrics) {
    const std::string where = map_path + ": quadric " + std::to_string(entry.id) + ": ";
    if (index.count(entry.id))
      throw std::runtime_error(where + "the id is used twice");
    try {
      loaded.landmarks.push_back(landmarkFromMapFile(entry));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(where + e.what());
    }
    index[entry.id] = loaded.landmarks.size() - 1;
  }

  const std::string pcd_path = reconstructionPathFor(map_path);
  if (!fs::exists(pcd_path))
    return loaded;
  // PCL trusts the header; a damaged file is refused before PCL reads it (io/pcd_header.h).
  const PcdHeader header = checkPcdFile(pcd_path);
  for (const char* axis : {"x", "y", "z"}) {
    bool float_axis = false;
    for (std::size_t i = 0; i < header.fields.size(); ++i)
      float_axis = float_axis || (header.fields[i] == axis && header.types[i] == 'F');
    if (!float_axis)
      throw std::runtime_error(pcd_path + ": no float field '" + axis + "'");
  }
  pcl::PCLPointCloud2 cloud;
  if (pcl::io::loadPCDFile(pcd_path, cloud) != 0)
    throw std::runtime_error("cannot read the reconstruction " + pcd_path);
  bool has_label = false, has_colour = false;
  for (const pcl::PCLPointField& field : cloud.fields) {
    has_label = has_label || field.name == "label";
    has_colour = has_colour || field.name == "rgb" || field.name == "rgba";
  }
  if (!has_label)
    throw std::runtime_error(pcd_path + ": no 'label' field (the landmark id of each point)");
  pcl::PointCloud<pcl::PointXYZRGBL> points;
  pcl::fromPCLPointCloud2(cloud, points);
  if (!has_colour)
    for (pcl::PointXYZRGBL& p : points)
      p.rgba = 0;  // no colours: each landmark's own (PCL's default would be opaque black)
  loaded.reconstruction_path = pcd_path;

  // Extents: the box of each landmark's points in its quadric frame.
  std::set<int> has_points;
  for (const pcl::PointXYZRGBL& p : points) {
    const auto it = index.find(static_cast<int>(p.label));
    const Eigen::Vector3d p_map(p.x, p.y, p.z);
    if (it == index.end() || !p_map.allFinite())
      continue;
    loaded.reconstruction.push_back(p);
    QuadricLandmark& landmark = loaded.landmarks[it->second];
    const Eigen::Vector3d p_quadric = landmark.quadric_map.pose().inverse() * p_map;
    if (has_points.insert(landmark.id).second) {
      landmark.extent_min = landmark.extent_max = p_quadric;
    } else {
      landmark.extent_min = landmark.extent_min.cwiseMin(p_quadric);
      landmark.extent_max = landmark.extent_max.cwiseMax(p_quadric);
    }
  }
  return loaded;
}

}  // namespace quadric_slam
