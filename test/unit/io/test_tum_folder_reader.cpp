#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include "../fuzz_mutations.h"
#include "../test_data.h"
#include "quadric_slam/io/camera_info_yaml.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/tum_folder_reader.h"

namespace fs = std::filesystem;
using quadric_slam::RgbdFrame;
using quadric_slam::TumFolderReader;

namespace {

const std::string kFrames = quadric_slam::test::shippedData("tum_frames/").string();

struct DepthStats {
  double median = NAN;
  double valid_fraction = 0;
};

DepthStats stats(const cv::Mat& depth, int row_begin = 0, int row_end = -1) {
  if (row_end < 0)
    row_end = depth.rows;
  std::vector<float> valid;
  for (int v = row_begin; v < row_end; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      if (std::isfinite(depth.at<float>(v, u)))
        valid.push_back(depth.at<float>(v, u));
    }
  }
  DepthStats s;
  s.valid_fraction = static_cast<double>(valid.size()) / ((row_end - row_begin) * depth.cols);
  if (!valid.empty()) {
    std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
    s.median = valid[valid.size() / 2];
  }
  return s;
}

// Equal pixel by pixel, NaN matching NaN.
bool sameDepth(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != CV_32FC1 || b.type() != CV_32FC1)
    return false;
  for (int v = 0; v < a.rows; ++v) {
    for (int u = 0; u < a.cols; ++u) {
      const float x = a.at<float>(v, u), y = b.at<float>(v, u);
      if (!(x == y || (std::isnan(x) && std::isnan(y))))
        return false;
    }
  }
  return true;
}

// A TUM folder named like the official sequence, made from the two fr1_xyz depth frames with RGB
// partners at the sequence's RGB stamps, plus one depth image (a copy) 5 s later with no RGB
// partner.
std::string makeFr1Folder() {
  const fs::path root =
      fs::path(::testing::TempDir()) / "tum_folder_reader_test" / "rgbd_dataset_freiburg1_xyz";
  fs::remove_all(root);
  fs::create_directories(root / "depth");
  fs::create_directories(root / "rgb");
  const fs::path src = kFrames + "fr1_xyz";
  fs::copy_file(src / "1305031102.160407.png", root / "depth" / "1305031102.160407.png");
  fs::copy_file(src / "1305031102.262886.png", root / "depth" / "1305031102.262886.png");
  fs::copy_file(src / "1305031102.262886.png", root / "depth" / "1305031107.262886.png");
  fs::copy_file(src / "1305031102.175304.png", root / "rgb" / "1305031102.175304.png");
  fs::copy_file(src / "1305031102.275326.png", root / "rgb" / "1305031102.275326.png");
  std::ofstream(root / "depth.txt") << "# depth maps\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n"
                                       "# timestamp filename\n"
                                       "1305031102.160407 depth/1305031102.160407.png\n"
                                       "1305031107.262886 depth/1305031107.262886.png\n"
                                       "1305031102.262886 depth/1305031102.262886.png\n";
  std::ofstream(root / "rgb.txt") << "# color images\n"
                                     "1305031102.175304 rgb/1305031102.175304.png\n"
                                     "1305031102.275326 rgb/1305031102.275326.png\n";
  std::ofstream(root / "groundtruth.txt") << "# ground truth trajectory\n"
                                             "1305031102.1758 1.3405 0.6266 1.6575 0.6574 0.6126 "
                                             "-0.2949 -0.3248\n";
  return root.string();
}

}  // namespace

TEST(TumFolderReader, IntrinsicsBySequenceName) {
  EXPECT_DOUBLE_EQ(quadric_slam::tumIntrinsicsForSequence("rgbd_dataset_freiburg1_xyz").fx, 517.3);
  EXPECT_DOUBLE_EQ(quadric_slam::tumIntrinsicsForSequence("fr2_desk").cy, 249.7);
  EXPECT_DOUBLE_EQ(
      quadric_slam::tumIntrinsicsForSequence("rgbd_dataset_Freiburg3_long_office_household").fy,
      539.2);
  const auto fallback = quadric_slam::tumIntrinsicsForSequence("my_sequence");
  EXPECT_DOUBLE_EQ(fallback.fx, 525.0);
  EXPECT_DOUBLE_EQ(fallback.cx, 319.5);
  EXPECT_EQ(fallback.width, 640);
  EXPECT_EQ(fallback.height, 480);
}

