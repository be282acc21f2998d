// The depth correction file (io/depth_correction_yaml.h): written and read back unchanged; a
// malformed file is an error naming the file and the problem.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "quadric_slam/io/depth_correction_yaml.h"

namespace quadric_slam {
namespace {

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / name).string();
}

TEST(DepthCorrectionYaml, RoundTrip) {
  std::vector<double> offsets;
  for (int i = 0; i < 12; ++i)
    offsets.push_back(0.01 * i - 0.05);
  const DepthCorrection written(640, 480, 4, 3, offsets, 39.375);
  const std::string path = tempPath("qs_depth_correction_round_trip.yaml");
  writeDepthCorrectionYaml(path, written, "a test");
  const DepthCorrection read = readDepthCorrectionYaml(path);
  EXPECT_EQ(read.width(), 640);
  EXPECT_EQ(read.height(), 480);
  EXPECT_EQ(read.cols(), 4);
  EXPECT_EQ(read.rows(), 3);
  EXPECT_DOUBLE_EQ(read.focalBaseline(), 39.375);
  ASSERT_EQ(read.offsets().size(), offsets.size());
  for (std::size_t i = 0; i < offsets.size(); ++i)
    EXPECT_NEAR(read.offsets()[i], offsets[i], 1e-9);
  EXPECT_THROW(writeDepthCorrectionYaml(path, DepthCorrection()), std::runtime_error);
  std::filesystem::remove(path);
}

TEST(DepthCorrectionYaml, MalformedFilesNameTheProblem) {
  const std::string path = tempPath("qs_depth_correction_bad.yaml");
  auto expectError = [&](const std::string& text, const std::string& fragment) {
    std::ofstream(path) << text;
    try {
      readDepthCorrectionYaml(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find(fragment), std::string::npos) << what;
    }
  };
  const std::string head =
      "image_width: 640\nimage_height: 480\nfocal_baseline: 39.4\ngrid_cols: 3\ngrid_rows: 2\n";
  expectError("image_width: 640\n", "missing key");
  expectError(head + "offsets: [[0, 0, 0]]\n", "grid_rows");
  expectError(head + "offsets: [[0, 0, 0], [0, 0]]\n", "grid_cols");
  expectError(
      "image_width: 640\nimage_height: 480\nfocal_baseline: -1\ngrid_cols: 3\ngrid_rows: "
      "2\noffsets: [[0, 0, 0], [0, 0, 0]]\n",
      "focal_baseline");
  expectError("[unclosed", "cannot read");
  EXPECT_THROW(readDepthCorrectionYaml(tempPath("qs_no_such_depth_correction.yaml")),
               std::runtime_error);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace quadric_slam
