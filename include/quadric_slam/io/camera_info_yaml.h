// A camera's pinhole intrinsics in the YAML file ROS's camera_calibration and camera_info_manager
// write (image_width, image_height, camera_name, camera_matrix {rows, cols, data}, distortion,
// rectification and projection matrices). A TUM folder carries no intrinsics of its own; the
// generator writes its camera here as DIR/camera_info.yaml, and the folder reader prefers that
// file to guessing from the folder's name.
#pragma once

#include <string>

#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// The file name a TUM folder's intrinsics are kept under.
inline constexpr char kCameraInfoFileName[] = "camera_info.yaml";

// Writes k (no distortion: depth here is rectified) as camera_name. Throws std::runtime_error
// naming the file when it cannot be written.
void writeCameraInfoYaml(const std::string& path, const CameraIntrinsics& k,
                         const std::string& camera_name);

// Reads fx, fy, cx, cy from camera_matrix and the image size. Throws std::runtime_error naming
// the file and the problem: unreadable, not YAML, a missing or malformed key, intrinsics that are
// not usable (CameraIntrinsics::problem), or a distortion that is not zero (this package reads
// rectified depth only).
CameraIntrinsics readCameraInfoYaml(const std::string& path);

}  // namespace quadric_slam
