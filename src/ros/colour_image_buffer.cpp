#include "quadric_slam/ros/colour_image_buffer.h"

#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <stdexcept>

#include "quadric_slam/ros/depth_image.h"
#include "quadric_slam/ros/message_validation.h"

namespace quadric_slam {

std::string colourImageToRgb(const sensor_msgs::ImageConstPtr& image,
                             cv_bridge::CvImageConstPtr* out) {
  out->reset();
  if (!image)
    return "no image";
  const std::string problem = colourImageProblem(*image);
  if (!problem.empty())
    return problem;
  try {
    *out = cv_bridge::toCvShare(image, sensor_msgs::image_encodings::RGB8);
  } catch (const cv_bridge::Exception& e) {
    return std::string("cv_bridge cannot convert the colour image: ") + e.what();
  }
  return "";
}

ColourImageBuffer::ColourImageBuffer(std::size_t capacity, double max_difference)
    : capacity_(capacity), max_difference_(max_difference) {
  if (capacity < 1)
    throw std::invalid_argument("ColourImageBuffer: capacity must be >= 1 image");
  if (!(max_difference > 0.0 && std::isfinite(max_difference)))
    throw std::invalid_argument("ColourImageBuffer: max_difference must be > 0 s, got " +
                                std::to_string(max_difference));
}

void ColourImageBuffer::add(Entry entry) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!entries_.empty() && entry.stamp < entries_.back().stamp)
    entries_.clear();
  entries_.push_back(std::move(entry));
  while (entries_.size() > capacity_)
    entries_.pop_front();
}

bool ColourImageBuffer::nearest(double stamp, Entry* out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Entry* best = nullptr;
  for (const Entry& entry : entries_)
    if (!best || std::abs(entry.stamp - stamp) < std::abs(best->stamp - stamp))
      best = &entry;
  if (!best || !(std::abs(best->stamp - stamp) < max_difference_))
    return false;
  *out = *best;
  return true;
}

void ColourImageBuffer::dropBefore(double stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  while (!entries_.empty() && entries_.front().stamp < stamp)
    entries_.pop_front();
}

bool ColourImageBuffer::span(double* oldest, double* newest) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (entries_.empty())
    return false;
  *oldest = entries_.front().stamp;
  *newest = entries_.back().stamp;
  return true;
}

void ColourImageBuffer::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.clear();
}

std::size_t ColourImageBuffer::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

std::string colourEntryFromMessages(const sensor_msgs::ImageConstPtr& image,
                                    const sensor_msgs::CameraInfoConstPtr& info,
                                    ColourImageBuffer::Entry* entry) {
  std::string problem = info ? cameraInfoProblem(*info) : "no camera_info";
  ColourImageBuffer::Entry usable;
  if (problem.empty())
    problem = colourImageToRgb(image, &usable.rgb);
  if (problem.empty() && (info->width != image->width || info->height != image->height))
    problem = "rgb/camera_info is for " + std::to_string(info->width) + "x" +
              std::to_string(info->height) + " images, the image is " +
              std::to_string(image->width) + "x" + std::to_string(image->height);
  if (!problem.empty())
    return problem;
  usable.stamp = image->header.stamp.toSec();
  usable.intrinsics = intrinsicsFromCameraInfo(*info);
  *entry = std::move(usable);
  return problem;
}

}  // namespace quadric_slam
