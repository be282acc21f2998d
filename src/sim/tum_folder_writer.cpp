#include "quadric_slam/sim/tum_folder_writer.h"

#include "quadric_slam/io/camera_info_yaml.h"
#include "quadric_slam/sim/png_writer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace quadric_slam {

void TumFolderWriter::Params::validate() const {
  if (png_compression < 0 || png_compression > 9)
    throw std::invalid_argument("TumFolderWriter::Params::png_compression must be in [0, 9]");
}

TumFolderWriter::TumFolderWriter(const std::string& directory, const Params& params)
    : directory_(directory), params_(params) {
  params_.validate();
  std::error_code error;
  std::filesystem::create_directories(directory_, error);
  if (params_.images) {
    std::filesystem::create_directories(directory_ + "/rgb", error);
    std::filesystem::create_directories(directory_ + "/depth", error);
  }
  if (params_.labels)
    std::filesystem::create_directories(directory_ + "/labels", error);
  if (error || !std::filesystem::is_directory(directory_))
    throw std::runtime_error("cannot create output directory " + directory_);
}

std::string TumFolderWriter::stampString(double stamp) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.6f", stamp);
  return buffer;
}

cv::Mat TumFolderWriter::encodeDepth(const cv::Mat& depth_metres) {
  cv::Mat out(depth_metres.size(), CV_16UC1);
  for (int v = 0; v < depth_metres.rows; ++v) {
    const float* in = depth_metres.ptr<float>(v);
    std::uint16_t* o = out.ptr<std::uint16_t>(v);
    for (int u = 0; u < depth_metres.cols; ++u) {
      const double units = std::round(static_cast<double>(in[u]) * 5000.0);
      o[u] = (std::isfinite(units) && units > 0.0 && units <= 65535.0)
                 ? static_cast<std::uint16_t>(units)
                 : 0;
    }
  }
  return out;
}

void TumFolderWriter::writeFrame(const StampedPose& pose, const RenderedFrame& frame) const {
  const std::string stamp = stampString(pose.stamp);
  if (params_.images) {
    writePng(directory_ + "/rgb/" + stamp + ".png", frame.rgb, params_.png_compression);
    writePng(directory_ + "/depth/" + stamp + ".png", encodeDepth(frame.depth),
             params_.png_compression);
  }
  if (params_.labels)
    writePng(directory_ + "/labels/" + stamp + ".png", frame.labels, params_.png_compression);
}

void TumFolderWriter::finish(const std::vector<StampedPose>& frames) const {
  auto open = [&](const std::string& name) {
    std::ofstream out(directory_ + "/" + name);
    if (!out)
      throw std::runtime_error("cannot write " + directory_ + "/" + name);
    return out;
  };
  const std::string file = "# file: '" + params_.sequence_name + ".bag'\n";
  if (params_.images) {
    std::ofstream rgb = open("rgb.txt"), depth = open("depth.txt");
    rgb << "# color images\n" << file << "# timestamp filename\n";
    depth << "# depth maps\n" << file << "# timestamp filename\n";
    for (const StampedPose& f : frames) {
      const std::string stamp = stampString(f.stamp);
      rgb << stamp << " rgb/" << stamp << ".png\n";
      depth << stamp << " depth/" << stamp << ".png\n";
    }
    if (params_.camera.fx > 0)
      writeCameraInfoYaml(directory_ + "/" + kCameraInfoFileName, params_.camera,
                          params_.sequence_name);
  }
  std::ofstream gt = open("groundtruth.txt");
  gt << "# ground truth trajectory\n" << file;
  writeTumTrajectory(frames, gt);
  if (!gt)
    throw std::runtime_error("failed writing " + directory_ + "/groundtruth.txt");
}

}  // namespace quadric_slam
