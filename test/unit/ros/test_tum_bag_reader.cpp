#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include "../fuzz_mutations.h"
#include "quadric_slam/ros/tum_bag_reader.h"

using quadric_slam::RgbdFrame;
using quadric_slam::TumBagReader;

namespace {

constexpr int kWidth = 8, kHeight = 6;
const float kNan = std::numeric_limits<float>::quiet_NaN();

// Depth of pixel (u, v) in frame k, metres (a whole number of millimetres); NaN at one pixel.
float depthAt(int k, int u, int v) {
  if (u == 2 && v == 3)
    return kNan;
  return static_cast<float>((500 + 100 * k + 10 * u + v) * 0.001);
}

sensor_msgs::Image depthImage(int k, double stamp, bool millimetres) {
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(stamp);
  image.header.frame_id = "openni_rgb_optical_frame";
  image.width = kWidth;
  image.height = kHeight;
  image.encoding = millimetres ? "16UC1" : "32FC1";
  image.step = millimetres ? kWidth * 2 + 4 : kWidth * 4;  // padded rows for 16UC1
  image.data.assign(static_cast<std::size_t>(image.step) * kHeight, 0);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      std::uint8_t* p = image.data.data() + v * image.step;
      const float z = depthAt(k, u, v);
      if (millimetres) {
        const std::uint16_t mm =
            std::isnan(z) ? 0 : static_cast<std::uint16_t>(std::lround(z * 1000));
        std::memcpy(p + 2 * u, &mm, 2);
      } else {
        std::memcpy(p + 4 * u, &z, 4);
      }
    }
  }
  return image;
}

sensor_msgs::Image rgbImage(int k, double stamp) {
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(stamp);
  image.header.frame_id = "openni_rgb_optical_frame";
  image.width = kWidth;
  image.height = kHeight;
  image.encoding = "rgb8";
  image.step = kWidth * 3;
  image.data.resize(image.step * kHeight);
  for (std::size_t i = 0; i < image.data.size(); ++i) {
    image.data[i] = static_cast<std::uint8_t>(i * 7 + k * 31);
  }
  return image;
}

sensor_msgs::CameraInfo cameraInfo() {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "openni_rgb_optical_frame";
  info.width = kWidth;
  info.height = kHeight;
  info.K = {525.0, 0, 3.5, 0, 524.0, 2.5, 0, 0, 1};
  return info;
}

// Five depth frames (0-2 as 32FC1 metres, 3-4 as 16UC1 millimetres) at 10 Hz; RGB 5 ms later for
// every frame except frame 2.
std::string writeBag(const std::string& name, bool with_camera_info) {
  const std::string path = ::testing::TempDir() + "/" + name;
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  const double t0 = 1305031102.0;
  if (with_camera_info) {
    sensor_msgs::CameraInfo info = cameraInfo();
    info.header.stamp = ros::Time(t0);
    bag.write("/camera/depth/camera_info", info.header.stamp, info);
  }
  for (int k = 0; k < 5; ++k) {
    const double stamp = t0 + 0.1 * k;
    bag.write("/camera/depth/image", ros::Time(stamp), depthImage(k, stamp, k >= 3));
    if (k != 2)
      bag.write("/camera/rgb/image_color", ros::Time(stamp + 0.005), rgbImage(k, stamp + 0.005));
  }
  bag.close();
  return path;
}

}  // namespace

TEST(TumBagReader, ReadsBackWhatWasWritten) {
  const std::string path = writeBag("tum_bag_reader_test.bag", true);
  TumBagReader reader(path);
  EXPECT_EQ(reader.size(), 4u);  // frame 2 has no RGB partner
  EXPECT_DOUBLE_EQ(reader.intrinsics().fx, 525.0);
  EXPECT_DOUBLE_EQ(reader.intrinsics().fy, 524.0);
  EXPECT_DOUBLE_EQ(reader.intrinsics().cx, 3.5);
  EXPECT_DOUBLE_EQ(reader.intrinsics().cy, 2.5);
  EXPECT_EQ(reader.intrinsics().width, kWidth);

  RgbdFrame frame;
  for (int k : {0, 1, 3, 4}) {
    ASSERT_TRUE(reader.next(frame)) << k;
    const double stamp = ros::Time(1305031102.0 + 0.1 * k).toSec();
    EXPECT_DOUBLE_EQ(frame.stamp, stamp);
    EXPECT_DOUBLE_EQ(frame.rgb_stamp, ros::Time(1305031102.0 + 0.1 * k + 0.005).toSec());
    EXPECT_EQ(frame.frame_id, "openni_rgb_optical_frame");
    EXPECT_DOUBLE_EQ(frame.intrinsics.fx, 525.0);
    EXPECT_EQ(frame.intrinsics.height, kHeight);
    ASSERT_EQ(frame.depth_m.type(), CV_32FC1);
    ASSERT_EQ(frame.depth_m.rows, kHeight);
    ASSERT_EQ(frame.depth_m.cols, kWidth);
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const float expected = depthAt(k, u, v), got = frame.depth_m.at<float>(v, u);
        if (std::isnan(expected)) {
          EXPECT_TRUE(std::isnan(got)) << k << " " << u << " " << v;
        } else {
          EXPECT_NEAR(got, expected, 1e-6) << k << " " << u << " " << v;
        }
      }
    }
    ASSERT_EQ(frame.rgb.type(), CV_8UC3);
    const sensor_msgs::Image rgb = rgbImage(k, 0);
    EXPECT_EQ(std::memcmp(frame.rgb.data, rgb.data.data(), rgb.data.size()), 0) << k;
  }
  EXPECT_FALSE(reader.next(frame));
  reader.rewind();
  ASSERT_TRUE(reader.next(frame));
  EXPECT_DOUBLE_EQ(frame.stamp, ros::Time(1305031102.0).toSec());

  TumBagReader::Params params;
  params.keep_frames_without_rgb = true;
  params.intrinsics.fx = params.intrinsics.fy = 100.0;
  params.intrinsics.cx = 4.0;
  params.intrinsics.cy = 3.0;
  TumBagReader all(path, params);
  EXPECT_EQ(all.size(), 5u);
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(all.next(frame));
  EXPECT_TRUE(frame.rgb.empty());  // frame 2
  EXPECT_DOUBLE_EQ(frame.intrinsics.fx, 100.0);
  EXPECT_EQ(frame.intrinsics.width, kWidth);
  std::remove(path.c_str());
}

