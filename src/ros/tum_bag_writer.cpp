#include "quadric_slam/ros/tum_bag_writer.h"

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>

#include <cstring>
#include <stdexcept>

#include "quadric_slam/sim/kinect_frames.h"

namespace quadric_slam {
namespace {

geometry_msgs::TransformStamped toMsg(const std::string& parent, const std::string& child,
                                      const Eigen::Isometry3d& T, const ros::Time& stamp) {
  geometry_msgs::TransformStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = parent;
  msg.child_frame_id = child;
  const Eigen::Quaterniond q(T.rotation());
  msg.transform.translation.x = T.translation().x();
  msg.transform.translation.y = T.translation().y();
  msg.transform.translation.z = T.translation().z();
  msg.transform.rotation.x = q.x();
  msg.transform.rotation.y = q.y();
  msg.transform.rotation.z = q.z();
  msg.transform.rotation.w = q.w();
  return msg;
}

sensor_msgs::Image toImage(const cv::Mat& image, const std::string& encoding,
                           const std_msgs::Header& header) {
  sensor_msgs::Image msg;
  msg.header = header;
  msg.height = image.rows;
  msg.width = image.cols;
  msg.encoding = encoding;
  msg.is_bigendian = 0;
  const std::size_t row_bytes = image.cols * image.elemSize();
  msg.step = static_cast<std::uint32_t>(row_bytes);
  msg.data.resize(row_bytes * image.rows);
  for (int v = 0; v < image.rows; ++v)
    std::memcpy(&msg.data[v * row_bytes], image.ptr(v), row_bytes);
  return msg;
}

}  // namespace

void TumBagWriter::Params::validate() const {
  if (compression != "none" && compression != "lz4" && compression != "bz2")
    throw std::invalid_argument("TumBagWriter::Params::compression must be none, lz4 or bz2");
}

TumBagWriter::TumBagWriter(const std::string& path, const CameraIntrinsics& camera,
                           const Params& params)
    : camera_(camera) {
  params.validate();
  try {
    bag_.open(path, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error("cannot open bag " + path + ": " + e.what());
  }
  if (params.compression == "lz4")
    bag_.setCompression(rosbag::compression::LZ4);
  else if (params.compression == "bz2")
    bag_.setCompression(rosbag::compression::BZ2);
}

TumBagWriter::~TumBagWriter() {
  try {
    close();
  } catch (...) {
  }
}

void TumBagWriter::close() {
  if (bag_.isOpen())
    bag_.close();
}

sensor_msgs::CameraInfo TumBagWriter::cameraInfo(const CameraIntrinsics& c) {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = kTumRgbOpticalFrame;
  info.width = c.width;
  info.height = c.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {c.fx, 0.0, c.cx, 0.0, 0.0, c.fy, c.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

void TumBagWriter::write(const StampedPose& pose, const RenderedFrame& frame) {
  if (!bag_.isOpen())
    throw std::runtime_error("TumBagWriter::write after close()");
  const ros::Time stamp(pose.stamp);
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(
      toMsg(kTumWorldFrame, kTumKinectFrame, worldToKinect(pose.T_world_sensor), stamp));
  for (const FixedTransform& fixed : kinectFrameChain())
    tf.transforms.push_back(toMsg(fixed.parent, fixed.child, fixed.T_parent_child, stamp));
  bag_.write("/tf", stamp, tf);

  std_msgs::Header header;
  header.seq = seq_++;
  header.stamp = stamp;
  header.frame_id = kTumRgbOpticalFrame;
  sensor_msgs::CameraInfo info = cameraInfo(camera_);
  info.header = header;
  bag_.write("/camera/rgb/camera_info", stamp, info);
  bag_.write("/camera/rgb/image_color", stamp,
             toImage(frame.rgb, sensor_msgs::image_encodings::RGB8, header));
  bag_.write("/camera/depth/camera_info", stamp, info);
  bag_.write("/camera/depth/image", stamp,
             toImage(frame.depth, sensor_msgs::image_encodings::TYPE_32FC1, header));
}

}  // namespace quadric_slam
