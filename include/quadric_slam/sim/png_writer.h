// A fast PNG encoder for the generator's images (zlib directly, one fixed PNG filter per image
// type instead of libpng's per-row filter search): 8-bit RGB (given in R G B order), 8-bit grey
// and 16-bit grey. About twice as fast as OpenCV's imwrite at the same compression level; any PNG
// reader decodes the result.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace quadric_slam {

// PNG bytes of a CV_8UC3 (R G B order), CV_8UC1 or CV_16UC1 image; zlib level 0 (none) .. 9.
// Throws std::invalid_argument for other types or levels.
std::vector<unsigned char> encodePng(const cv::Mat& image, int level = 1);
// Writes encodePng(image, level) to path; throws std::runtime_error when it cannot.
void writePng(const std::string& path, const cv::Mat& image, int level = 1);

}  // namespace quadric_slam
