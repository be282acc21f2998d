#include "quadric_slam/io/param_reader.h"

#include <stdexcept>

namespace quadric_slam {

YamlParamReader YamlParamReader::fromFile(const std::string& path) {
  try {
    YAML::Node root = YAML::LoadFile(path);
    if (root && !root.IsMap() && !root.IsNull()) {
      throw std::runtime_error("not a YAML mapping of parameters");
    }
    return YamlParamReader(root);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("cannot read parameter file " + path + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("parameter file " + path + ": " + e.what());
  }
}

YamlParamReader YamlParamReader::withOverrides(const YamlParamReader& overrides) const {
  const auto isMapping = [](const YAML::Node& node) { return !node || node.IsNull() || node.IsMap(); };
  if (!isMapping(root_) || !isMapping(overrides.root_))
    throw std::runtime_error("parameter overrides need two YAML mappings");
  YAML::Node merged(YAML::NodeType::Map);
  for (const YAML::Node* source : {&root_, &overrides.root_})
    if (*source && source->IsMap())
      for (const auto& entry : *source)
        merged[entry.first.as<std::string>()] = YAML::Clone(entry.second);
  return YamlParamReader(merged);
}

template <typename T>
bool YamlParamReader::read(const std::string& key, T& value) const {
  if (!root_ || !root_.IsMap())
    return false;
  const YAML::Node node = root_[key];
  if (!node)
    return false;
  try {
    value = node.as<T>();
  } catch (const YAML::Exception&) {
    throw std::invalid_argument("parameter '" + key + "' has the wrong type");
  }
  return true;
}

template bool YamlParamReader::read(const std::string&, double&) const;
template bool YamlParamReader::read(const std::string&, int&) const;
template bool YamlParamReader::read(const std::string&, bool&) const;
template bool YamlParamReader::read(const std::string&, std::string&) const;

}  // namespace quadric_slam
