// Validation of incoming PointCloud2, Image and CameraInfo messages (message_validation.h) and the
// per-reason throttle of drop reports (drop_reporter.h), without a master. Includes the messages
// that once killed the nodelet manager (issue 14), and a check that the core processes the
// smallest input the validation lets through.
#include <gtest/gtest.h>
#include <pcl_conversions/pcl_conversions.h>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/ros/depth_image.h"
#include "quadric_slam/ros/drop_reporter.h"
#include "quadric_slam/ros/message_validation.h"
#include "quadric_slam/ros/points_normals.h"

namespace qs = quadric_slam;
namespace enc = sensor_msgs::image_encodings;

namespace {

bool mentions(const std::string& problem, const std::string& text) {
  return problem.find(text) != std::string::npos;
}

// An organized points_normals cloud as NormalEstimation publishes it: a tilted plane at 1-2 m.
sensor_msgs::PointCloud2 pointsNormals(std::uint32_t width, std::uint32_t height) {
  pcl::PointCloud<pcl::PointNormal> cloud(width, height);
  for (std::uint32_t v = 0; v < height; ++v) {
    for (std::uint32_t u = 0; u < width; ++u) {
      pcl::PointNormal& p = cloud(u, v);
      p.z = 1.0f + 0.001f * u;
      p.x = (static_cast<float>(u) - 0.5f * width) * p.z / 500.f;
      p.y = (static_cast<float>(v) - 0.5f * height) * p.z / 500.f;
      p.normal_x = 0.f;
      p.normal_y = 0.f;
      p.normal_z = -1.f;
    }
  }
  sensor_msgs::PointCloud2 msg;
  pcl::toROSMsg(cloud, msg);
  return msg;
}

sensor_msgs::Image depthImage(const std::string& encoding, std::uint32_t width,
                              std::uint32_t height) {
  sensor_msgs::Image image;
  image.encoding = encoding;
  image.width = width;
  image.height = height;
  const std::uint32_t bytes = encoding == enc::TYPE_32FC1 ? 4 : 2;
  image.step = width * bytes;
  image.data.assign(static_cast<std::size_t>(image.step) * height, 0);
  for (std::size_t i = 0; i < static_cast<std::size_t>(width) * height; ++i) {
    if (bytes == 4) {
      const float z = 1.5f;
      std::memcpy(&image.data[4 * i], &z, 4);
    } else {
      const std::uint16_t mm = 1500;
      std::memcpy(&image.data[2 * i], &mm, 2);
    }
  }
  return image;
}

sensor_msgs::CameraInfo cameraInfo(std::uint32_t width, std::uint32_t height) {
  sensor_msgs::CameraInfo info;
  info.width = width;
  info.height = height;
  info.K = {525.0, 0, 0.5 * width, 0, 525.0, 0.5 * height, 0, 0, 1};
  return info;
}

sensor_msgs::PointField* field(sensor_msgs::PointCloud2& msg, const std::string& name) {
  for (auto& f : msg.fields)
    if (f.name == name)
      return &f;
  return nullptr;
}

std::string cloudProblem(const sensor_msgs::PointCloud2& msg) {
  return qs::pointCloudProblem(msg, qs::pointsNormalsLayout());
}

}  // namespace

TEST(MessageValidation, WellFormedMessagesPass) {
  EXPECT_EQ(cloudProblem(pointsNormals(640, 480)), "");
  EXPECT_EQ(cloudProblem(pointsNormals(2, 2)), "");
  EXPECT_EQ(qs::depthImageProblem(depthImage(enc::TYPE_32FC1, 640, 480)), "");
  EXPECT_EQ(qs::depthImageProblem(depthImage(enc::TYPE_16UC1, 640, 480)), "");
  EXPECT_EQ(qs::depthImageProblem(depthImage(enc::MONO16, 2, 2)), "");
  EXPECT_EQ(qs::cameraInfoProblem(cameraInfo(640, 480)), "");
  // A padded row is fine: row_step / step may exceed the row's bytes.
  sensor_msgs::PointCloud2 padded = pointsNormals(4, 3);
  const std::uint32_t old_row_step = padded.row_step;
  padded.row_step += 8;
  std::vector<std::uint8_t> data(padded.row_step * padded.height, 0);
  for (std::uint32_t v = 0; v < padded.height; ++v)
    std::memcpy(&data[v * padded.row_step], &padded.data[v * old_row_step], old_row_step);
  padded.data = data;
  EXPECT_EQ(cloudProblem(padded), "");
}

