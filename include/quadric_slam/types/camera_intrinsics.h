// Pinhole intrinsics of a depth camera: the plain type every layer shares (no PCL, no OpenCV).
#pragma once

#include <string>

namespace quadric_slam {

// Pinhole intrinsics of a depth image (pixels). Depth is registered to this camera.
struct CameraIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;

  // Empty when usable, else a sentence naming what is wrong: focal lengths must be positive and
  // finite, the image size positive, the field of view between kMinFieldOfView and
  // kMaxFieldOfView in both axes (a finite but absurd focal length, e.g. 1e-300 or 1e300 from a
  // corrupted camera_info, would back-project to infinite or collapsed points), and the
  // principal point within kMaxPrincipalPointOffset image sizes of the image.
  std::string problem() const;
  static constexpr double kMinFieldOfView = 0.1 * 3.14159265358979323846 / 180.0;    // rad
  static constexpr double kMaxFieldOfView = 179.0 * 3.14159265358979323846 / 180.0;  // rad
  static constexpr double kMaxPrincipalPointOffset = 10.0;
  bool valid() const { return problem().empty(); }
};

// Parses "fx,fy,cx,cy" (the tools' --intrinsics) into k, leaving width/height; false when
// malformed.
bool parseIntrinsics(const std::string& text, CameraIntrinsics& k);

// Empty when an image of width x height fits these intrinsics, else the reason.
std::string imageSizeProblem(const CameraIntrinsics& intrinsics, int width, int height);

}  // namespace quadric_slam
