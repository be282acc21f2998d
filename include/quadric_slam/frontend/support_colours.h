// The RGB colour of each supporting point of a frame's measurements (types/observation.h), sampled
// from an RGB image registered to the depth camera: the colour camera and the depth camera share
// one optical frame and one pinhole model up to image scale (TUM RGB-D, OpenNI/RealSense
// depth_registered). A support point p_camera came from the depth pixel
// (fx x / z + cx, fy y / z + cy); projecting it back with the intrinsics recovers that pixel, whose
// colour is the point's. An RGB image of another size than the intrinsics' image (a camera that
// streams colour at a different resolution) is sampled at the pixel scaled by the size ratio; a
// different aspect ratio cannot be a resized registered image and is refused.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "quadric_slam/types/camera_intrinsics.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

// 0xAARRGGBB packing of support colours and reconstruction points: alpha 255 = a sampled colour,
// alpha 0 = none.
constexpr std::uint32_t kNoColour = 0;
inline std::uint32_t packColour(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  return 0xFF000000u | (std::uint32_t{r} << 16) | (std::uint32_t{g} << 8) | std::uint32_t{b};
}
inline bool hasColour(std::uint32_t rgba) {
  return (rgba >> 24) != 0;
}

// Fills support_colours of every measurement of `frame` (one per support point; kNoColour where
// the point does not project into the image or is not finite) from `rgb`, CV_8UC3 in R G B channel
// order, whose camera is registered to `intrinsics` (the depth camera's; width/height give the
// image size the intrinsics describe, 0 = the RGB image's own size). Returns the number of coloured
// points. Throws std::invalid_argument when rgb is not CV_8UC3, the intrinsics are not finite and
// positive, or the RGB image has another aspect ratio than the intrinsics' image (more than 1%).
int colourSupportPoints(FrameMeasurements& frame, const cv::Mat& rgb,
                        const CameraIntrinsics& intrinsics);

}  // namespace quadric_slam
