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
