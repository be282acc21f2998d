// The intrinsics of the unit tests' rendered frames: the ROS defaults of a Kinect v1 at 640 x 480.
#pragma once

#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {
namespace test {

inline CameraIntrinsics kinectVga() {
  CameraIntrinsics k;
  k.fx = k.fy = 525.0;
  k.cx = 319.5;
  k.cy = 239.5;
  k.width = 640;
  k.height = 480;
  return k;
}

}  // namespace test
}  // namespace quadric_slam
