#include "quadric_slam/io/frame_source.h"

#include <cmath>
#include <stdexcept>

namespace quadric_slam {

DepthImageView<float> depthViewOf(const cv::Mat& depth_m) {
  if (depth_m.type() != CV_32FC1)
    throw std::invalid_argument("depthViewOf needs a CV_32FC1 image in metres");
  DepthImageView<float> view;
  view.data = depth_m.data;
  view.width = depth_m.cols;
  view.height = depth_m.rows;
  view.row_step_bytes = depth_m.step;
  view.metres_per_unit = 1.0;
  return view;
}

void validateReaderParams(double max_rgb_difference, const CameraIntrinsics& intrinsics_override) {
  if (!(max_rgb_difference > 0.0) || !std::isfinite(max_rgb_difference)) {
    throw std::invalid_argument("max_rgb_difference must be in (0, inf) s, got " +
                                std::to_string(max_rgb_difference));
  }
  if (intrinsics_override.fx != 0.0) {
    CameraIntrinsics check = intrinsics_override;
    if (check.width == 0 && check.height == 0) {
      // The size comes from the images (checked with it on every frame); until then assume the
      // principal point near the image centre, so the field-of-view rule has a size to work with.
      const auto axis = [](double c) {
        return std::isfinite(c) && c >= 0.5 && c < 1e6 ? static_cast<int>(std::lround(2 * c)) : 1;
      };
      check.width = axis(check.cx);
      check.height = axis(check.cy);
    }
    const std::string problem = check.problem();
    if (!problem.empty())
      throw std::invalid_argument("intrinsics: " + problem);
  }
}

}  // namespace quadric_slam
