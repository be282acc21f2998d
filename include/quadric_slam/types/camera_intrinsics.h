// Pinhole intrinsics of a depth camera: the plain type every layer shares (no PCL, no OpenCV).
#pragma once

#include <string>

namespace quadric_slam {

// Pinhole intrinsics of a depth image (pixels). Depth is registered to this camera.
struct CameraIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;

  // Empty when usable, else a sentence naming what is wrong.
  std::string problem() const;
  bool valid() const { return problem().empty(); }
};

// Parses "fx,fy,cx,cy" (the tools' --intrinsics) into k, leaving width/height; false when
// malformed.
bool parseIntrinsics(const std::string& text, CameraIntrinsics& k);

// Empty when an image of width x height fits these intrinsics, else the reason.
std::string imageSizeProblem(const CameraIntrinsics& intrinsics, int width, int height);

}  // namespace quadric_slam
