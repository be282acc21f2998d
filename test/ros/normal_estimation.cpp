// Checker for normal_estimation.test: publishes depth images of a known plane and bad input to the
// nodelet, and checks the organized cloud it publishes.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <vector>

namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kFx = 525.0, kFy = 525.0, kCx = 319.5, kCy = 239.5;
// The plane n.p = offset in the camera frame, facing the camera.
const Eigen::Vector3d kNormal = Eigen::Vector3d(-0.2, 0.35, -1.0).normalized();
constexpr double kOffset = -1.8;

double planeDepth(int u, int v) {
  const Eigen::Vector3d ray((u - kCx) / kFx, (v - kCy) / kFy, 1.0);
  return kOffset / kNormal.dot(ray);
}

sensor_msgs::CameraInfo cameraInfo(int width, int height) {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "test_optical_frame";
  info.width = width;
  info.height = height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {kFx, 0, kCx, 0, kFy, kCy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {kFx, 0, kCx, 0, 0, kFy, kCy, 0, 0, 0, 1, 0};
  return info;
}

sensor_msgs::Image planeImage(const std::string& encoding, int width, int height, double stamp) {
  namespace enc = sensor_msgs::image_encodings;
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(stamp);
  image.header.frame_id = "test_optical_frame";
  image.width = width;
  image.height = height;
  image.encoding = encoding;
  const int bytes = encoding == enc::TYPE_32FC1 ? 4 : 2;
  image.step = width * bytes;
  image.data.resize(image.step * height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      std::uint8_t* pixel = &image.data[v * image.step + u * bytes];
      const double z = planeDepth(u, v);
      if (bytes == 4) {
        const float metres = static_cast<float>(z);
        std::memcpy(pixel, &metres, 4);
      } else {
        const std::uint16_t millimetres = static_cast<std::uint16_t>(std::lround(z * 1000.0));
        std::memcpy(pixel, &millimetres, 2);
      }
    }
  }
  return image;
}

class NormalEstimationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::NodeHandle nh("test_camera");
    image_pub_ = nh.advertise<sensor_msgs::Image>("depth/image", 5);
    info_pub_ = nh.advertise<sensor_msgs::CameraInfo>("depth/camera_info", 5, true);
    cloud_sub_ = nh.subscribe("points_normals", 5, &NormalEstimationTest::onCloud, this);
    diagnostics_sub_ = nh.subscribe("/diagnostics", 50, &NormalEstimationTest::onDiagnostics, this);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    while ((image_pub_.getNumSubscribers() == 0 || info_pub_.getNumSubscribers() == 0 ||
            cloud_sub_.getNumPublishers() == 0) &&
           ros::WallTime::now() < deadline) {
      ros::WallDuration(0.05).sleep();
      ros::spinOnce();
    }
    ASSERT_GT(image_pub_.getNumSubscribers(), 0u) << "nodelet did not subscribe";
  }

  void onCloud(const sensor_msgs::PointCloud2ConstPtr& cloud) { clouds_.push_back(cloud); }

  void onDiagnostics(const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
    for (const auto& status : array->status) {
      if (status.name != "quadric_slam: normal_estimation")
        continue;
      for (const auto& kv : status.values) {
        if (kv.key == "frames dropped")
          frames_dropped_ = std::stoul(kv.value);
        if (kv.key == "frames processed")
          frames_processed_ = std::stoul(kv.value);
      }
    }
  }

  // Publishes the image and waits for the cloud stamped like it; null when none comes in time.
  sensor_msgs::PointCloud2ConstPtr publishAndWait(const sensor_msgs::Image& image,
                                                  double timeout_s) {
    image_pub_.publish(image);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::WallTime::now() < deadline) {
      ros::spinOnce();
      for (const auto& cloud : clouds_) {
        if (cloud->header.stamp == image.header.stamp)
          return cloud;
      }
      ros::WallDuration(0.01).sleep();
    }
    return nullptr;
  }

  void checkPlaneCloud(const sensor_msgs::PointCloud2& msg, double point_tolerance,
                       double median_angle_tolerance_deg) {
    std::set<std::string> fields;
    for (const auto& field : msg.fields)
      fields.insert(field.name);
    for (const char* name : {"x", "y", "z", "normal_x", "normal_y", "normal_z"}) {
      EXPECT_TRUE(fields.count(name)) << "missing field " << name;
    }
    EXPECT_EQ(msg.width, static_cast<unsigned>(kWidth));
    EXPECT_EQ(msg.height, static_cast<unsigned>(kHeight));
    EXPECT_EQ(msg.header.frame_id, "test_optical_frame");
    pcl::PointCloud<pcl::PointNormal> cloud;
    pcl::fromROSMsg(msg, cloud);
    std::vector<double> angles;
    int valid_points = 0;
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const pcl::PointNormal& p = cloud(u, v);
        ASSERT_TRUE(std::isfinite(p.z));
        ++valid_points;
        // The point is the back-projection of pixel (u, v) and lies on the plane.
        EXPECT_NEAR(p.z, planeDepth(u, v), point_tolerance);
        EXPECT_NEAR(p.x, (u - kCx) * p.z / kFx, 1e-4);
        EXPECT_NEAR(p.y, (v - kCy) * p.z / kFy, 1e-4);
        if (!std::isfinite(p.normal_x))
          continue;
        const Eigen::Vector3d n(p.normal_x, p.normal_y, p.normal_z);
        angles.push_back(std::acos(std::clamp(n.dot(kNormal), -1.0, 1.0)) * 180.0 / M_PI);
      }
    }
    EXPECT_EQ(valid_points, kWidth * kHeight);
    ASSERT_GT(angles.size(), 0.9 * kWidth * kHeight);
    std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
    EXPECT_LT(angles[angles.size() / 2], median_angle_tolerance_deg);
  }

  ros::Publisher image_pub_, info_pub_;
  ros::Subscriber cloud_sub_, diagnostics_sub_;
  std::vector<sensor_msgs::PointCloud2ConstPtr> clouds_;
  unsigned long frames_dropped_ = 0, frames_processed_ = 0;
};

