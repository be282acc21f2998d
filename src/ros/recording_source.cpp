#include "quadric_slam/ros/recording_source.h"

#include <filesystem>
#include <stdexcept>

#include "quadric_slam/io/tum_folder_reader.h"
#include "quadric_slam/ros/tum_bag_reader.h"

namespace quadric_slam {

std::unique_ptr<FrameSource> openRecording(const std::string& path,
                                           const RecordingOptions& options) {
  namespace fs = std::filesystem;
  if (fs::is_directory(path)) {
    TumFolderReader::Params params;
    // A depth frame without an RGB partner (io/stamp_association.h) runs uncoloured, so the
    // frames are those of a depth-only run.
    params.load_rgb = options.rgb && fs::is_regular_file(fs::path(path) / "rgb.txt");
    params.keep_frames_without_rgb = true;
    if (options.intrinsics.fx > 0)
      params.intrinsics = options.intrinsics;
    return std::make_unique<TumFolderReader>(path, params);
  }
  if (fs::is_regular_file(path)) {
    TumBagReader::Params params;
    if (!options.rgb)
      params.rgb_topic.clear();             // depth only
    params.keep_frames_without_rgb = true;  // as for a folder: the same frames with or without RGB
    if (options.intrinsics.fx > 0)
      params.intrinsics = options.intrinsics;
    return std::make_unique<TumBagReader>(path, params);
  }
  throw std::runtime_error("INPUT " + path + " is neither a TUM folder nor a bag file");
}

}  // namespace quadric_slam