// A folder that carries its camera (camera_info.yaml, as the generator writes it) is read with
// that camera, whatever its name says: a sequence rendered with 525/525/319.5/239.5 into a folder
// named fr1_* was read with the Freiburg 1 intrinsics (cy 16 pixels off), which bent the
// generated benchmarks' trajectories by 1-2 % and cost centimetres of ATE.
TEST(TumFolderReader, TheFoldersCameraInfoComesBeforeItsName) {
  const std::string folder = makeFr1Folder();
  EXPECT_DOUBLE_EQ(TumFolderReader(folder).intrinsics().fx, 517.3);  // by the name
  quadric_slam::CameraIntrinsics rendered{525.0, 525.0, 319.5, 239.5, 640, 480};
  quadric_slam::writeCameraInfoYaml(folder + "/camera_info.yaml", rendered, "synthetic");
  TumFolderReader reader(folder);
  EXPECT_DOUBLE_EQ(reader.intrinsics().fx, 525.0);
  EXPECT_DOUBLE_EQ(reader.intrinsics().cy, 239.5);
  RgbdFrame frame;
  ASSERT_TRUE(reader.next(frame));
  EXPECT_DOUBLE_EQ(frame.intrinsics.cy, 239.5);
  // An explicit camera still comes first.
  TumFolderReader::Params params;
  params.intrinsics = quadric_slam::tumIntrinsicsForSequence("fr3");
  EXPECT_DOUBLE_EQ(TumFolderReader(folder, params).intrinsics().fx, 535.4);
  // A camera_info.yaml that cannot be read is an error naming it, not a silent fallback.
  std::ofstream(folder + "/camera_info.yaml") << "image_width: 640\nimage_height: 480\n";
  try {
    TumFolderReader broken(folder);
    ADD_FAILURE() << "a camera_info.yaml without camera_matrix was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("camera_info.yaml"), std::string::npos) << e.what();
  }
}

TEST(TumFolderReader, DepthPngReadsMetresWithNanForNoData) {
  const std::string path = kFrames + "fr3_long_office_household/1341847980.723020.png";
  const cv::Mat raw = cv::imread(path, cv::IMREAD_ANYDEPTH);
  ASSERT_EQ(raw.type(), CV_16UC1);
  const cv::Mat depth = quadric_slam::readTumDepthPng(path);
  ASSERT_EQ(depth.type(), CV_32FC1);
  ASSERT_EQ(depth.size(), raw.size());
  int zeros = 0;
  for (int v = 0; v < raw.rows; ++v) {
    for (int u = 0; u < raw.cols; ++u) {
      const std::uint16_t r = raw.at<std::uint16_t>(v, u);
      if (r == 0) {
        ++zeros;
        EXPECT_TRUE(std::isnan(depth.at<float>(v, u)));
      } else {
        EXPECT_FLOAT_EQ(depth.at<float>(v, u), static_cast<float>(r / 5000.0));
      }
    }
  }
  EXPECT_GT(zeros, 0);  // a real Kinect frame has holes
  // The paper's Fig. 3 frame: mostly valid, median in room range; the README's floor strip (rows
  // 430-475) at about 2.1 m and back wall (rows 5-60) at about 2.5 m.
  const DepthStats all = stats(depth);
  EXPECT_GT(all.valid_fraction, 0.5);
  EXPECT_GT(all.median, 0.5);
  EXPECT_LT(all.median, 5.0);
  EXPECT_NEAR(stats(depth, 430, 476).median, 2.1, 0.3);
  EXPECT_NEAR(stats(depth, 5, 61).median, 2.5, 0.4);
  // fr2 scale: 5208 units per metre shrinks every depth by 5000/5208.
  const cv::Mat fr2 = quadric_slam::readTumDepthPng(path, 5208.0);
  EXPECT_FLOAT_EQ(stats(fr2).median, static_cast<float>(all.median * 5000.0 / 5208.0));

  EXPECT_THROW(quadric_slam::readTumDepthPng(kFrames + "fr1_xyz/1305031102.175304.png"),
               std::runtime_error);  // an RGB image
  EXPECT_THROW(quadric_slam::readTumDepthPng("/nonexistent.png"), std::runtime_error);
  EXPECT_THROW(quadric_slam::depthUnitsToMetres(raw, 0.0), std::invalid_argument);
}