TEST(TumBagReader, MissingCameraInfoOrBadEncodingIsAClearError) {
  const std::string path = writeBag("tum_bag_reader_no_info.bag", false);
  try {
    TumBagReader reader(path);
    FAIL() << "expected runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/camera/depth/camera_info"), std::string::npos)
        << e.what();
  }
  std::remove(path.c_str());

  const std::string bad = ::testing::TempDir() + "/tum_bag_reader_bad_encoding.bag";
  {
    rosbag::Bag bag(bad, rosbag::bagmode::Write);
    sensor_msgs::CameraInfo info = cameraInfo();
    info.header.stamp = ros::Time(10.0);
    bag.write("/camera/depth/camera_info", info.header.stamp, info);
    sensor_msgs::Image depth = depthImage(0, 10.0, true);
    depth.encoding = "mono8";
    bag.write("/camera/depth/image", ros::Time(10.0), depth);
  }
  TumBagReader reader(bad);  // no RGB in the bag: depth-only frames
  ASSERT_EQ(reader.size(), 1u);
  RgbdFrame frame;
  try {
    reader.next(frame);
    FAIL() << "expected runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("mono8"), std::string::npos) << e.what();
  }
  std::remove(bad.c_str());
  EXPECT_THROW(TumBagReader("/nonexistent/file.bag"), std::runtime_error);
}

// Seeded fuzzing of a TUM bag (issue 14): the bag file mutated a few bytes at a time (headers,
// chunk sizes, index records and message bytes alike). Opening it and reading every frame must
// either stop with std::runtime_error naming the bag, or give frames a pipeline can use. No other
// exception, no crash.
TEST(TumBagReader, FuzzedBagsAreRefusedOrGiveValidFrames) {
  const std::string path = writeBag("tum_bag_reader_fuzz_original.bag", true);
  std::string original;
  {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    original = bytes.str();
  }
  const std::string mutated_path = ::testing::TempDir() + "/tum_bag_reader_fuzz_case.bag";
  const int cases = quadric_slam::test::fuzzCases(300);
  int refused = 0, read_through = 0;
  quadric_slam::test::FuzzMutator mutator(11);
  for (int k = 0; k < cases; ++k) {
    std::ofstream(mutated_path, std::ios::binary | std::ios::trunc) << mutator.mutate(original);
    try {
      TumBagReader reader(mutated_path);
      RgbdFrame frame;
      while (reader.next(frame)) {
        ASSERT_EQ(frame.depth_m.type(), CV_32FC1) << "case " << k;
        EXPECT_EQ(frame.depth_m.cols, frame.intrinsics.width) << "case " << k;
        EXPECT_EQ(frame.depth_m.rows, frame.intrinsics.height) << "case " << k;
        EXPECT_TRUE(std::isfinite(frame.stamp)) << "case " << k;
        for (int v = 0; v < frame.depth_m.rows; ++v)
          for (int u = 0; u < frame.depth_m.cols; ++u) {
            const float z = frame.depth_m.at<float>(v, u);
            EXPECT_TRUE(std::isnan(z) || (std::isfinite(z) && z > 0))
                << "case " << k << ": depth " << z << " at " << u << ", " << v;
          }
      }
      ++read_through;
    } catch (const std::runtime_error& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find("tum_bag_reader_fuzz_case.bag"), std::string::npos)
          << "case " << k << ": " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << k << ": " << typeid(e).name() << ": " << e.what();
    }
  }
  std::printf("fuzzed TUM bags: %d cases, %d read through, %d refused with std::runtime_error\n",
              cases, read_through, refused);
  EXPECT_GT(refused, 0);
  EXPECT_GT(read_through, 0);
}
