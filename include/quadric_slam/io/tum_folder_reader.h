// Frames from an extracted TUM RGB-D sequence folder: depth.txt and rgb.txt (`timestamp filename`
// lines, '#' comments), depth/ 16-bit PNGs, rgb/ 8-bit PNGs, optional groundtruth.txt. Each depth
// image is paired with an RGB image by associate.py's rule (nearest stamps first, each used once,
// |difference| < max_rgb_difference).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// Intrinsics for a TUM sequence by its name (containing freiburg1/fr1, freiburg2/fr2,
// freiburg3/fr3; case-insensitive), else the ROS default 525/525/319.5/239.5; 640 x 480.
// fr1 517.3/516.5/318.6/255.3, fr2 520.9/521.0/325.1/249.7, fr3 535.4/539.2/320.1/247.6.
CameraIntrinsics tumIntrinsicsForSequence(const std::string& sequence_name);

class TumFolderReader : public FrameSource {
 public:
  struct Params {
    double depth_units_per_metre = 5000.0;  // TUM PNG units per metre (ORB-SLAM2 uses 5208 for fr2)
    double max_rgb_difference = 0.02;       // s, RGB-depth pairing gate (associate.py default)
    bool load_rgb = true;                   // false: depth only (rgb.txt not needed)
    bool keep_frames_without_rgb = false;   // true: depth frames with no RGB partner, rgb empty
    // fx = 0 (the default): the folder's camera_info.yaml when it has one (io/camera_info_yaml.h;
    // the generator writes it), else chosen from the folder name by tumIntrinsicsForSequence.
    // width/height 0: taken from each image; else they must match the images.
    CameraIntrinsics intrinsics;
    std::string frame_id = "openni_rgb_optical_frame";

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // Reads the lists (not the images). Throws std::runtime_error naming the file (and line) when a
  // list is missing or malformed.
  explicit TumFolderReader(const std::string& folder) : TumFolderReader(folder, Params{}) {}
  TumFolderReader(const std::string& folder, const Params& params);

  bool next(RgbdFrame& frame) override;
  std::size_t size() const override { return entries_.size(); }
  void rewind() override { position_ = 0; }

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  // groundtruth.txt when present, else empty.
  const Trajectory& groundtruth() const { return groundtruth_; }

 private:
  struct Entry {
    double depth_stamp;
    std::string depth_file;
    double rgb_stamp;
    std::string rgb_file;  // empty: no RGB
  };

  std::string folder_;
  Params params_;
  CameraIntrinsics intrinsics_;
  Trajectory groundtruth_;
  std::vector<Entry> entries_;
  std::size_t position_ = 0;
};

}  // namespace quadric_slam
