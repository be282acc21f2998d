#include "quadric_slam/ros/tum_bag_reader.h"

#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "quadric_slam/io/stamp_association.h"
#include "quadric_slam/ros/frame_ids.h"

namespace quadric_slam {
namespace {

// The header stamp of a stamped message, read from its serialised bytes (a Header comes first:
// uint32 seq, uint32 sec, uint32 nsec), so indexing does not decode whole images.
double headerStamp(const rosbag::MessageInstance& message) {
  std::vector<std::uint8_t> buffer(message.size());
  ros::serialization::OStream stream(buffer.data(), static_cast<std::uint32_t>(buffer.size()));
  message.write(stream);
  if (buffer.size() < 12) {
    throw std::runtime_error("message on " + message.getTopic() + " is too short for a header");
  }
  std::uint32_t sec = 0, nsec = 0;
  std::memcpy(&sec, buffer.data() + 4, 4);
  std::memcpy(&nsec, buffer.data() + 8, 4);
  return ros::Time(sec, nsec).toSec();
}

std::string where(const sensor_msgs::Image& image, const std::string& topic) {
  return topic + " at " + std::to_string(image.header.stamp.toSec()) + " s";
}

void checkLayout(const sensor_msgs::Image& image, const std::string& topic,
                 std::size_t bytes_per_pixel) {
  if (image.is_bigendian) {
    throw std::runtime_error(where(image, topic) + ": big-endian images are not supported");
  }
  if (image.step < image.width * bytes_per_pixel ||
      image.data.size() < static_cast<std::size_t>(image.step) * image.height) {
    throw std::runtime_error(where(image, topic) + ": step or data size does not fit " +
                             std::to_string(image.width) + " x " + std::to_string(image.height) +
                             " " + image.encoding);
  }
}

// 32FC1 metres or 16UC1 millimetres -> CV_32FC1 metres, NaN where there is no data.
cv::Mat depthToMetres(const sensor_msgs::Image& image, const std::string& topic) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int rows = static_cast<int>(image.height), cols = static_cast<int>(image.width);
  cv::Mat depth(rows, cols, CV_32FC1);
  if (image.encoding == "32FC1") {
    checkLayout(image, topic, 4);
    for (int v = 0; v < rows; ++v) {
      const std::uint8_t* row = image.data.data() + static_cast<std::size_t>(v) * image.step;
      float* out = depth.ptr<float>(v);
      std::memcpy(out, row, static_cast<std::size_t>(cols) * 4);
      for (int u = 0; u < cols; ++u) {
        if (!(out[u] > 0.0f) || !std::isfinite(out[u]))
          out[u] = nan;
      }
    }
  } else if (image.encoding == "16UC1" || image.encoding == "mono16") {
    checkLayout(image, topic, 2);
    for (int v = 0; v < rows; ++v) {
      const std::uint8_t* row = image.data.data() + static_cast<std::size_t>(v) * image.step;
      float* out = depth.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        std::uint16_t mm = 0;
        std::memcpy(&mm, row + 2 * u, 2);
        out[u] = mm == 0 ? nan : static_cast<float>(mm * 0.001);
      }
    }
  } else {
    throw std::runtime_error(where(image, topic) + ": unsupported depth encoding '" +
                             image.encoding + "' (need 32FC1 metres or 16UC1 millimetres)");
  }
  return depth;
}

// rgb8 or bgr8 -> CV_8UC3 in RGB order.
cv::Mat colourToRgb(const sensor_msgs::Image& image, const std::string& topic) {
  if (image.encoding != "rgb8" && image.encoding != "bgr8") {
    throw std::runtime_error(where(image, topic) + ": unsupported colour encoding '" +
                             image.encoding + "' (need rgb8 or bgr8)");
  }
  checkLayout(image, topic, 3);
  const cv::Mat view(static_cast<int>(image.height), static_cast<int>(image.width), CV_8UC3,
                     const_cast<std::uint8_t*>(image.data.data()), image.step);
  cv::Mat rgb;
  if (image.encoding == "rgb8") {
    rgb = view.clone();
  } else {
    cv::cvtColor(view, rgb, cv::COLOR_BGR2RGB);
  }
  return rgb;
}

// rosbag and roscpp's deserialisation throw without the file's name (ros::Exception "Buffer
// Overrun", "Error parsing header", std::bad_alloc for a corrupted length): every error of the
// reader becomes a std::runtime_error that names the bag. Call from a catch block.
[[noreturn]] void rethrowNamingTheBag(const std::string& bag_path) {
  try {
    throw;
  } catch (const std::exception& e) {
    const std::string what = e.what();
    if (what.rfind(bag_path, 0) == 0)
      throw std::runtime_error(what);
    throw std::runtime_error(bag_path + ": " + what);
  }
}

}  // namespace

struct TumBagReader::Impl {
  struct Entry {
    double depth_stamp;
    std::size_t depth_index;
    long rgb_index;  // -1: none
  };

  Params params;
  std::string path;
  rosbag::Bag bag;
  std::vector<rosbag::MessageInstance> depth_messages, rgb_messages;
  std::vector<double> rgb_stamps;
  std::vector<Entry> entries;
  std::size_t position = 0;
  CameraIntrinsics intrinsics;
};

void TumBagReader::Params::validate() const {
  if (depth_topic.empty())
    throw std::invalid_argument("depth_topic must not be empty");
  validateReaderParams(max_rgb_difference, intrinsics);
  if (intrinsics.fx == 0.0 && camera_info_topic.empty()) {
    throw std::invalid_argument(
        "camera_info_topic must not be empty without an intrinsics override");
  }
}

TumBagReader::TumBagReader(const std::string& bag_path, const Params& params)
    : impl_(std::make_unique<Impl>()) {
  params.validate();
  try {
    open(bag_path, params);
  } catch (...) {
    rethrowNamingTheBag(bag_path);
  }
}

