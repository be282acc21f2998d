// The camera_info YAML of ROS's camera_calibration (io/camera_info_yaml.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "quadric_slam/io/camera_info_yaml.h"

namespace quadric_slam {
namespace {

std::string tempFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/camera_info_yaml_" + name + ".yaml";
  std::ofstream(path) << text;
  return path;
}

void expectRefused(const std::string& path, const std::string& reason) {
  try {
    readCameraInfoYaml(path);
    ADD_FAILURE() << path << " was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what;
  }
}

TEST(CameraInfoYaml, WrittenIntrinsicsReadBackExactly) {
  const CameraIntrinsics k{517.3, 516.5, 318.6, 255.3, 640, 480};
  const std::string path = ::testing::TempDir() + "/camera_info_yaml_round_trip.yaml";
  writeCameraInfoYaml(path, k, "fr1");
  const CameraIntrinsics back = readCameraInfoYaml(path);
  EXPECT_DOUBLE_EQ(back.fx, k.fx);
  EXPECT_DOUBLE_EQ(back.fy, k.fy);
  EXPECT_DOUBLE_EQ(back.cx, k.cx);
  EXPECT_DOUBLE_EQ(back.cy, k.cy);
  EXPECT_EQ(back.width, 640);
  EXPECT_EQ(back.height, 480);
}

// As camera_calibration writes it (block style, a camera name, rectification and projection).
TEST(CameraInfoYaml, ReadsTheFileRosCalibrationWrites) {
  const std::string path = tempFile("ros", R"(image_width: 640
image_height: 480
camera_name: rgb_PS1080_PrimeSense
camera_matrix:
  rows: 3
  cols: 3
  data: [525.0, 0.0, 319.5, 0.0, 524.0, 239.5, 0.0, 0.0, 1.0]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.0, 0.0, 0.0, 0.0, 0.0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
projection_matrix:
  rows: 3
  cols: 4
  data: [525.0, 0.0, 319.5, 0.0, 0.0, 524.0, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0]
)");
  const CameraIntrinsics k = readCameraInfoYaml(path);
  EXPECT_DOUBLE_EQ(k.fy, 524.0);
  EXPECT_DOUBLE_EQ(k.cy, 239.5);
}

TEST(CameraInfoYaml, BadFilesAreRefusedNamingTheProblem) {
  expectRefused(::testing::TempDir() + "/camera_info_yaml_missing.yaml", "cannot read");
  expectRefused(tempFile("no_size", "camera_matrix: {data: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n"),
                "image_width");
  expectRefused(tempFile("short",
                         "image_width: 640\nimage_height: 480\n"
                         "camera_matrix: {data: [525, 0, 319.5]}\n"),
                "camera_matrix.data");
  expectRefused(tempFile("text",
                         "image_width: 640\nimage_height: 480\n"
                         "camera_matrix: {data: [a, 0, 0, 0, 1, 0, 0, 0, 1]}\n"),
                "malformed");
  expectRefused(tempFile("zero_focal",
                         "image_width: 640\nimage_height: 480\n"
                         "camera_matrix: {data: [0, 0, 319.5, 0, 0, 239.5, 0, 0, "
                         "1]}\n"),
                "focal");
  expectRefused(tempFile("distorted",
                         "image_width: 640\nimage_height: 480\n"
                         "camera_matrix: {data: [525, 0, 319.5, 0, 525, 239.5, 0, 0, "
                         "1]}\ndistortion_coefficients: {data: [0.1, 0, 0, 0, 0]}\n"),
                "distortion");
}

}  // namespace
}  // namespace quadric_slam
