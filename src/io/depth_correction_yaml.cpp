#include "quadric_slam/io/depth_correction_yaml.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <iomanip>
#include <stdexcept>
#include <vector>

namespace quadric_slam {

void writeDepthCorrectionYaml(const std::string& path, const DepthCorrection& correction,
                              const std::string& comment) {
  if (correction.empty())
    throw std::runtime_error("cannot write an empty depth correction to " + path);
  std::ofstream out(path);
  if (!out)
    throw std::runtime_error("cannot write " + path);
  out << "# Depth correction (quadric_slam frontend/depth_correction.h): true depth\n"
      << "# z = focal_baseline / (focal_baseline / z_measured + D(u, v)), D bilinear over the "
         "grid.\n";
  if (!comment.empty())
    out << "# " << comment << "\n";
  out << "image_width: " << correction.width() << "\n"
      << "image_height: " << correction.height() << "\n"
      << std::setprecision(10) << "focal_baseline: " << correction.focalBaseline() << "\n"
      << "grid_cols: " << correction.cols() << "\n"
      << "grid_rows: " << correction.rows() << "\n"
      << "offsets:  # disparity px, row-major\n";
  out << std::setprecision(6);
  for (int r = 0; r < correction.rows(); ++r) {
    out << "  - [";
    for (int c = 0; c < correction.cols(); ++c)
      out << (c ? ", " : "")
          << correction.offsets()[static_cast<std::size_t>(r) * correction.cols() + c];
    out << "]\n";
  }
  if (!out)
    throw std::runtime_error("failed writing " + path);
}

DepthCorrection readDepthCorrectionYaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read depth correction (" + e.what() + ")");
  }
  try {
    for (const char* key :
         {"image_width", "image_height", "focal_baseline", "grid_cols", "grid_rows", "offsets"})
      if (!root.IsMap() || !root[key])
        throw std::runtime_error(std::string("missing key ") + key);
    const int cols = root["grid_cols"].as<int>(), rows = root["grid_rows"].as<int>();
    const YAML::Node grid = root["offsets"];
    if (!grid.IsSequence() || static_cast<int>(grid.size()) != rows)
      throw std::runtime_error("offsets must hold grid_rows rows");
    std::vector<double> offsets;
    for (const YAML::Node& row : grid) {
      if (!row.IsSequence() || static_cast<int>(row.size()) != cols)
        throw std::runtime_error("each row of offsets must hold grid_cols numbers");
      for (const YAML::Node& value : row)
        offsets.push_back(value.as<double>());
    }
    return DepthCorrection(root["image_width"].as<int>(), root["image_height"].as<int>(), cols,
                           rows, std::move(offsets), root["focal_baseline"].as<double>());
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace quadric_slam
