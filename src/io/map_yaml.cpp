#include "quadric_slam/io/map_yaml.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace quadric_slam {
namespace {

std::vector<double> readVector(const YAML::Node& node, const std::string& what, std::size_t size) {
  if (!node)
    throw std::runtime_error("missing key '" + what + "'");
  std::vector<double> values;
  if (node.IsScalar()) {
    values.push_back(node.as<double>());
  } else if (node.IsSequence()) {
    values = node.as<std::vector<double>>();
  } else {
    throw std::runtime_error("'" + what + "' must be a number or a list of numbers");
  }
  if (size != 0 && values.size() != size) {
    throw std::runtime_error("'" + what + "' must have " + std::to_string(size) + " entries, has " +
                             std::to_string(values.size()));
  }
  return values;
}

MapFileQuadric readQuadric(const YAML::Node& node) {
  MapFileQuadric q;
  if (!node["id"])
    throw std::runtime_error("quadric without 'id'");
  q.id = node["id"].as<int>();
  const std::string where = "quadric " + std::to_string(q.id) + ": ";
  try {
    if (!node["class"])
      throw std::runtime_error("missing key 'class'");
    q.quadric_class = node["class"].as<std::string>();
    q.observations = node["observations"] ? node["observations"].as<int>() : 0;
    q.large_views = node["large_views"] ? node["large_views"].as<int>() : 0;
    const YAML::Node pose = node["pose"];
    if (!pose)
      throw std::runtime_error("missing key 'pose'");
    const std::vector<double> p = readVector(pose["position"], "pose.position", 3);
    const std::vector<double> o = readVector(pose["orientation"], "pose.orientation", 4);
    Eigen::Quaterniond rotation(o[3], o[0], o[1], o[2]);
    if (std::abs(rotation.norm() - 1.0) > 1e-3) {
      throw std::runtime_error("pose.orientation is not a unit quaternion");
    }
    q.T_map_quadric = Eigen::Isometry3d::Identity();
    q.T_map_quadric.linear() = rotation.normalized().toRotationMatrix();
    q.T_map_quadric.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
    const std::vector<double> s = readVector(node["scale"], "scale", 3);
    q.scale = Eigen::Vector3d(s[0], s[1], s[2]);
    if (const YAML::Node shape = node["shape"]) {
      for (const auto& entry : shape) {
        const std::string key = entry.first.as<std::string>();
        q.shape[key] = readVector(entry.second, "shape." + key, 0);
      }
    }
    if (node["extent_min"] || node["extent_max"]) {
      const std::vector<double> lo = readVector(node["extent_min"], "extent_min", 3);
      const std::vector<double> hi = readVector(node["extent_max"], "extent_max", 3);
      q.extent_min = Eigen::Vector3d(lo[0], lo[1], lo[2]);
      q.extent_max = Eigen::Vector3d(hi[0], hi[1], hi[2]);
      if (!q.extent_min.allFinite() || !q.extent_max.allFinite() ||
          (q.extent_max.array() < q.extent_min.array()).any())
        throw std::runtime_error("extent_max must not be below extent_min on any axis");
      q.has_extent = true;
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(where + e.what());
  }
  return q;
}

void writeVector(YAML::Emitter& out, const std::vector<double>& values) {
  if (values.size() == 1) {
    out << values[0];
    return;
  }
  out << YAML::Flow << YAML::BeginSeq;
  for (double v : values)
    out << v;
  out << YAML::EndSeq;
}

}  // namespace

MapFile parseMapYaml(const std::string& text) {
  const YAML::Node root = YAML::Load(text);
  MapFile map;
  if (!root || !root.IsMap())
    throw std::runtime_error("map file must be a YAML mapping");
  if (root["frame_id"])
    map.frame_id = root["frame_id"].as<std::string>();
  if (const YAML::Node quadrics = root["quadrics"]) {
    if (!quadrics.IsSequence())
      throw std::runtime_error("'quadrics' must be a list");
    for (const auto& node : quadrics)
      map.quadrics.push_back(readQuadric(node));
  }
  if (const YAML::Node merged = root["merged_into"]) {
    if (!merged.IsMap())
      throw std::runtime_error("'merged_into' must be a map of landmark ids");
    for (const auto& entry : merged)
      map.merged_into[entry.first.as<int>()] = entry.second.as<int>();
  }
  return map;
}

MapFile readMapYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("cannot open map file " + path);
  std::stringstream text;
  text << in.rdbuf();
  try {
    return parseMapYaml(text.str());
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

std::string mapYamlString(const MapFile& map) {
  YAML::Emitter out;
  out.SetDoublePrecision(9);
  out << YAML::BeginMap;
  out << YAML::Key << "frame_id" << YAML::Value << map.frame_id;
  out << YAML::Key << "quadrics" << YAML::Value << YAML::BeginSeq;
  for (const MapFileQuadric& q : map.quadrics) {
    const Eigen::Quaterniond r(q.T_map_quadric.rotation());
    const Eigen::Vector3d t = q.T_map_quadric.translation();
    out << YAML::BeginMap;
    out << YAML::Key << "id" << YAML::Value << q.id;
    out << YAML::Key << "class" << YAML::Value << q.quadric_class;
    out << YAML::Key << "observations" << YAML::Value << q.observations;
    if (q.large_views > 0)
      out << YAML::Key << "large_views" << YAML::Value << q.large_views;
    out << YAML::Key << "pose" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "position" << YAML::Value;
    writeVector(out, {t.x(), t.y(), t.z()});
    out << YAML::Key << "orientation" << YAML::Value;
    writeVector(out, {r.x(), r.y(), r.z(), r.w()});
    out << YAML::EndMap;
    out << YAML::Key << "scale" << YAML::Value;
    writeVector(out, {q.scale.x(), q.scale.y(), q.scale.z()});
    out << YAML::Key << "shape" << YAML::Value << YAML::BeginMap;
    for (const auto& [key, values] : q.shape) {
      out << YAML::Key << key << YAML::Value;
      writeVector(out, values);
    }
    out << YAML::EndMap;
    if (q.has_extent) {
      out << YAML::Key << "extent_min" << YAML::Value;
      writeVector(out, {q.extent_min.x(), q.extent_min.y(), q.extent_min.z()});
      out << YAML::Key << "extent_max" << YAML::Value;
      writeVector(out, {q.extent_max.x(), q.extent_max.y(), q.extent_max.z()});
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (!map.merged_into.empty()) {
    out << YAML::Key << "merged_into" << YAML::Value << YAML::Flow << YAML::BeginMap;
    for (const auto& [id, into] : map.merged_into)
      out << YAML::Key << id << YAML::Value << into;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void writeMapYaml(const MapFile& map, const std::string& path) {
  std::ofstream out(path);
  if (!out)
    throw std::runtime_error("cannot write map file " + path);
  out << mapYamlString(map);
  if (!out)
    throw std::runtime_error("failed writing map file " + path);
}

}  // namespace quadric_slam