TEST(TumFolderReader, EveryRealDepthFrameIsPlausible) {
  const char* const files[] = {"fr1_xyz/1305031102.160407.png",
                               "fr1_xyz/1305031102.262886.png",
                               "fr2_desk/a_depth.png",
                               "fr2_desk/b_depth.png",
                               "fr3_long_office_household/1341847980.723020.png",
                               "fr3_long_office_household/1341847982.998830.png"};
  for (const char* file : files) {
    const cv::Mat depth = quadric_slam::readTumDepthPng(kFrames + file);
    EXPECT_EQ(depth.cols, 640) << file;
    EXPECT_EQ(depth.rows, 480) << file;
    const DepthStats s = stats(depth);
    EXPECT_GT(s.valid_fraction, 0.5) << file;
    EXPECT_GT(s.median, 0.5) << file;
    EXPECT_LT(s.median, 5.0) << file;
    double min_value, max_value;
    cv::minMaxIdx(depth, &min_value, &max_value, nullptr, nullptr, depth == depth);  // not NaN
    EXPECT_GT(min_value, 0.0) << file;
    EXPECT_LT(max_value, 13.2) << file;  // 65535 / 5000 m
  }
}

TEST(TumFolderReader, ReadsAFolderBuiltFromRealFrames) {
  const std::string folder = makeFr1Folder();
  TumFolderReader reader(folder);
  EXPECT_EQ(reader.size(), 2u);  // the depth image without an RGB partner is dropped
  EXPECT_DOUBLE_EQ(reader.intrinsics().fx, 517.3);
  ASSERT_EQ(reader.groundtruth().size(), 1u);
  EXPECT_DOUBLE_EQ(reader.groundtruth()[0].stamp, 1305031102.1758);

  const double depth_stamps[] = {1305031102.160407, 1305031102.262886};
  const double rgb_stamps[] = {1305031102.175304, 1305031102.275326};
  const char* const depth_files[] = {"depth/1305031102.160407.png", "depth/1305031102.262886.png"};
  const char* const rgb_files[] = {"rgb/1305031102.175304.png", "rgb/1305031102.275326.png"};
  RgbdFrame frame;
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(reader.next(frame));
    EXPECT_DOUBLE_EQ(frame.stamp, depth_stamps[k]);
    EXPECT_DOUBLE_EQ(frame.rgb_stamp, rgb_stamps[k]);
    EXPECT_EQ(frame.frame_id, "openni_rgb_optical_frame");
    EXPECT_DOUBLE_EQ(frame.intrinsics.cy, 255.3);
    EXPECT_EQ(frame.intrinsics.width, 640);
    EXPECT_EQ(frame.intrinsics.height, 480);
    ASSERT_EQ(frame.depth_m.type(), CV_32FC1);
    ASSERT_EQ(frame.rgb.type(), CV_8UC3);
    const DepthStats s = stats(frame.depth_m);
    EXPECT_GT(s.valid_fraction, 0.5);
    EXPECT_GT(s.median, 0.5);
    EXPECT_LT(s.median, 5.0);
    // Same values as a file-level read; RGB in RGB order (OpenCV reads BGR).
    EXPECT_TRUE(
        sameDepth(quadric_slam::readTumDepthPng(folder + "/" + depth_files[k]), frame.depth_m));
    const cv::Mat bgr = cv::imread(folder + "/" + rgb_files[k]);
    const cv::Vec3b a = bgr.at<cv::Vec3b>(240, 320), b = frame.rgb.at<cv::Vec3b>(240, 320);
    EXPECT_EQ(a[0], b[2]);
    EXPECT_EQ(a[2], b[0]);
  }
  EXPECT_FALSE(reader.next(frame));
  reader.rewind();
  ASSERT_TRUE(reader.next(frame));
  EXPECT_DOUBLE_EQ(frame.stamp, depth_stamps[0]);

  TumFolderReader::Params params;
  params.keep_frames_without_rgb = true;
  params.intrinsics.fx = params.intrinsics.fy = 525.0;
  params.intrinsics.cx = 319.5;
  params.intrinsics.cy = 239.5;
  TumFolderReader all(folder, params);
  EXPECT_EQ(all.size(), 3u);
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(all.next(frame));
  EXPECT_DOUBLE_EQ(frame.stamp, 1305031107.262886);
  EXPECT_TRUE(frame.rgb.empty());
  EXPECT_DOUBLE_EQ(frame.intrinsics.fx, 525.0);
  EXPECT_EQ(frame.intrinsics.width, 640);
}

