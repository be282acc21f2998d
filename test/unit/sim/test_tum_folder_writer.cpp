#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "quadric_slam/io/camera_info_yaml.h"
#include "quadric_slam/sim/tum_folder_writer.h"

using namespace quadric_slam;

TEST(TumFolderWriter, EncodesDepthAs5000UnitsPerMetre) {
  cv::Mat depth(1, 5, CV_32FC1);
  depth.at<float>(0, 0) = 1.0f;
  depth.at<float>(0, 1) = 2.34567f;
  depth.at<float>(0, 2) = std::numeric_limits<float>::quiet_NaN();
  depth.at<float>(0, 3) = 20.0f;  // beyond 16 bits: no data
  depth.at<float>(0, 4) = 0.0f;
  const cv::Mat png = TumFolderWriter::encodeDepth(depth);
  EXPECT_EQ(png.at<std::uint16_t>(0, 0), 5000);
  EXPECT_EQ(png.at<std::uint16_t>(0, 1), 11728);
  EXPECT_EQ(png.at<std::uint16_t>(0, 2), 0);
  EXPECT_EQ(png.at<std::uint16_t>(0, 3), 0);
  EXPECT_EQ(png.at<std::uint16_t>(0, 4), 0);
  EXPECT_EQ(TumFolderWriter::stampString(1305031449.7996), "1305031449.799600");
}

TEST(TumFolderWriter, WritesTheTumLayout) {
  const std::string dir = testing::TempDir() + "/tum_folder_writer_test";
  std::filesystem::remove_all(dir);
  TumFolderWriter::Params params;
  params.sequence_name = "unit";
  params.camera = CameraIntrinsics{525.0, 525.0, 319.5, 239.5, 640, 480};
  const TumFolderWriter writer(dir, params);
  RenderedFrame frame;
  frame.depth = cv::Mat(4, 6, CV_32FC1, cv::Scalar(1.5f));
  frame.depth.at<float>(1, 2) = std::numeric_limits<float>::quiet_NaN();
  frame.rgb = cv::Mat(4, 6, CV_8UC3, cv::Scalar(10, 20, 30));
  frame.labels = cv::Mat(4, 6, CV_16UC1, cv::Scalar(7));
  std::vector<StampedPose> poses(2);
  poses[0].stamp = 100.0;
  poses[1].stamp = 100.0 + 1.0 / 30;
  poses[1].T_world_sensor.translation() = Eigen::Vector3d(1, 2, 3);
  for (const StampedPose& p : poses)
    writer.writeFrame(p, frame);
  writer.finish(poses);

  const cv::Mat rgb = cv::imread(dir + "/rgb/100.033333.png", cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(rgb.empty());
  EXPECT_EQ(rgb.type(), CV_8UC3);
  EXPECT_EQ(rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));  // stored as RGB (read back BGR)
  const cv::Mat depth = cv::imread(dir + "/depth/100.000000.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16UC1);
  EXPECT_EQ(depth.at<std::uint16_t>(0, 0), 7500);
  EXPECT_EQ(depth.at<std::uint16_t>(1, 2), 0);
  // The camera travels with the images: the folder reader takes it from there.
  const CameraIntrinsics camera = readCameraInfoYaml(dir + "/camera_info.yaml");
  EXPECT_DOUBLE_EQ(camera.fx, 525.0);
  EXPECT_DOUBLE_EQ(camera.cy, 239.5);
  const cv::Mat labels = cv::imread(dir + "/labels/100.000000.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(labels.type(), CV_16UC1);
  EXPECT_EQ(labels.at<std::uint16_t>(3, 5), 7);

  std::ifstream rgb_txt(dir + "/rgb.txt");
  std::string line;
  std::getline(rgb_txt, line);
  EXPECT_EQ(line, "# color images");
  std::getline(rgb_txt, line);
  EXPECT_EQ(line, "# file: 'unit.bag'");
  std::getline(rgb_txt, line);
  EXPECT_EQ(line, "# timestamp filename");
  std::getline(rgb_txt, line);
  EXPECT_EQ(line, "100.000000 rgb/100.000000.png");
  const std::vector<StampedPose> gt = readTumTrajectory(dir + "/groundtruth.txt");
  ASSERT_EQ(gt.size(), 2u);
  EXPECT_NEAR(gt[1].stamp, 100.033333, 1e-6);
  EXPECT_NEAR((gt[1].T_world_sensor.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 0, 1e-9);
  std::filesystem::remove_all(dir);
}
