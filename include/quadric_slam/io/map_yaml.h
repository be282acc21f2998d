// The map schema shared by the generator's truth (quadrics_gt.yaml), the mapper's saved map and the
// evaluator (README, "Map files"). Plain data: no geometry is computed here.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

namespace quadric_slam {

struct MapFileQuadric {
  int id = 0;
  std::string quadric_class;  // plane | sphere | cylinder | cone | ellipsoid | general
  int observations = 0;
  // Truth files only (optional key `large_views`, written when > 0): frames in which the surface
  // covered at least 2000 pixels (sim/sequence_generator.h kLargeViewPixels).
  int large_views = 0;
  Eigen::Isometry3d T_map_quadric = Eigen::Isometry3d::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();  // diagonal of S (1/m)
  // Human-readable shape, keyed as in the schema: plane normal (3) + offset (1); sphere center (3)
  // + radius (1); cylinder point (3) + axis (3) + radius (1); cone apex (3) + axis (3) +
  // half_angle (1, rad); ellipsoid center (3) + radii (3, the semi-axes along quadric x, y, z).
  // Scalars are vectors of length 1.
  std::map<std::string, std::vector<double>> shape;
  // The bounded piece of the quadric, as an axis-aligned box in the quadric frame (m): the box of
  // the points observed on a mapped surface, or the generator's true piece (a wall's rectangle, a
  // cylinder's length). Optional keys `extent_min`, `extent_max`, written only when has_extent:
  // with them two coplanar surfaces (two desks at one height, a floor and a cap on it) are told
  // apart.
  bool has_extent = false;
  Eigen::Vector3d extent_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d extent_max = Eigen::Vector3d::Zero();
};

struct MapFile {
  std::string frame_id = "map";
  std::vector<MapFileQuadric> quadrics;
  // Landmarks merged into another because both were one surface: id merged away -> the id of this
  // file's landmark that holds its surface (chains resolved), as QuadricMap.merged_ids /
  // merged_into. Optional key `merged_into: {id: into, ...}`, written only when not empty.
  std::map<int, int> merged_into;
};

// Throws std::runtime_error naming the file and the problem (missing key, wrong length, bad YAML).
MapFile readMapYaml(const std::string& path);
MapFile parseMapYaml(const std::string& text);
// Writes the schema; throws std::runtime_error when the file cannot be written.
void writeMapYaml(const MapFile& map, const std::string& path);
std::string mapYamlString(const MapFile& map);

}  // namespace quadric_slam
