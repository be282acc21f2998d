// TUM depth PNGs: 16-bit single channel, `units_per_metre` units per metre (5000 for TUM), 0 = no
// measurement.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace quadric_slam {

// CV_16UC1 raw depth -> CV_32FC1 metres, 0 -> NaN. Throws std::invalid_argument on another type
// or a units_per_metre that is not positive and finite.
cv::Mat depthUnitsToMetres(const cv::Mat& raw, double units_per_metre);

// Reads one TUM depth PNG to CV_32FC1 metres (NaN = no data). Throws std::runtime_error naming the
// file when it cannot be read or is not a 16-bit single-channel image.
cv::Mat readTumDepthPng(const std::string& path, double units_per_metre = 5000.0);

// Reads an 8-bit colour PNG as CV_8UC3 in RGB channel order (as sensor_msgs rgb8). Throws
// std::runtime_error naming the file when it cannot be read.
cv::Mat readRgbPng(const std::string& path);

}  // namespace quadric_slam
