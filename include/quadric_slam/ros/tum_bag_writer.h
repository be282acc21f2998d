// Writes a synthetic sequence as a rosbag in the TUM RGB-D layout: /camera/depth/image (32FC1
// metres, NaN = no data), /camera/rgb/image_color (rgb8), /camera/{depth,rgb}/camera_info and
// /tf (tf2_msgs/TFMessage: the ground truth /world -> /kinect and the Kinect's fixed chain) at
// every frame. Images are registered to the RGB camera (frame /openni_rgb_optical_frame). Record
// times equal the message stamps.
#pragma once

#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>

#include <string>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/trajectory.h"

namespace quadric_slam {

class TumBagWriter {
 public:
  struct Params {
    std::string compression = "none";  // none | lz4 | bz2 (rosbag chunk compression)

    // Throws std::invalid_argument naming the bad field and its allowed values.
    void validate() const;
  };

  // Opens the bag for writing; throws std::runtime_error when it cannot.
  TumBagWriter(const std::string& path, const CameraIntrinsics& camera, const Params& params);
  ~TumBagWriter();

  // Writes /tf, both camera_infos and both images of one frame, stamped pose.stamp.
  void write(const StampedPose& pose, const RenderedFrame& frame);
  void close();

  // CameraInfo of the intrinsics (plumb_bob, zero distortion), frame /openni_rgb_optical_frame.
  static sensor_msgs::CameraInfo cameraInfo(const CameraIntrinsics& camera);

 private:
  rosbag::Bag bag_;
  CameraIntrinsics camera_;
  std::uint32_t seq_ = 0;
};

}  // namespace quadric_slam
