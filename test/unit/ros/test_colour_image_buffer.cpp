// ColourImageBuffer and colourImageToRgb: an observation's stamp finds the colour image of the
// nearest stamp within the gate, or none; time going backwards empties the buffer; rgb8 is shared,
// bgr8 and mono8 are converted to R G B, other encodings and broken images are refused.
#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

#include <boost/make_shared.hpp>

#include <stdexcept>

#include "quadric_slam/ros/colour_image_buffer.h"

namespace qs = quadric_slam;

namespace {

sensor_msgs::ImagePtr image(const std::string& encoding, int width, int height,
                            std::vector<std::uint8_t> pixel) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->encoding = encoding;
  msg->width = static_cast<std::uint32_t>(width);
  msg->height = static_cast<std::uint32_t>(height);
  msg->step = static_cast<std::uint32_t>(width * pixel.size());
  for (int i = 0; i < width * height; ++i)
    msg->data.insert(msg->data.end(), pixel.begin(), pixel.end());
  return msg;
}

qs::ColourImageBuffer::Entry entryAt(double stamp) {
  qs::ColourImageBuffer::Entry entry;
  entry.stamp = stamp;
  entry.intrinsics.fx = stamp;  // tells the entries apart
  return entry;
}

}  // namespace

TEST(ColourImageBuffer, FindsTheNearestImageWithinTheGate) {
  qs::ColourImageBuffer buffer(3, 0.02);
  for (double stamp : {1.000, 1.033, 1.067, 1.100})
    buffer.add(entryAt(stamp));
  EXPECT_EQ(buffer.size(), 3u);  // 1.000 went first
  qs::ColourImageBuffer::Entry found;
  ASSERT_TRUE(buffer.nearest(1.040, &found));
  EXPECT_DOUBLE_EQ(found.stamp, 1.033);
  ASSERT_TRUE(buffer.nearest(1.105, &found));
  EXPECT_DOUBLE_EQ(found.stamp, 1.100);
  EXPECT_FALSE(buffer.nearest(1.000, &found)) << "evicted";
  EXPECT_FALSE(buffer.nearest(1.130, &found)) << "outside the gate";
  EXPECT_DOUBLE_EQ(found.stamp, 1.100) << "untouched when nothing matches";
  double oldest = 0.0, newest = 0.0;
  ASSERT_TRUE(buffer.span(&oldest, &newest));
  EXPECT_DOUBLE_EQ(oldest, 1.033);
  EXPECT_DOUBLE_EQ(newest, 1.100);
  buffer.dropBefore(1.05);  // the observations have reached 1.07
  EXPECT_EQ(buffer.size(), 2u);
  EXPECT_FALSE(buffer.nearest(1.035, &found));
  buffer.add(entryAt(0.5));  // time went backwards: the older images are gone
  EXPECT_EQ(buffer.size(), 1u);
  EXPECT_FALSE(buffer.nearest(1.100, &found));
  EXPECT_THROW(qs::ColourImageBuffer(0, 0.02), std::invalid_argument);
  EXPECT_THROW(qs::ColourImageBuffer(3, 0.0), std::invalid_argument);
}

TEST(ColourImageToRgb, ConvertsTheEncodingsTheMapperReads) {
  cv_bridge::CvImageConstPtr rgb;
  const sensor_msgs::ImagePtr rgb8 = image("rgb8", 40, 30, {10, 20, 30});
  ASSERT_EQ(qs::colourImageToRgb(rgb8, &rgb), "");
  EXPECT_EQ(rgb->image.type(), CV_8UC3);
  EXPECT_EQ(rgb->image.at<cv::Vec3b>(5, 7), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(rgb->image.data, rgb8->data.data()) << "rgb8 is shared, not copied";
  ASSERT_EQ(qs::colourImageToRgb(image("bgr8", 40, 30, {10, 20, 30}), &rgb), "");
  EXPECT_EQ(rgb->image.at<cv::Vec3b>(5, 7), cv::Vec3b(30, 20, 10));
  ASSERT_EQ(qs::colourImageToRgb(image("mono8", 40, 30, {77}), &rgb), "");
  EXPECT_EQ(rgb->image.at<cv::Vec3b>(5, 7), cv::Vec3b(77, 77, 77));

  EXPECT_NE(qs::colourImageToRgb(image("rgba8", 40, 30, {1, 2, 3, 4}), &rgb), "");
  EXPECT_FALSE(rgb);
  EXPECT_NE(qs::colourImageToRgb(image("32FC1", 40, 30, {0, 0, 0, 0}), &rgb), "");
  sensor_msgs::ImagePtr short_data = image("rgb8", 40, 30, {1, 2, 3});
  short_data->data.resize(100);
  EXPECT_NE(qs::colourImageToRgb(short_data, &rgb), "");
  sensor_msgs::ImagePtr bad_step = image("rgb8", 40, 30, {1, 2, 3});
  bad_step->step = 40;
  EXPECT_NE(qs::colourImageToRgb(bad_step, &rgb), "");
  EXPECT_NE(qs::colourImageToRgb(nullptr, &rgb), "");
}