// The six messages of issue 14 that took the manager down.
TEST(MessageValidation, CloudsThatCrashedTheManagerAreRefused) {
  // point_step 0, row_step 0, empty data: SIGSEGV in pcl::fromROSMsg.
  sensor_msgs::PointCloud2 zero_step = pointsNormals(640, 480);
  zero_step.point_step = 0;
  zero_step.row_step = 0;
  zero_step.data.clear();
  EXPECT_TRUE(mentions(cloudProblem(zero_step), "point_step is 0")) << cloudProblem(zero_step);

  // 65536 x 65536 with 64 bytes: width * height wraps to 0 in uint32.
  sensor_msgs::PointCloud2 wrapping = pointsNormals(2, 2);
  wrapping.width = wrapping.height = 65536;
  wrapping.data.resize(64);
  EXPECT_TRUE(mentions(cloudProblem(wrapping), "65536 x 65536 = 4294967296 points"))
      << cloudProblem(wrapping);

  // 20000 x 20000, point_step 0: std::bad_alloc.
  sensor_msgs::PointCloud2 huge = pointsNormals(2, 2);
  huge.width = huge.height = 20000;
  huge.point_step = huge.row_step = 0;
  EXPECT_TRUE(mentions(cloudProblem(huge), "more than the 16777216")) << cloudProblem(huge);
  // 4000 x 4000 (within the limit) with point_step 0 would have made a 1 GB cloud from nothing.
  huge.width = huge.height = 4000;
  EXPECT_TRUE(mentions(cloudProblem(huge), "point_step is 0")) << cloudProblem(huge);

  // 1 x 1 points_normals: QuadricSegmenter threw out of the callback.
  EXPECT_TRUE(mentions(cloudProblem(pointsNormals(1, 1)), "not an organized"));
}

TEST(MessageValidation, ImagesThatCrashedTheManagerAreRefused) {
  // 640 x 1 and 1 x 1 depth images with matching camera_info: NormalEstimator threw.
  for (const auto& size : {std::make_pair(640u, 1u), std::make_pair(1u, 1u)}) {
    const std::string problem =
        qs::depthImageProblem(depthImage(enc::TYPE_32FC1, size.first, size.second));
    EXPECT_TRUE(mentions(problem, "not an organized")) << problem;
    EXPECT_TRUE(
        mentions(qs::cameraInfoProblem(cameraInfo(size.first, size.second)), "not an organized"));
  }
}

TEST(MessageValidation, EachCloudRuleNamesTheField) {
  sensor_msgs::PointCloud2 msg = pointsNormals(8, 6);
  msg.point_step = 12;  // x y z only, but the normals lie beyond it
  msg.row_step = 12 * 8;
  msg.data.resize(msg.row_step * 6);
  EXPECT_TRUE(mentions(cloudProblem(msg),
                       "field 'normal_x' (offset 16) ends at byte 20 but "
                       "point_step is 12"))
      << cloudProblem(msg);

  msg = pointsNormals(8, 6);
  field(msg, "y")->datatype = sensor_msgs::PointField::FLOAT64;
  EXPECT_TRUE(mentions(cloudProblem(msg), "field 'y' is FLOAT64; only FLOAT32"));

  msg = pointsNormals(8, 6);
  field(msg, "z")->count = 3;
  EXPECT_TRUE(mentions(cloudProblem(msg), "field 'z' has count 3"));

  msg = pointsNormals(8, 6);
  msg.fields.erase(
      std::find_if(msg.fields.begin(), msg.fields.end(),
                   [](const sensor_msgs::PointField& f) { return f.name == "normal_x"; }));
  EXPECT_TRUE(mentions(cloudProblem(msg), "no field 'normal_x'")) << cloudProblem(msg);

  msg = pointsNormals(8, 6);
  msg.is_bigendian = true;
  EXPECT_TRUE(mentions(cloudProblem(msg), "big-endian"));

  for (const auto& size : {std::make_pair(0u, 480u), std::make_pair(640u, 0u),
                           std::make_pair(640u, 1u), std::make_pair(1u, 480u)}) {
    msg = pointsNormals(2, 2);
    msg.width = size.first;
    msg.height = size.second;
    EXPECT_TRUE(mentions(cloudProblem(msg), "not an organized")) << cloudProblem(msg);
  }
  // A cloud without points, as PCL writes one, is empty rather than malformed, when allowed.
  msg = pointsNormals(0, 0);
  EXPECT_EQ(msg.height, 1u);
  EXPECT_EQ(cloudProblem(msg), "");
  EXPECT_TRUE(mentions(
      qs::pointCloudProblem(msg, qs::CloudLayout{{"x"}, /*organized=*/true, /*allow_empty=*/false}),
      "not an organized"));
  // An unorganized layout accepts one row, but not more points than a sensor has.
  const qs::CloudLayout row{{"x", "y", "z"}, false, false};
  EXPECT_EQ(qs::pointCloudProblem(pointsNormals(640, 1), row), "");
  msg = pointsNormals(2, 2);
  msg.width = 1u << 25;
  msg.height = 1;
  EXPECT_TRUE(mentions(qs::pointCloudProblem(msg, row), "more than"));

  msg = pointsNormals(8, 6);
  msg.row_step -= 1;
  EXPECT_TRUE(mentions(cloudProblem(msg), "row_step")) << cloudProblem(msg);

  msg = pointsNormals(8, 6);
  msg.data.pop_back();
  EXPECT_TRUE(mentions(cloudProblem(msg), "data has")) << cloudProblem(msg);
  msg.data.resize(msg.data.size() + 2);  // longer than the layout: refused too (exact length)
  EXPECT_TRUE(mentions(cloudProblem(msg), "data has")) << cloudProblem(msg);
}

