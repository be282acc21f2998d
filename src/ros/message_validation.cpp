#include "quadric_slam/ros/message_validation.h"

#include <sensor_msgs/image_encodings.h>

#include <sstream>

#include "quadric_slam/ros/depth_image.h"

namespace quadric_slam {
namespace {

namespace enc = sensor_msgs::image_encodings;

std::string datatypeName(std::uint8_t datatype) {
  static const char* const names[] = {"INT8",  "UINT8",  "INT16",   "UINT16",
                                      "INT32", "UINT32", "FLOAT32", "FLOAT64"};
  if (datatype >= 1 && datatype <= 8)
    return names[datatype - 1];
  return "unknown datatype " + std::to_string(datatype);
}

// Empty when a width x height grid is within kMaxMessagePixels and, when organized, at least
// kMinGridSide on each side. what: "cloud", "depth image", "camera_info".
std::string gridSizeProblem(const std::string& what, std::uint32_t width, std::uint32_t height,
                            bool organized) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * height;
  std::ostringstream why;
  if (pixels > kMaxMessagePixels) {
    why << what << " declares " << width << " x " << height << " = " << pixels
        << " points, more than the " << kMaxMessagePixels << " (4096 x 4096) accepted";
  } else if (organized && (width < kMinGridSide || height < kMinGridSide)) {
    why << what << " is " << width << " x " << height << ": not an organized depth-image grid "
        << "(width and height must be at least " << kMinGridSide << ")";
  }
  return why.str();
}

std::string fieldProblem(const sensor_msgs::PointCloud2& cloud, const std::string& name) {
  for (const sensor_msgs::PointField& field : cloud.fields) {
    if (field.name != name)
      continue;
    std::ostringstream why;
    if (field.datatype != sensor_msgs::PointField::FLOAT32) {
      why << "field '" << name << "' is " << datatypeName(field.datatype)
          << "; only FLOAT32 is supported";
    } else if (field.count != 1) {
      why << "field '" << name << "' has count " << field.count << "; expected 1";
    } else if (static_cast<std::uint64_t>(field.offset) + sizeof(float) > cloud.point_step) {
      why << "field '" << name << "' (offset " << field.offset << ") ends at byte "
          << static_cast<std::uint64_t>(field.offset) + sizeof(float) << " but point_step is "
          << cloud.point_step;
    }
    return why.str();
  }
  return "cloud has no field '" + name + "'";
}

// Bytes per pixel of a depth encoding this package reads, 0 for any other encoding.
std::size_t depthPixelBytes(const std::string& encoding) {
  if (encoding == enc::TYPE_32FC1)
    return sizeof(float);
  if (encoding == enc::TYPE_16UC1 || encoding == enc::MONO16)
    return sizeof(std::uint16_t);
  return 0;
}

}  // namespace

const CloudLayout& pointsNormalsLayout() {
  static const CloudLayout layout{{"x", "y", "z", "normal_x", "normal_y", "normal_z"}, true, true};
  return layout;
}

std::string pointCloudProblem(const sensor_msgs::PointCloud2& cloud, const CloudLayout& layout) {
  if (cloud.is_bigendian)
    return "big-endian cloud (is_bigendian true) is not supported";
  const bool empty = cloud.width == 0 && cloud.height <= 1;
  std::string problem = gridSizeProblem("cloud", cloud.width, cloud.height,
                                        layout.organized && !(layout.allow_empty && empty));
  if (!problem.empty())
    return problem;
  for (const std::string& name : layout.float32_fields) {
    problem = fieldProblem(cloud, name);
    if (!problem.empty()) {
      std::string needed;
      for (const std::string& n : layout.float32_fields)
        needed += (needed.empty() ? "" : " ") + n;
      return problem + " (" + std::to_string(cloud.width) + " x " + std::to_string(cloud.height) +
             " cloud; needs float32 " + needed + ")";
    }
  }
  std::ostringstream why;
  const std::uint64_t row_bytes = static_cast<std::uint64_t>(cloud.width) * cloud.point_step;
  const std::uint64_t data_bytes = static_cast<std::uint64_t>(cloud.row_step) * cloud.height;
  if (cloud.row_step < row_bytes) {
    why << "row_step " << cloud.row_step << " is smaller than width x point_step (" << cloud.width
        << " x " << cloud.point_step << " = " << row_bytes << ")";
  } else if (cloud.data.size() != data_bytes) {
    why << "data has " << cloud.data.size() << " bytes, but row_step x height is " << cloud.row_step
        << " x " << cloud.height << " = " << data_bytes;
  }
  return why.str();
}

namespace {

// The grid size, step and data length of an image whose pixels take pixel_bytes each; "" when
// they fit. kind names the image in the message ("depth image").
std::string imageLayoutProblem(const sensor_msgs::Image& image, const std::string& kind,
                               std::size_t pixel_bytes) {
  std::string problem = gridSizeProblem(kind, image.width, image.height, true);
  if (!problem.empty())
    return problem;
  std::ostringstream why;
  const std::uint64_t row_bytes = static_cast<std::uint64_t>(image.width) * pixel_bytes;
  const std::uint64_t data_bytes = static_cast<std::uint64_t>(image.step) * image.height;
  if (image.step < row_bytes) {
    why << image.encoding << " " << kind << " step " << image.step
        << " is smaller than width x pixel size (" << image.width << " x " << pixel_bytes << " = "
        << row_bytes << ")";
  } else if (image.data.size() != data_bytes) {
    why << image.encoding << " " << kind << " data has " << image.data.size()
        << " bytes, but step x height is " << image.step << " x " << image.height << " = "
        << data_bytes;
  }
  return why.str();
}

}  // namespace

std::string depthImageProblem(const sensor_msgs::Image& image) {
  const std::size_t pixel_bytes = depthPixelBytes(image.encoding);
  if (pixel_bytes == 0) {
    return "unsupported depth encoding '" + image.encoding +
           "' (expected 32FC1 metres or 16UC1 millimetres)";
  }
  if (image.is_bigendian)
    return "big-endian depth image (is_bigendian true) is not supported";
  return imageLayoutProblem(image, "depth image", pixel_bytes);
}

std::string colourImageProblem(const sensor_msgs::Image& image) {
  const std::size_t pixel_bytes = image.encoding == "rgb8" || image.encoding == "bgr8" ? 3
                                  : image.encoding == "mono8"                          ? 1
                                                                                       : 0;
  if (pixel_bytes == 0)
    return "unsupported colour encoding '" + image.encoding + "' (expected rgb8, bgr8 or mono8)";
  return imageLayoutProblem(image, "colour image", pixel_bytes);
}

std::string cameraInfoProblem(const sensor_msgs::CameraInfo& info) {
  const std::string problem = gridSizeProblem("camera_info", info.width, info.height, true);
  if (!problem.empty())
    return problem;
  return intrinsicsFromCameraInfo(info).problem();
}

}  // namespace quadric_slam