TEST_F(NormalEstimationTest, PlaneInBothEncodingsAndBadInput) {
  namespace enc = sensor_msgs::image_encodings;
  // 1. No camera_info yet: the frame is dropped.
  EXPECT_EQ(publishAndWait(planeImage(enc::TYPE_32FC1, kWidth, kHeight, 1.0), 1.5), nullptr);

  info_pub_.publish(cameraInfo(kWidth, kHeight));
  ros::WallDuration(0.5).sleep();

  // 2. 32FC1 metres: points exact, normals on the analytic plane.
  auto cloud = publishAndWait(planeImage(enc::TYPE_32FC1, kWidth, kHeight, 2.0), 20.0);
  ASSERT_NE(cloud, nullptr) << "no cloud for a valid 32FC1 frame";
  {
    SCOPED_TRACE("32FC1");
    checkPlaneCloud(*cloud, 1e-5, 0.05);
  }

  // 3. 16UC1 millimetres: points within the 1 mm quantisation.
  cloud = publishAndWait(planeImage(enc::TYPE_16UC1, kWidth, kHeight, 3.0), 20.0);
  ASSERT_NE(cloud, nullptr) << "no cloud for a valid 16UC1 frame";
  {
    SCOPED_TRACE("16UC1");
    checkPlaneCloud(*cloud, 0.6e-3, 0.5);
  }

  // 4. Bad input is dropped: an unsupported encoding, a size that does not match camera_info, a
  //    truncated buffer.
  EXPECT_EQ(publishAndWait(planeImage(enc::RGB8, kWidth, kHeight, 4.0), 1.5), nullptr);
  EXPECT_EQ(publishAndWait(planeImage(enc::TYPE_32FC1, 320, 240, 5.0), 1.5), nullptr);
  sensor_msgs::Image truncated = planeImage(enc::TYPE_32FC1, kWidth, kHeight, 6.0);
  truncated.data.resize(truncated.data.size() / 2);
  EXPECT_EQ(publishAndWait(truncated, 1.5), nullptr);

  // 5. The nodelet is still alive and well after bad input.
  cloud = publishAndWait(planeImage(enc::TYPE_32FC1, kWidth, kHeight, 7.0), 20.0);
  ASSERT_NE(cloud, nullptr) << "no cloud after bad input";

  // 6. /diagnostics counts what happened: 4 frames dropped, 3 processed.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(5.0);
  while (frames_processed_ < 3 && ros::WallTime::now() < deadline) {
    ros::WallDuration(0.05).sleep();
    ros::spinOnce();
  }
  EXPECT_EQ(frames_dropped_, 4u);
  EXPECT_EQ(frames_processed_, 3u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "normal_estimation_checker");
  return RUN_ALL_TESTS();
}
