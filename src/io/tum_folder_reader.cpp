#include "quadric_slam/io/tum_folder_reader.h"

#include "quadric_slam/io/camera_info_yaml.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/stamp_association.h"

namespace quadric_slam {
namespace {

struct ListEntry {
  double stamp;
  std::string file;
};

// A TUM list file (rgb.txt, depth.txt): `timestamp filename` per line, '#' comments.
std::vector<ListEntry> readList(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error(path + ": cannot open");
  std::vector<ListEntry> entries;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#')
      continue;
    std::istringstream fields(line);
    std::string stamp_text, file;
    fields >> stamp_text >> file;
    char* end = nullptr;
    const double stamp = std::strtod(stamp_text.c_str(), &end);
    if (file.empty() || end == stamp_text.c_str() || *end != '\0' || !std::isfinite(stamp)) {
      throw std::runtime_error(path + ":" + std::to_string(number) +
                               ": expected 'timestamp filename'");
    }
    entries.push_back({stamp, file});
  }
  return entries;
}

bool fileExists(const std::string& path) {
  return static_cast<bool>(std::ifstream(path));
}

std::string baseName(std::string path) {
  while (path.size() > 1 && path.back() == '/')
    path.pop_back();
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

CameraIntrinsics tumIntrinsicsForSequence(const std::string& sequence_name) {
  std::string name = sequence_name;
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  CameraIntrinsics k;
  k.width = 640;
  k.height = 480;
  auto has = [&](const char* a, const char* b) {
    return name.find(a) != std::string::npos || name.find(b) != std::string::npos;
  };
  if (has("freiburg1", "fr1")) {
    k.fx = 517.3, k.fy = 516.5, k.cx = 318.6, k.cy = 255.3;
  } else if (has("freiburg2", "fr2")) {
    k.fx = 520.9, k.fy = 521.0, k.cx = 325.1, k.cy = 249.7;
  } else if (has("freiburg3", "fr3")) {
    k.fx = 535.4, k.fy = 539.2, k.cx = 320.1, k.cy = 247.6;
  } else {
    k.fx = 525.0, k.fy = 525.0, k.cx = 319.5, k.cy = 239.5;
  }
  return k;
}

void TumFolderReader::Params::validate() const {
  if (!(depth_units_per_metre > 0.0) || !std::isfinite(depth_units_per_metre)) {
    throw std::invalid_argument("depth_units_per_metre must be in (0, inf), got " +
                                std::to_string(depth_units_per_metre));
  }
  validateReaderParams(max_rgb_difference, intrinsics);
}

TumFolderReader::TumFolderReader(const std::string& folder, const Params& params)
    : folder_(folder), params_(params) {
  params_.validate();
  while (folder_.size() > 1 && folder_.back() == '/')
    folder_.pop_back();
  const std::string camera_info = folder_ + "/" + kCameraInfoFileName;
  if (params_.intrinsics.fx != 0.0)
    intrinsics_ = params_.intrinsics;
  else if (fileExists(camera_info))
    intrinsics_ = readCameraInfoYaml(camera_info);
  else
    intrinsics_ = tumIntrinsicsForSequence(baseName(folder_));
  if (params_.intrinsics.fx != 0.0 && params_.intrinsics.width == 0) {
    intrinsics_.width = intrinsics_.height = 0;  // from the images
  }

  const std::vector<ListEntry> depth = readList(folder_ + "/depth.txt");
  std::vector<ListEntry> rgb;
  if (params_.load_rgb)
    rgb = readList(folder_ + "/rgb.txt");
  if (fileExists(folder_ + "/groundtruth.txt")) {
    groundtruth_ = readTumTrajectory(folder_ + "/groundtruth.txt");
  }

  std::vector<long> rgb_of_depth(depth.size(), -1);
  if (!rgb.empty()) {
    std::vector<double> depth_stamps, rgb_stamps;
    for (const ListEntry& e : depth)
      depth_stamps.push_back(e.stamp);
    for (const ListEntry& e : rgb)
      rgb_stamps.push_back(e.stamp);
    StampAssociationParams association;
    association.max_difference = params_.max_rgb_difference;
    for (const auto& match : associateStamps(depth_stamps, rgb_stamps, association)) {
      rgb_of_depth[match.first] = static_cast<long>(match.second);
    }
  }
  for (std::size_t i = 0; i < depth.size(); ++i) {
    Entry entry{depth[i].stamp, depth[i].file, 0.0, ""};
    if (rgb_of_depth[i] >= 0) {
      const ListEntry& partner = rgb[static_cast<std::size_t>(rgb_of_depth[i])];
      entry.rgb_stamp = partner.stamp;
      entry.rgb_file = partner.file;
    } else if (params_.load_rgb && !params_.keep_frames_without_rgb) {
      continue;
    }
    entries_.push_back(entry);
  }
  std::stable_sort(entries_.begin(), entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.depth_stamp < b.depth_stamp; });
}

bool TumFolderReader::next(RgbdFrame& frame) {
  if (position_ >= entries_.size())
    return false;
  const Entry& entry = entries_[position_++];
  frame.stamp = entry.depth_stamp;
  frame.depth_m = readTumDepthPng(folder_ + "/" + entry.depth_file, params_.depth_units_per_metre);
  frame.rgb.release();
  frame.rgb_stamp = 0.0;
  if (!entry.rgb_file.empty()) {
    frame.rgb = readRgbPng(folder_ + "/" + entry.rgb_file);
    frame.rgb_stamp = entry.rgb_stamp;
    if (frame.rgb.size() != frame.depth_m.size()) {
      throw std::runtime_error(folder_ + "/" + entry.rgb_file + ": RGB size differs from depth " +
                               entry.depth_file);
    }
  }
  frame.intrinsics = intrinsics_;
  if (intrinsics_.width == 0) {
    frame.intrinsics.width = frame.depth_m.cols;
    frame.intrinsics.height = frame.depth_m.rows;
  } else if (frame.depth_m.cols != intrinsics_.width || frame.depth_m.rows != intrinsics_.height) {
    throw std::runtime_error(folder_ + "/" + entry.depth_file + ": " +
                             imageSizeProblem(intrinsics_, frame.depth_m.cols, frame.depth_m.rows));
  }
  frame.frame_id = params_.frame_id;
  return true;
}

}  // namespace quadric_slam
