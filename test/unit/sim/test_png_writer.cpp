#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <stdexcept>

#include "quadric_slam/sim/png_writer.h"
#include "quadric_slam/sim/random.h"

using namespace quadric_slam;

namespace {

cv::Mat randomImage(int rows, int cols, int type, std::uint64_t seed) {
  cv::Mat image(rows, cols, type);
  SimRandom random(seed);
  for (int v = 0; v < rows; ++v) {
    unsigned char* row = image.ptr<unsigned char>(v);
    // Smooth ramps plus noise, like rendered images, and some random bytes.
    for (std::size_t i = 0; i < image.cols * image.elemSize(); ++i)
      row[i] = static_cast<unsigned char>((i % 7 == 0) ? random() : (v + i / 3) & 0xff);
  }
  return image;
}

void expectEqual(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.type(), b.type());
  ASSERT_EQ(a.size(), b.size());
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);
}

}  // namespace

TEST(PngWriter, OpenCvDecodesEveryTypeExactly) {
  for (int level : {0, 1, 6, 9}) {
    for (const cv::Size size : {cv::Size(640, 480), cv::Size(37, 5), cv::Size(1, 1)}) {
      const cv::Mat depth = randomImage(size.height, size.width, CV_16UC1, level + 1);
      expectEqual(cv::imdecode(encodePng(depth, level), cv::IMREAD_UNCHANGED), depth);
      const cv::Mat grey = randomImage(size.height, size.width, CV_8UC1, level + 2);
      expectEqual(cv::imdecode(encodePng(grey, level), cv::IMREAD_UNCHANGED), grey);
      const cv::Mat rgb = randomImage(size.height, size.width, CV_8UC3, level + 3);
      cv::Mat bgr;
      cv::cvtColor(cv::imdecode(encodePng(rgb, level), cv::IMREAD_UNCHANGED), bgr,
                   cv::COLOR_BGR2RGB);
      expectEqual(bgr, rgb);  // input is R G B; OpenCV decodes to B G R
    }
  }
}

TEST(PngWriter, CompressesAndWritesFiles) {
  const cv::Mat flat(480, 640, CV_16UC1, cv::Scalar(7));
  EXPECT_LT(encodePng(flat, 1).size(), 10000u);
  const cv::Mat roi = randomImage(40, 60, CV_16UC1, 9)(cv::Rect(5, 5, 30, 20));  // strided view
  const std::string path = testing::TempDir() + "/png_writer_test.png";
  writePng(path, roi, 1);
  expectEqual(cv::imread(path, cv::IMREAD_UNCHANGED), roi);
  std::filesystem::remove(path);
  EXPECT_THROW(encodePng(cv::Mat(2, 2, CV_32FC1), 1), std::invalid_argument);
  EXPECT_THROW(encodePng(flat, 10), std::invalid_argument);
  EXPECT_THROW(writePng("/nonexistent/dir/x.png", flat, 1), std::runtime_error);
}
