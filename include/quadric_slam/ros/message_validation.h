// Checks of incoming sensor messages, run before any conversion touches their buffers. A message's
// sizes are whatever its publisher (or a corrupted byte) says: every product is formed in 64 bits,
// every field must lie inside its point, the buffer must be exactly as long as the layout says, and
// no declared size may exceed a real sensor's, so nothing is read out of bounds and nothing huge is
// allocated. Each check returns "" when the message is usable, else one sentence naming the field
// at fault.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include <cstdint>
#include <string>
#include <vector>

namespace quadric_slam {

// The most pixels (or points) a message may declare: a 4096 x 4096 sensor.
constexpr std::uint64_t kMaxMessagePixels = 4096ull * 4096ull;

// The smallest image or organized cloud the front end takes: NormalEstimator needs an organized
// cloud (more than one row), QuadricSegmenter a grid, and point-to-plane odometry a neighbour in
// each direction; 2 x 2 is the smallest grid all of them accept (test_message_validation runs the
// core on it).
constexpr std::uint32_t kMinGridSide = 2;

// What a consumer reads from a PointCloud2.
struct CloudLayout {
  // Fields read as one little-endian float32 each, by name.
  std::vector<std::string> float32_fields;
  // Whether the cloud must be an organized grid of at least kMinGridSide x kMinGridSide.
  bool organized = true;
  // Whether a cloud without points, declared 0 x 0 or 0 x 1 as PCL writes an empty cloud, passes
  // (an organized layout still refuses 0 x 480 and the like).
  bool allow_empty = true;
};

// x y z normal_x normal_y normal_z, organized or empty: quadric_slam/NormalEstimation's
// points_normals.
const CloudLayout& pointsNormalsLayout();

// Empty when the cloud can be read with the layout: little-endian, width x height within
// kMaxMessagePixels (and a grid when organized, unless empty and allowed), each field present,
// FLOAT32, count 1 and ending within point_step, row_step >= width * point_step, data exactly
// row_step * height bytes.
std::string pointCloudProblem(const sensor_msgs::PointCloud2& cloud, const CloudLayout& layout);

// Empty when the image is a depth image this package reads (32FC1 metres, 16UC1 or mono16
// millimetres), little-endian, at least kMinGridSide x kMinGridSide and at most kMaxMessagePixels,
// step >= width * pixel size, data exactly step * height bytes.
std::string depthImageProblem(const sensor_msgs::Image& image);

// Empty when the image is a colour image the mapping nodelet reads (rgb8, bgr8 or mono8; the
// reconstruction's colours), at least kMinGridSide x kMinGridSide and at most kMaxMessagePixels,
// step >= width * pixel size, data exactly step * height bytes.
std::string colourImageProblem(const sensor_msgs::Image& image);

// Empty when camera_info describes a usable camera: a size like an image's (see depthImageProblem)
// and positive finite focal lengths, finite principal point.
std::string cameraInfoProblem(const sensor_msgs::CameraInfo& info);

}  // namespace quadric_slam
