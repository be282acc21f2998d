// Reading private parameters with their defaults, and logging the effective values once.
#pragma once

#include <ros/node_handle.h>

#include <sstream>
#include <string>

namespace quadric_slam {
namespace ros_params {

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

// Reads ~name into value (keeping value as the default when unset) and records it in log.
template <typename T>
void read(const ros::NodeHandle& private_nh, const std::string& name, T& value, ParamLog& log) {
  private_nh.param(name, value, value);
  log.add(name, value);
}

}  // namespace ros_params
}  // namespace quadric_slam
