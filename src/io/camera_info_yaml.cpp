#include "quadric_slam/io/camera_info_yaml.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <iomanip>
#include <stdexcept>
#include <vector>

namespace quadric_slam {

void writeCameraInfoYaml(const std::string& path, const CameraIntrinsics& k,
                         const std::string& camera_name) {
  std::ofstream out(path);
  if (!out)
    throw std::runtime_error("cannot write " + path);
  out << std::setprecision(10);
  out << "image_width: " << k.width << "\n"
      << "image_height: " << k.height << "\n"
      << "camera_name: " << camera_name << "\n"
      << "camera_matrix:\n  rows: 3\n  cols: 3\n"
      << "  data: [" << k.fx << ", 0, " << k.cx << ", 0, " << k.fy << ", " << k.cy << ", 0, 0, 1]\n"
      << "distortion_model: plumb_bob\n"
      << "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n"
      << "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
      << "projection_matrix:\n  rows: 3\n  cols: 4\n"
      << "  data: [" << k.fx << ", 0, " << k.cx << ", 0, 0, " << k.fy << ", " << k.cy
      << ", 0, 0, 0, 1, 0]\n";
  if (!out)
    throw std::runtime_error("failed writing " + path);
}

namespace {

std::vector<double> matrixData(const YAML::Node& root, const char* key, std::size_t size,
                               const std::string& path) {
  const YAML::Node data = root[key] ? root[key]["data"] : YAML::Node();
  if (!data || !data.IsSequence() || data.size() != size)
    throw std::runtime_error(path + ": " + key + ".data must hold " + std::to_string(size) +
                             " numbers");
  std::vector<double> values;
  for (const YAML::Node& value : data)
    values.push_back(value.as<double>());
  return values;
}

}  // namespace

CameraIntrinsics readCameraInfoYaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read camera info (" + e.what() + ")");
  }
  CameraIntrinsics k;
  try {
    if (!root.IsMap() || !root["image_width"] || !root["image_height"])
      throw std::runtime_error(path + ": image_width and image_height are required");
    k.width = root["image_width"].as<int>();
    k.height = root["image_height"].as<int>();
    const std::vector<double> K = matrixData(root, "camera_matrix", 9, path);
    k.fx = K[0];
    k.cx = K[2];
    k.fy = K[4];
    k.cy = K[5];
    if (root["distortion_coefficients"]) {
      const YAML::Node d = root["distortion_coefficients"]["data"];
      if (d && d.IsSequence())
        for (const YAML::Node& value : d)
          if (value.as<double>() != 0.0)
            throw std::runtime_error(path +
                                     ": the distortion is not zero (rectified depth is expected)");
    }
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": malformed camera info (" + e.what() + ")");
  }
  const std::string problem = k.problem();
  if (!problem.empty())
    throw std::runtime_error(path + ": " + problem);
  return k;
}

}  // namespace quadric_slam
