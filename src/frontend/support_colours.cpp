#include "quadric_slam/frontend/support_colours.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace quadric_slam {

int colourSupportPoints(FrameMeasurements& frame, const cv::Mat& rgb,
                        const CameraIntrinsics& intrinsics) {
  if (rgb.type() != CV_8UC3 || rgb.empty())
    throw std::invalid_argument("colourSupportPoints: the RGB image must be a non-empty CV_8UC3");
  const double values[] = {intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy};
  for (double value : values)
    if (!std::isfinite(value))
      throw std::invalid_argument("colourSupportPoints: intrinsics must be finite");
  if (!(intrinsics.fx > 0.0 && intrinsics.fy > 0.0))
    throw std::invalid_argument("colourSupportPoints: fx and fy must be > 0");
  // Pixel of the intrinsics' image -> pixel of the RGB image (the same field of view).
  const double scale_u =
      intrinsics.width > 0 ? static_cast<double>(rgb.cols) / intrinsics.width : 1.0;
  const double scale_v =
      intrinsics.height > 0 ? static_cast<double>(rgb.rows) / intrinsics.height : 1.0;
  if (std::abs(scale_u / scale_v - 1.0) > 0.01)
    throw std::invalid_argument(
        "colourSupportPoints: the RGB image (" + std::to_string(rgb.cols) + "x" +
        std::to_string(rgb.rows) + ") has another aspect ratio than the depth intrinsics (" +
        std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height) +
        "): not a registered colour image");
  int coloured = 0;
  for (QuadricMeasurement& measurement : frame.observations) {
    measurement.support_colours.assign(measurement.support_points.size(), kNoColour);
    for (std::size_t i = 0; i < measurement.support_points.size(); ++i) {
      const Eigen::Vector3f& p = measurement.support_points[i];
      if (!p.allFinite() || !(p.z() > 0.0f))
        continue;
      // Pixel centres are at integer coordinates (the back-projection's convention,
      // frontend/frame.h); scaling maps pixel areas, so centres move by (scale - 1) / 2.
      const double u = (intrinsics.fx * p.x() / p.z() + intrinsics.cx + 0.5) * scale_u - 0.5;
      const double v = (intrinsics.fy * p.y() / p.z() + intrinsics.cy + 0.5) * scale_v - 0.5;
      const long col = std::lround(u), row = std::lround(v);
      if (col < 0 || row < 0 || col >= rgb.cols || row >= rgb.rows)
        continue;
      const cv::Vec3b& c = rgb.at<cv::Vec3b>(static_cast<int>(row), static_cast<int>(col));
      measurement.support_colours[i] = packColour(c[0], c[1], c[2]);
      ++coloured;
    }
  }
  return coloured;
}

}  // namespace quadric_slam