void TumBagReader::open(const std::string& bag_path, const Params& params) {
  Impl& d = *impl_;
  d.params = params;
  d.path = bag_path;
  try {
    d.bag.open(bag_path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(bag_path + ": cannot open bag: " + e.what());
  }

  if (params.intrinsics.fx != 0.0) {
    d.intrinsics = params.intrinsics;
  } else {
    rosbag::View info_view(d.bag, rosbag::TopicQuery(params.camera_info_topic));
    for (const rosbag::MessageInstance& m : info_view) {
      const auto info = m.instantiate<sensor_msgs::CameraInfo>();
      if (!info)
        continue;
      d.intrinsics.fx = info->K[0];
      d.intrinsics.fy = info->K[4];
      d.intrinsics.cx = info->K[2];
      d.intrinsics.cy = info->K[5];
      d.intrinsics.width = static_cast<int>(info->width);
      d.intrinsics.height = static_cast<int>(info->height);
      break;
    }
    if (d.intrinsics.fx == 0.0) {
      throw std::runtime_error(bag_path + ": no sensor_msgs/CameraInfo on " +
                               params.camera_info_topic + " (give intrinsics explicitly)");
    }
    const std::string problem = d.intrinsics.problem();
    if (!problem.empty()) {
      throw std::runtime_error(bag_path + ": camera_info on " + params.camera_info_topic + ": " +
                               problem);
    }
  }

  std::vector<double> depth_stamps;
  rosbag::View depth_view(d.bag, rosbag::TopicQuery(params.depth_topic));
  for (const rosbag::MessageInstance& m : depth_view) {
    if (m.getDataType() != "sensor_msgs/Image")
      continue;
    d.depth_messages.push_back(m);
    depth_stamps.push_back(headerStamp(m));
  }
  if (d.depth_messages.empty()) {
    throw std::runtime_error(bag_path + ": no sensor_msgs/Image on " + params.depth_topic);
  }
  if (!params.rgb_topic.empty()) {
    rosbag::View rgb_view(d.bag, rosbag::TopicQuery(params.rgb_topic));
    for (const rosbag::MessageInstance& m : rgb_view) {
      if (m.getDataType() != "sensor_msgs/Image")
        continue;
      d.rgb_messages.push_back(m);
      d.rgb_stamps.push_back(headerStamp(m));
    }
  }

  std::vector<long> rgb_of_depth(depth_stamps.size(), -1);
  if (!d.rgb_messages.empty()) {
    StampAssociationParams association;
    association.max_difference = params.max_rgb_difference;
    for (const auto& match : associateStamps(depth_stamps, d.rgb_stamps, association)) {
      rgb_of_depth[match.first] = static_cast<long>(match.second);
    }
  }
  for (std::size_t i = 0; i < depth_stamps.size(); ++i) {
    if (rgb_of_depth[i] < 0 && !d.rgb_messages.empty() && !params.keep_frames_without_rgb) {
      continue;
    }
    d.entries.push_back({depth_stamps[i], i, rgb_of_depth[i]});
  }
  std::stable_sort(
      d.entries.begin(), d.entries.end(),
      [](const Impl::Entry& a, const Impl::Entry& b) { return a.depth_stamp < b.depth_stamp; });
}

TumBagReader::~TumBagReader() = default;

std::size_t TumBagReader::size() const {
  return impl_->entries.size();
}

void TumBagReader::rewind() {
  impl_->position = 0;
}

const CameraIntrinsics& TumBagReader::intrinsics() const {
  return impl_->intrinsics;
}

bool TumBagReader::next(RgbdFrame& frame) {
  try {
    return readNext(frame);
  } catch (...) {
    rethrowNamingTheBag(impl_->path);
  }
}

bool TumBagReader::readNext(RgbdFrame& frame) {
  Impl& d = *impl_;
  if (d.position >= d.entries.size())
    return false;
  const Impl::Entry& entry = d.entries[d.position++];
  const auto depth = d.depth_messages[entry.depth_index].instantiate<sensor_msgs::Image>();
  if (!depth)
    throw std::runtime_error(d.params.depth_topic + ": cannot decode sensor_msgs/Image");
  frame.stamp = depth->header.stamp.toSec();
  frame.frame_id = withoutLeadingSlash(depth->header.frame_id);  // TUM's "/openni_..."
  frame.depth_m = depthToMetres(*depth, d.params.depth_topic);
  frame.intrinsics = d.intrinsics;
  if (frame.intrinsics.width == 0 && frame.intrinsics.height == 0) {
    frame.intrinsics.width = frame.depth_m.cols;
    frame.intrinsics.height = frame.depth_m.rows;
  }
  const std::string size_problem =
      imageSizeProblem(frame.intrinsics, frame.depth_m.cols, frame.depth_m.rows);
  if (!size_problem.empty())
    throw std::runtime_error(where(*depth, d.params.depth_topic) + ": " + size_problem);

  frame.rgb.release();
  frame.rgb_stamp = 0.0;
  if (entry.rgb_index >= 0) {
    const auto colour =
        d.rgb_messages[static_cast<std::size_t>(entry.rgb_index)].instantiate<sensor_msgs::Image>();
    if (!colour)
      throw std::runtime_error(d.params.rgb_topic + ": cannot decode sensor_msgs/Image");
    frame.rgb = colourToRgb(*colour, d.params.rgb_topic);
    frame.rgb_stamp = colour->header.stamp.toSec();
    if (frame.rgb.size() != frame.depth_m.size()) {
      throw std::runtime_error(where(*colour, d.params.rgb_topic) +
                               ": colour image size differs from the depth image");
    }
  }
  return true;
}

}  // namespace quadric_slam