TEST(MessageValidation, SizesAreComparedWithoutWrapping) {
  // width * point_step = 65536 * 65536 = 2^32 is 0 in uint32: row_step 0 must still be refused.
  sensor_msgs::PointCloud2 msg = pointsNormals(2, 2);
  msg.width = 65536;
  msg.height = 2;
  msg.point_step = 65536;
  msg.row_step = 0;
  msg.data.clear();
  EXPECT_TRUE(mentions(cloudProblem(msg), "= 4294967296")) << cloudProblem(msg);
  // row_step * height = 2^31 * 2 = 2^32 is 0 in uint32: an empty buffer must still be refused.
  msg = pointsNormals(2, 2);
  msg.row_step = 1u << 31;
  msg.data.clear();
  EXPECT_TRUE(mentions(cloudProblem(msg), "= 4294967296")) << cloudProblem(msg);

  sensor_msgs::Image image = depthImage(enc::TYPE_32FC1, 2, 2);
  image.step = 1u << 31;
  image.data.clear();
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "= 4294967296"))
      << qs::depthImageProblem(image);
  image = depthImage(enc::TYPE_32FC1, 2, 2);
  image.width = image.height = 65536;
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "more than"));
}

TEST(MessageValidation, EachImageRuleNamesTheField) {
  sensor_msgs::Image image = depthImage(enc::TYPE_32FC1, 8, 6);
  image.encoding = enc::RGB8;
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "unsupported depth encoding 'rgb8'"));
  image.encoding = enc::TYPE_64FC1;
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "'64FC1'"));
  image.encoding = "";
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "encoding ''"));

  image = depthImage(enc::TYPE_16UC1, 8, 6);
  image.is_bigendian = 1;
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "big-endian"));

  image = depthImage(enc::TYPE_16UC1, 8, 6);
  image.step = 15;
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "step 15 is smaller than width x pixel size"));

  image = depthImage(enc::TYPE_32FC1, 8, 6);
  image.data.resize(10);
  EXPECT_TRUE(mentions(qs::depthImageProblem(image), "data has 10 bytes"));

  for (const auto& size : {std::make_pair(0u, 480u), std::make_pair(640u, 0u)}) {
    image = depthImage(enc::TYPE_32FC1, size.first, size.second);
    EXPECT_TRUE(mentions(qs::depthImageProblem(image), "not an organized"));
  }
}

TEST(MessageValidation, CameraInfoRules) {
  sensor_msgs::CameraInfo info = cameraInfo(640, 480);
  info.K[0] = std::nan("");
  EXPECT_TRUE(mentions(qs::cameraInfoProblem(info), "focal lengths"));
  info = cameraInfo(640, 480);
  info.K[4] = -525.0;
  EXPECT_TRUE(mentions(qs::cameraInfoProblem(info), "focal lengths"));
  info = cameraInfo(640, 480);
  info.K[2] = INFINITY;
  EXPECT_TRUE(mentions(qs::cameraInfoProblem(info), "principal point"));
  EXPECT_TRUE(mentions(qs::cameraInfoProblem(cameraInfo(0, 480)), "not an organized"));
  EXPECT_TRUE(mentions(qs::cameraInfoProblem(cameraInfo(100000, 100000)), "more than"));
  // Finite but absurd: back-projection would give infinite or collapsed points.
  for (const double focal : {1e-300, 1e-3, 1.0, 4e5, 1e300}) {
    info = cameraInfo(640, 480);
    info.K[0] = info.K[4] = focal;
    EXPECT_TRUE(mentions(qs::cameraInfoProblem(info), "field of view")) << focal;
  }
  info = cameraInfo(640, 480);
  info.K[2] = 1e12;
  EXPECT_TRUE(mentions(qs::cameraInfoProblem(info), "outside the 640 x 480 image"));
  // Real cameras pass: a Kinect (about 58 x 45 degrees), a fisheye-like 170 degrees, a long lens
  // of 1 degree, a principal point off-centre (a crop).
  for (const double focal : {525.0, 28.0, 36000.0}) {
    info = cameraInfo(640, 480);
    info.K[0] = info.K[4] = focal;
    EXPECT_EQ(qs::cameraInfoProblem(info), "") << focal;
  }
  info = cameraInfo(640, 480);
  info.K[2] = -600.0;
  EXPECT_EQ(qs::cameraInfoProblem(info), "");
}

