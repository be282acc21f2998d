// Private ROS parameters as a ParamReader, so nodelets read the same key tables
// (io/pipeline_params.h) as the offline tools read from config/*.yaml.
#pragma once

#include <ros/node_handle.h>

#include <string>

#include "quadric_slam/io/param_reader.h"

namespace quadric_slam {

class RosParamReader : public ParamReader {
 public:
  explicit RosParamReader(const ros::NodeHandle& private_nh) : nh_(private_nh) {}

  bool get(const std::string& key, double& value) const override { return read(key, value); }
  bool get(const std::string& key, int& value) const override { return read(key, value); }
  bool get(const std::string& key, bool& value) const override { return read(key, value); }
  bool get(const std::string& key, std::string& value) const override { return read(key, value); }

 private:
  template <typename T>
  bool read(const std::string& key, T& value) const {
    if (!nh_.hasParam(key))
      return false;
    if (!nh_.getParam(key, value)) {
      throw std::invalid_argument("parameter '" + nh_.resolveName(key) + "' has the wrong type");
    }
    return true;
  }

  ros::NodeHandle nh_;
};

}  // namespace quadric_slam
