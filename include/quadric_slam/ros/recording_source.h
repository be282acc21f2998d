// A TUM RGB-D recording on disk as a frame source: a TUM folder (rgb.txt, depth.txt, depth/;
// io/tum_folder_reader.h) or a TUM rosbag (ros/tum_bag_reader.h). The offline tools open their
// input here, so a folder and a bag are read alike.
#pragma once

#include <memory>
#include <string>

#include "quadric_slam/io/frame_source.h"

namespace quadric_slam {

struct RecordingOptions {
  // Read RGB when the recording has it (registered to depth, paired by stamp); a depth frame
  // without an RGB partner is kept, uncoloured. false: depth only.
  bool rgb = true;
  // fx = 0: the recording's own intrinsics (a folder's camera_info.yaml or its name; a bag's
  // camera_info).
  CameraIntrinsics intrinsics;
};

// Throws std::runtime_error when `path` is neither a directory nor a file, or cannot be read.
std::unique_ptr<FrameSource> openRecording(const std::string& path,
                                           const RecordingOptions& options);

}  // namespace quadric_slam
