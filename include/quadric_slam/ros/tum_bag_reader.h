// Frames from a TUM RGB-D rosbag (or any bag with the same topics), read offline with
// rosbag::View (no master): depth /camera/depth/image (32FC1 metres or 16UC1 millimetres; 0 and
// NaN = no data), paired with /camera/rgb/image_color (rgb8 or bgr8) by associate.py's rule on
// header stamps, intrinsics from the first /camera/depth/camera_info (or an override).
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/io/frame_source.h"

namespace quadric_slam {

class TumBagReader : public FrameSource {
 public:
  struct Params {
    std::string depth_topic = "/camera/depth/image";
    std::string rgb_topic = "/camera/rgb/image_color";  // empty: depth only
    std::string camera_info_topic = "/camera/depth/camera_info";
    double max_rgb_difference = 0.02;      // s, RGB-depth pairing gate (associate.py default)
    bool keep_frames_without_rgb = false;  // true: depth frames with no RGB partner, rgb empty
    // fx = 0 (the default): from the first camera_info message. width/height 0: from the images.
    CameraIntrinsics intrinsics;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // Opens the bag and indexes the depth and RGB messages by header stamp (images are decoded only
  // in next()). Throws std::runtime_error when the bag cannot be opened, holds no depth message on
  // depth_topic, or has no camera_info while no intrinsics override is given. When the bag has no
  // message on rgb_topic every depth frame is kept, without RGB.
  explicit TumBagReader(const std::string& bag_path) : TumBagReader(bag_path, Params{}) {}
  TumBagReader(const std::string& bag_path, const Params& params);
  ~TumBagReader() override;

  // Throws std::runtime_error naming the topic, stamp and problem for an unsupported encoding or
  // an image whose size does not match the intrinsics.
  bool next(RgbdFrame& frame) override;
  std::size_t size() const override;
  void rewind() override;

  const CameraIntrinsics& intrinsics() const;

 private:
  // The constructor's and next()'s work; their callers make every error name the bag.
  void open(const std::string& bag_path, const Params& params);
  bool readNext(RgbdFrame& frame);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace quadric_slam
