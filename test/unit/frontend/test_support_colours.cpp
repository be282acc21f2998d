// colourSupportPoints: support points back-projected from known depth pixels take exactly the
// colour of those pixels in a registered RGB image whose colour pattern encodes the pixel; an RGB
// image at twice the resolution is sampled at the matching pixel; points outside the image stay
// uncoloured; an image of another aspect ratio is refused.
#include <gtest/gtest.h>

#include <stdexcept>

#include "quadric_slam/frontend/support_colours.h"

namespace qs = quadric_slam;

namespace {

qs::CameraIntrinsics kinect() {
  qs::CameraIntrinsics k;
  k.fx = 525.0;
  k.fy = 520.0;
  k.cx = 319.5;
  k.cy = 239.5;
  k.width = 640;
  k.height = 480;
  return k;
}

// The colour that encodes pixel (u, v) of a 640 x 480 image: R = u mod 256, G = v mod 256,
// B = 16 (u / 256) + v / 256.
cv::Vec3b pixelCode(int u, int v) {
  return cv::Vec3b(static_cast<uchar>(u % 256), static_cast<uchar>(v % 256),
                   static_cast<uchar>(16 * (u / 256) + v / 256));
}

// An RGB image of width x height whose pixel shows the code of the 640 x 480 pixel it covers.
cv::Mat codedImage(int width, int height) {
  cv::Mat rgb(height, width, CV_8UC3);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u)
      rgb.at<cv::Vec3b>(v, u) = pixelCode(u * 640 / width, v * 480 / height);
  return rgb;
}

// Points back-projected (frontend/frame.h's convention) from pixels spread over the image, at
// depths between 0.5 and 4 m.
qs::FrameMeasurements framePoints(const qs::CameraIntrinsics& k, std::vector<cv::Point>* pixels) {
  qs::FrameMeasurements frame;
  frame.observations.resize(2);
  int i = 0;
  for (int v = 0; v < 480; v += 7)
    for (int u = 0; u < 640; u += 11, ++i) {
      const float z = 0.5f + 3.5f * static_cast<float>((u * 31 + v * 17) % 100) / 100.0f;
      const Eigen::Vector3f p(static_cast<float>((u - k.cx) * z / k.fx),
                              static_cast<float>((v - k.cy) * z / k.fy), z);
      frame.observations[i % 2].support_points.push_back(p);
      pixels->push_back(cv::Point(u, v));
    }
  return frame;
}

}  // namespace

TEST(SupportColours, EachPointTakesTheColourOfItsDepthPixel) {
  const qs::CameraIntrinsics k = kinect();
  std::vector<cv::Point> pixels;
  qs::FrameMeasurements frame = framePoints(k, &pixels);
  const int coloured = qs::colourSupportPoints(frame, codedImage(640, 480), k);
  EXPECT_EQ(coloured, static_cast<int>(pixels.size()));
  std::size_t index[2] = {0, 0};
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const qs::QuadricMeasurement& m = frame.observations[i % 2];
    ASSERT_EQ(m.support_colours.size(), m.support_points.size());
    const cv::Vec3b c = pixelCode(pixels[i].x, pixels[i].y);
    EXPECT_EQ(m.support_colours[index[i % 2]++], qs::packColour(c[0], c[1], c[2]))
        << "pixel " << pixels[i];
  }
}

TEST(SupportColours, AnRgbImageOfTwiceTheResolutionIsSampledAtTheSamePixel) {
  const qs::CameraIntrinsics k = kinect();
  std::vector<cv::Point> pixels;
  qs::FrameMeasurements frame = framePoints(k, &pixels);
  EXPECT_EQ(qs::colourSupportPoints(frame, codedImage(1280, 960), k),
            static_cast<int>(pixels.size()));
  std::size_t index[2] = {0, 0};
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const cv::Vec3b c = pixelCode(pixels[i].x, pixels[i].y);
    EXPECT_EQ(frame.observations[i % 2].support_colours[index[i % 2]++],
              qs::packColour(c[0], c[1], c[2]));
  }
}

TEST(SupportColours, PointsOutsideTheImageOrBehindTheCameraStayUncoloured) {
  const qs::CameraIntrinsics k = kinect();
  qs::FrameMeasurements frame;
  frame.observations.resize(1);
  auto& points = frame.observations[0].support_points;
  points.emplace_back(0.0f, 0.0f, 1.0f);   // the image centre
  points.emplace_back(5.0f, 0.0f, 1.0f);   // far right of the image
  points.emplace_back(0.0f, 0.0f, -1.0f);  // behind the camera
  points.emplace_back(NAN, 0.0f, 1.0f);    // not finite
  EXPECT_EQ(qs::colourSupportPoints(frame, codedImage(640, 480), k), 1);
  const auto& colours = frame.observations[0].support_colours;
  ASSERT_EQ(colours.size(), 4u);
  EXPECT_TRUE(qs::hasColour(colours[0]));
  EXPECT_EQ(colours[1], qs::kNoColour);
  EXPECT_EQ(colours[2], qs::kNoColour);
  EXPECT_EQ(colours[3], qs::kNoColour);
}

TEST(SupportColours, RefusesImagesItCannotSample) {
  const qs::CameraIntrinsics k = kinect();
  qs::FrameMeasurements frame;
  frame.observations.resize(1);
  frame.observations[0].support_points.emplace_back(0.0f, 0.0f, 1.0f);
  EXPECT_THROW(qs::colourSupportPoints(frame, codedImage(640, 360), k), std::invalid_argument);
  EXPECT_THROW(qs::colourSupportPoints(frame, cv::Mat(480, 640, CV_8UC1), k),
               std::invalid_argument);
  qs::CameraIntrinsics bad = k;
  bad.fx = 0.0;
  EXPECT_THROW(qs::colourSupportPoints(frame, codedImage(640, 480), bad), std::invalid_argument);
}
