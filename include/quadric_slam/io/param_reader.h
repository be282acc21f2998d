// Parameters by key from any source: the nodelets read their private ROS parameters and the offline
// tools read the same config/*.yaml files through this one interface, with the same per-class key
// tables (io/pipeline_params.h), so the live pipeline and the offline runner use the same values.
#pragma once

#include <yaml-cpp/yaml.h>

#include <sstream>
#include <string>

namespace quadric_slam {

class ParamReader {
 public:
  virtual ~ParamReader() = default;
  // Each returns false (leaving value untouched) when the key is absent; throws
  // std::invalid_argument when it is present with the wrong type.
  virtual bool get(const std::string& key, double& value) const = 0;
  virtual bool get(const std::string& key, int& value) const = 0;
  virtual bool get(const std::string& key, bool& value) const = 0;
  virtual bool get(const std::string& key, std::string& value) const = 0;
};

// A YAML mapping (e.g. config/odometry.yaml) as a parameter source.
class YamlParamReader : public ParamReader {
 public:
  explicit YamlParamReader(YAML::Node root) : root_(std::move(root)) {}
  // Throws std::runtime_error naming the file when it cannot be read or parsed.
  static YamlParamReader fromFile(const std::string& path);
  // This mapping with every key of `overrides` (a YAML mapping, e.g. a profile's file) replacing
  // or adding to its own; throws std::runtime_error when either is not a mapping.
  YamlParamReader withOverrides(const YamlParamReader& overrides) const;

  bool get(const std::string& key, double& value) const override { return read(key, value); }
  bool get(const std::string& key, int& value) const override { return read(key, value); }
  bool get(const std::string& key, bool& value) const override { return read(key, value); }
  bool get(const std::string& key, std::string& value) const override { return read(key, value); }

 private:
  template <typename T>
  bool read(const std::string& key, T& value) const;

  YAML::Node root_;
};

// Collects "name: value" lines while parameters are read, for one start-up log line.
class ParamLog {
 public:
  template <typename T>
  void add(const std::string& name, const T& value) {
    text_ << "\n  " << name << ": " << value;
  }
  std::string str() const { return text_.str(); }

 private:
  std::ostringstream text_;
};

// Reads key into value (keeping the default when absent) and records the effective value.
template <typename T>
void readParam(const ParamReader& reader, const std::string& key, T& value, ParamLog& log) {
  reader.get(key, value);
  log.add(key, value);
}

}  // namespace quadric_slam
