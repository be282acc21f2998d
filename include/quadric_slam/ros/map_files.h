// Saved maps of the mapping nodelet (~save_map, ~load_map, ~map_file): the map YAML (io/map_yaml.h,
// README "Map files") and beside it the reconstruction as a PCD file (the same path with the
// extension .pcd; fields x y z rgb label as ros/reconstruction_cloud.h, map frame, label = landmark
// id). The YAML holds each landmark's id, class, observation count, pose and scale; the PCD gives
// back the landmarks' extents (the box of their points in the quadric frame) and the
// reconstruction itself. Covariances are not saved: a loaded landmark has none until it is
// re-estimated.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/PointCloud2.h>

#include <map>
#include <string>
#include <vector>

#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/mapping/landmark.h"

namespace quadric_slam {

// map_path with its extension replaced by .pcd (appended when it has none).
std::string reconstructionPathFor(const std::string& map_path);

// Writes the map YAML (with `merged_into`, merged landmark ids -> surviving ids) and the
// reconstruction PCD (binary), creating the parent directory. An empty reconstruction writes no PCD
// and removes a stale one. Throws std::runtime_error naming the file.
void saveMapFiles(const std::string& map_path, const std::vector<QuadricLandmark>& landmarks,
                  const std::string& frame_id, const sensor_msgs::PointCloud2& reconstruction,
                  const std::map<int, int>& merged_into = {});

struct LoadedMap {
  std::string frame_id;
  std::vector<QuadricLandmark> landmarks;
  std::string reconstruction_path;  // empty when there was no PCD beside the YAML
  // The PCD's points (map frame, label = landmark id, rgba as ros/reconstruction_cloud.h wrote
  // it: alpha != 0 a colour from the RGB image); points of unknown landmarks are left out.
  pcl::PointCloud<pcl::PointXYZRGBL> reconstruction;
};

// Reads the map YAML and, when present, the PCD beside it; each landmark's extent is the box of its
// PCD points in its quadric frame (unknown, all zero, without points). Throws std::runtime_error
// naming the file and the problem (unreadable, bad schema, repeated id, a "general" landmark whose
// signature the schema does not hold, a PCD without a label field).
LoadedMap loadMapFiles(const std::string& map_path);

// One map-file entry as a landmark: class by name ("ellipsoid" = general with signature
// (+1, +1, +1, -1)), pose, scale, observation count; no covariance, unknown extent. Throws
// std::invalid_argument for an unknown class, "general" (signature unknown) or an invalid quadric.
QuadricLandmark landmarkFromMapFile(const MapFileQuadric& entry);

}  // namespace quadric_slam
