// One interface for synchronised depth (+ RGB) frames, whatever they come from (a TUM folder, a
// rosbag, a generator).
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <string>

#include "quadric_slam/frontend/frame.h"

namespace quadric_slam {

struct RgbdFrame {
  double stamp = 0.0;      // s, of the depth image
  cv::Mat depth_m;         // CV_32FC1 metres, NaN = no data
  cv::Mat rgb;             // CV_8UC3 in RGB channel order (sensor_msgs rgb8), or empty
  double rgb_stamp = 0.0;  // s, of the paired RGB image (meaningful only when rgb is not empty)
  CameraIntrinsics intrinsics;  // of the depth image (registered to RGB); width/height = image size
  std::string frame_id;         // optical frame of the depth camera
};

// A CV_32FC1 depth image in metres as the back-projection's view (no copy; the Mat must outlive
// it).
DepthImageView<float> depthViewOf(const cv::Mat& depth_m);

// Checks the parameters every reader shares: the RGB pairing gate (s, > 0) and an optional
// intrinsics override (fx = 0: none; width/height 0: from the images). Throws
// std::invalid_argument naming the bad field.
void validateReaderParams(double max_rgb_difference, const CameraIntrinsics& intrinsics_override);

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Fills the next frame in stamp order; false at the end. Throws std::runtime_error on unreadable
  // data (naming the file or message).
  virtual bool next(RgbdFrame& frame) = 0;
  // Total number of frames the source yields from the start.
  virtual std::size_t size() const = 0;
  // Back to the first frame.
  virtual void rewind() = 0;
};

}  // namespace quadric_slam