TEST(MessageValidation, DepthToCloudRefusesACloudDecimatedBelowTheMinimum) {
  const qs::CameraIntrinsics k = qs::intrinsicsFromCameraInfo(cameraInfo(3, 3));
  qs::BackProjectionParams params;
  params.decimation = 2;  // 3 x 3 -> 1 x 1
  pcl::PointCloud<pcl::PointXYZ> cloud;
  const std::string problem =
      qs::depthImageToCloud(depthImage(enc::TYPE_32FC1, 3, 3), k, params, cloud);
  EXPECT_TRUE(mentions(problem, "at decimation 2 leaves fewer than 2 x 2")) << problem;
  EXPECT_TRUE(cloud.empty());
}

// What the validation lets through, the core processes: the smallest grids reach NormalEstimator,
// QuadricSegmenter and OdometryTracker without an exception.
TEST(MessageValidation, TheCoreTakesTheSmallestAcceptedGrids) {
  for (const auto& size : {std::make_pair(2u, 2u), std::make_pair(2u, 480u),
                           std::make_pair(640u, 2u), std::make_pair(3u, 3u)}) {
    SCOPED_TRACE(std::to_string(size.first) + " x " + std::to_string(size.second));
    const sensor_msgs::Image image = depthImage(enc::TYPE_32FC1, size.first, size.second);
    const sensor_msgs::CameraInfo info = cameraInfo(size.first, size.second);
    ASSERT_EQ(qs::depthImageProblem(image), "");
    ASSERT_EQ(qs::cameraInfoProblem(info), "");
    const qs::CameraIntrinsics k = qs::intrinsicsFromCameraInfo(info);
    pcl::PointCloud<pcl::PointXYZ> cloud;
    ASSERT_EQ(qs::depthImageToCloud(image, k, {}, cloud), "");

    for (const std::string method : {"box_gradient", "covariance_matrix"}) {
      qs::NormalEstimator::Params normal_params;
      normal_params.method = method;
      pcl::PointCloud<pcl::PointNormal> with_normals;
      EXPECT_NO_THROW(qs::NormalEstimator(normal_params).compute(cloud, with_normals)) << method;
    }

    const sensor_msgs::PointCloud2 msg = pointsNormals(size.first, size.second);
    pcl::PointCloud<pcl::PointNormal> points;
    ASSERT_EQ(qs::pointsNormalsFromMsg(msg, points), "");
    EXPECT_NO_THROW(qs::QuadricSegmenter(qs::QuadricSegmenter::Params()).segment(points));
    qs::OdometryTracker tracker{qs::OdometryTracker::Params()};
    EXPECT_NO_THROW(tracker.track(points, k, 0.0));
    EXPECT_NO_THROW(tracker.track(points, k, 0.1));
  }
}

TEST(ReasonThrottle, EachReasonHasItsOwnPeriod) {
  using Clock = qs::ReasonThrottle::Clock;
  qs::ReasonThrottle throttle(5.0, 3);
  const Clock::time_point t0 = Clock::now();
  unsigned long suppressed = 99;
  EXPECT_TRUE(throttle.allow("bad encoding", t0, &suppressed));
  EXPECT_EQ(suppressed, 0u);
  EXPECT_FALSE(throttle.allow("bad encoding", t0 + std::chrono::seconds(1)));
  // A second reason within the period is still logged.
  EXPECT_TRUE(throttle.allow("point_step is 0", t0 + std::chrono::seconds(2), &suppressed));
  EXPECT_EQ(suppressed, 1u);
  // After the period the first reason is logged again.
  EXPECT_TRUE(throttle.allow("bad encoding", t0 + std::chrono::seconds(6)));
}

TEST(ReasonThrottle, EverDifferentReasonsCannotFloodTheLog) {
  using Clock = qs::ReasonThrottle::Clock;
  qs::ReasonThrottle throttle(5.0, 3);
  const Clock::time_point t0 = Clock::now();
  int logged = 0;
  for (int i = 0; i < 100; ++i)
    logged += throttle.allow("data has " + std::to_string(i) + " bytes", t0);
  EXPECT_EQ(logged, 3);
  unsigned long suppressed = 0;
  EXPECT_TRUE(throttle.allow("data has 1000 bytes", t0 + std::chrono::seconds(5), &suppressed));
  EXPECT_EQ(suppressed, 97u);
}
