// Writes a sequence in the TUM RGB-D folder layout: rgb/<stamp>.png (8-bit RGB),
// depth/<stamp>.png (16-bit, 5000 per metre, 0 = no data), rgb.txt, depth.txt, groundtruth.txt
// (pose of the optical frame in the world), plus labels/<stamp>.png (16-bit surface ids) and
// camera_info.yaml (the camera's intrinsics, io/camera_info_yaml.h: the folder reader takes them
// from there rather than guessing from the folder's name).
#pragma once

#include <string>
#include <vector>

#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/trajectory.h"

namespace quadric_slam {

class TumFolderWriter {
 public:
  struct Params {
    bool images = true;                       // rgb/, depth/, rgb.txt, depth.txt
    bool labels = true;                       // labels/
    int png_compression = 1;                  // zlib level of the PNG files, 0 (none, fastest) .. 9
    std::string sequence_name = "synthetic";  // named in the header comments
    // The camera the images were rendered with, written as camera_info.yaml with the images
    // (fx = 0: not written).
    CameraIntrinsics camera;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // Creates the directory and its sub-directories; throws std::runtime_error when it cannot.
  TumFolderWriter(const std::string& directory, const Params& params);

  // Writes the frame's PNG files. Thread-safe (distinct files per frame).
  void writeFrame(const StampedPose& pose, const RenderedFrame& frame) const;
  // Writes rgb.txt, depth.txt, camera_info.yaml and groundtruth.txt for all frames.
  void finish(const std::vector<StampedPose>& frames) const;

  // TUM file-name stamp: seconds with 6 decimals.
  static std::string stampString(double stamp);
  // Depth in metres (NaN = none) to TUM's 16-bit encoding (5000 per metre, 0 = no data).
  static cv::Mat encodeDepth(const cv::Mat& depth_metres);

 private:
  std::string directory_;
  Params params_;
};

}  // namespace quadric_slam
