#include "quadric_slam/types/camera_intrinsics.h"

#include <cmath>
#include <sstream>

namespace quadric_slam {

std::string CameraIntrinsics::problem() const {
  std::ostringstream why;
  if (!(fx > 0) || !(fy > 0) || !std::isfinite(fx) || !std::isfinite(fy)) {
    why << "focal lengths must be positive and finite (fx " << fx << ", fy " << fy << ")";
  } else if (!std::isfinite(cx) || !std::isfinite(cy)) {
    why << "principal point must be finite";
  } else if (width <= 0 || height <= 0) {
    why << "image size must be positive (" << width << " x " << height << ")";
  } else {
    // Field of view of an axis of n pixels with focal length f: 2 atan(n / (2 f)).
    const double fov_x = 2.0 * std::atan(width / (2.0 * fx));
    const double fov_y = 2.0 * std::atan(height / (2.0 * fy));
    const double deg = 180.0 / M_PI;
    if (!(fov_x >= kMinFieldOfView && fov_x <= kMaxFieldOfView && fov_y >= kMinFieldOfView &&
          fov_y <= kMaxFieldOfView)) {
      why << "focal lengths (fx " << fx << ", fy " << fy << ") give a field of view of "
          << fov_x * deg << " x " << fov_y * deg << " degrees for " << width << " x " << height
          << " pixels; it must be within [" << kMinFieldOfView * deg << ", "
          << kMaxFieldOfView * deg << "] degrees";
    } else if (std::abs(cx - 0.5 * width) > (kMaxPrincipalPointOffset + 0.5) * width ||
               std::abs(cy - 0.5 * height) > (kMaxPrincipalPointOffset + 0.5) * height) {
      why << "principal point (" << cx << ", " << cy << ") lies more than "
          << kMaxPrincipalPointOffset << " image sizes outside the " << width << " x " << height
          << " image";
    }
  }
  return why.str();
}

bool parseIntrinsics(const std::string& text, CameraIntrinsics& k) {
  std::stringstream in(text);
  CameraIntrinsics parsed = k;
  char c1 = 0, c2 = 0, c3 = 0;
  in >> parsed.fx >> c1 >> parsed.fy >> c2 >> parsed.cx >> c3 >> parsed.cy;
  if (!in || c1 != ',' || c2 != ',' || c3 != ',')
    return false;
  k = parsed;
  return true;
}

std::string imageSizeProblem(const CameraIntrinsics& intrinsics, int width, int height) {
  const std::string intrinsics_problem = intrinsics.problem();
  if (!intrinsics_problem.empty())
    return "invalid intrinsics: " + intrinsics_problem;
  if (width != intrinsics.width || height != intrinsics.height) {
    std::ostringstream why;
    why << "depth image is " << width << " x " << height << " but camera_info says "
        << intrinsics.width << " x " << intrinsics.height;
    return why.str();
  }
  return "";
}

}  // namespace quadric_slam