TEST(TumFolderReader, BadFoldersAndParamsNameTheProblem) {
  const fs::path root = fs::path(::testing::TempDir()) / "tum_folder_reader_bad";
  fs::remove_all(root);
  fs::create_directories(root);
  try {
    TumFolderReader reader(root.string());
    FAIL() << "expected runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("depth.txt"), std::string::npos) << e.what();
  }
  std::ofstream(root / "depth.txt") << "# c\n1.0 depth/1.png\nnot-a-stamp depth/2.png\n";
  std::ofstream(root / "rgb.txt") << "1.0 rgb/1.png\n";
  try {
    TumFolderReader reader(root.string());
    FAIL() << "expected runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("depth.txt:3"), std::string::npos) << e.what();
  }
  TumFolderReader::Params params;
  params.max_rgb_difference = -1;
  try {
    params.validate();
    FAIL() << "expected invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_rgb_difference"), std::string::npos);
  }
}

// Seeded fuzzing of a TUM folder (issue 14): depth.txt, rgb.txt, a depth PNG or an RGB PNG mutated
// a few bytes at a time. Opening the folder and reading every frame must either stop with
// std::runtime_error naming the file, or give frames a pipeline can use: 32FC1 depth of the
// intrinsics' size with finite positive metres or NaN, stamps finite. No other exception, no crash.
TEST(TumFolderReader, FuzzedFoldersAreRefusedOrGiveValidFrames) {
  const fs::path root = makeFr1Folder();
  const std::vector<fs::path> targets = {root / "depth.txt", root / "rgb.txt",
                                         root / "depth" / "1305031102.160407.png",
                                         root / "rgb" / "1305031102.175304.png"};
  std::vector<std::string> originals;
  for (const fs::path& target : targets) {
    std::ifstream in(target, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    originals.push_back(bytes.str());
  }
  const int cases = quadric_slam::test::fuzzCases(240);
  int refused = 0, read_through = 0;
  quadric_slam::test::FuzzMutator mutator(7);
  for (int k = 0; k < cases; ++k) {
    const std::size_t t = static_cast<std::size_t>(k) % targets.size();
    std::ofstream(targets[t], std::ios::binary) << mutator.mutate(originals[t]);
    try {
      TumFolderReader reader(root.string());
      RgbdFrame frame;
      while (reader.next(frame)) {
        ASSERT_EQ(frame.depth_m.type(), CV_32FC1) << "case " << k;
        EXPECT_EQ(frame.depth_m.cols, frame.intrinsics.width) << "case " << k;
        EXPECT_EQ(frame.depth_m.rows, frame.intrinsics.height) << "case " << k;
        EXPECT_TRUE(std::isfinite(frame.stamp)) << "case " << k;
        int bad = 0;
        for (int v = 0; v < frame.depth_m.rows; ++v)
          for (int u = 0; u < frame.depth_m.cols; ++u) {
            const float z = frame.depth_m.at<float>(v, u);
            bad += !(std::isnan(z) || (std::isfinite(z) && z > 0));
          }
        EXPECT_EQ(bad, 0) << "case " << k << ": depth values neither NaN nor positive metres";
        if (!frame.rgb.empty()) {
          EXPECT_EQ(frame.rgb.type(), CV_8UC3) << "case " << k;
        }
      }
      ++read_through;
    } catch (const std::runtime_error& e) {
      ++refused;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << k << " (" << targets[t].filename() << "): " << typeid(e).name()
                    << ": " << e.what();
    }
    std::ofstream(targets[t], std::ios::binary) << originals[t];
  }
  std::printf("fuzzed TUM folders: %d cases, %d read through, %d refused with std::runtime_error\n",
              cases, read_through, refused);
  EXPECT_GT(refused, 0);
  EXPECT_GT(read_through, 0);
}
