// Core <-> message conversions round trip for every class, without a master.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "../test_support.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/ros/conversions.h"

namespace qs = quadric_slam;
using qs::QuadricClass;

namespace {

qs::QuadricMeasurement randomMeasurement(QuadricClass c, std::mt19937& rng, int label) {
  qs::QuadricMeasurement m;
  m.quadric_camera = qs::test::randomQuadric(c, rng);
  const int k = qs::minimalDimension(c);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(k, k);
  m.covariance = a * a.transpose() + Eigen::MatrixXd::Identity(k, k) * 1e-3;
  m.num_points = 1000 + label;
  m.label = label;
  m.image_roi = {10 * label, 20, 100, 50 + label};
  m.fit_rms = 0.004;
  m.extent_min = Eigen::Vector3d(-0.1, -0.2, -0.3);
  m.extent_max = Eigen::Vector3d(0.1, 0.2, 0.3 + label);
  return m;
}

void expectSameQuadric(const qs::QuadricModel& a, const qs::QuadricModel& b) {
  EXPECT_EQ(a.quadricClass(), b.quadricClass());
  EXPECT_TRUE(a.pose().isApprox(b.pose(), 1e-12));
  EXPECT_TRUE(a.scale().isApprox(b.scale(), 1e-12));
  EXPECT_EQ(a.signature(), b.signature());
  EXPECT_TRUE(qs::test::normalizedMatrix(a.matrix())
                  .isApprox(qs::test::normalizedMatrix(b.matrix()), 1e-9));
}

}  // namespace

TEST(Conversions, ObservationRoundTripEveryClass) {
  std::mt19937 rng(7);
  int label = 1;
  for (QuadricClass c : qs::kAllQuadricClasses) {
    SCOPED_TRACE(qs::toString(c));
    for (int trial = 0; trial < 20; ++trial) {
      const qs::QuadricMeasurement m = randomMeasurement(c, rng, label++);
      const quadric_slam::QuadricObservation msg = qs::toObservationMsg(m);
      EXPECT_EQ(msg.surface.quadric_class, static_cast<int>(c));
      EXPECT_EQ(msg.minimal_dimension, qs::minimalDimension(c));
      EXPECT_EQ(msg.covariance.size(),
                static_cast<std::size_t>(msg.minimal_dimension) * msg.minimal_dimension);
      EXPECT_EQ(msg.surface.shape, qs::shapeVector(m.quadric_camera));
      const qs::QuadricMeasurement back = qs::fromObservationMsg(msg);
      expectSameQuadric(back.quadric_camera, m.quadric_camera);
      EXPECT_TRUE(back.covariance.isApprox(m.covariance, 1e-15));
      EXPECT_EQ(back.num_points, m.num_points);
      EXPECT_EQ(back.label, m.label);
      EXPECT_EQ(back.image_roi.x_offset, m.image_roi.x_offset);
      EXPECT_EQ(back.image_roi.height, m.image_roi.height);
      EXPECT_NEAR(back.fit_rms, m.fit_rms, 1e-9);
      EXPECT_EQ(back.extent_min, m.extent_min);
      EXPECT_EQ(back.extent_max, m.extent_max);
    }
  }
}

TEST(Conversions, ShapeFieldFollowsTheMessageLayout) {
  qs::SphereShape sphere;
  sphere.center = Eigen::Vector3d(0.2, -0.1, 1.5);
  sphere.radius = 0.16;
  const quadric_slam::QuadricSurface msg = qs::toSurfaceMsg(
      qs::quadricFromShape(sphere), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  ASSERT_EQ(msg.shape.size(), 4u);
  EXPECT_NEAR(msg.shape[0], 0.2, 1e-12);
  EXPECT_NEAR(msg.shape[2], 1.5, 1e-12);
  EXPECT_NEAR(msg.shape[3], 0.16, 1e-12);
  EXPECT_NEAR(msg.scale[0], 1.0 / 0.16, 1e-9);
  EXPECT_NEAR(msg.pose.position.z, 1.5, 1e-12);
}

TEST(Conversions, ArrayKeepsHeaderAndSkipsBadObservations) {
  std::mt19937 rng(3);
  qs::FrameMeasurements frame;
  frame.stamp = 1341847980.723020;
  frame.frame_id = "openni_rgb_optical_frame";
  frame.observations.push_back(randomMeasurement(QuadricClass::kPlane, rng, 1));
  frame.observations.push_back(randomMeasurement(QuadricClass::kCone, rng, 2));
  quadric_slam::QuadricObservationArray msg = qs::toObservationArrayMsg(frame);
  EXPECT_EQ(msg.header.frame_id, frame.frame_id);
  EXPECT_NEAR(msg.header.stamp.toSec(), frame.stamp, 1e-6);

  // A corrupted observation (covariance of the wrong size) is skipped and counted.
  quadric_slam::QuadricObservation bad = msg.observations[0];
  bad.covariance.pop_back();
  msg.observations.push_back(bad);
  quadric_slam::QuadricObservation bad_class = msg.observations[0];
  bad_class.surface.quadric_class = 9;
  msg.observations.push_back(bad_class);
  int rejected = -1;
  const qs::FrameMeasurements back = qs::fromObservationArrayMsg(msg, &rejected);
  EXPECT_EQ(rejected, 2);
  ASSERT_EQ(back.observations.size(), 2u);
  EXPECT_EQ(back.observations[1].quadric_camera.quadricClass(), QuadricClass::kCone);
  EXPECT_EQ(back.frame_id, frame.frame_id);
}

TEST(Conversions, LandmarkRoundTrip) {
  std::mt19937 rng(11);
  for (QuadricClass c : qs::kAllQuadricClasses) {
    SCOPED_TRACE(qs::toString(c));
    qs::QuadricLandmark landmark;
    landmark.id = 42;
    landmark.quadric_map = qs::test::randomQuadric(c, rng);
    landmark.observations = 57;
    landmark.covariance =
        Eigen::MatrixXd::Identity(qs::minimalDimension(c), qs::minimalDimension(c));
    landmark.last_observed = 12.5;
    landmark.extent_max = Eigen::Vector3d(1, 2, 3);
    const qs::QuadricLandmark back = qs::fromLandmarkMsg(qs::toLandmarkMsg(landmark));
    EXPECT_EQ(back.id, 42);
    EXPECT_EQ(back.observations, 57);
    expectSameQuadric(back.quadric_map, landmark.quadric_map);
    EXPECT_TRUE(back.covariance.isApprox(landmark.covariance));
    EXPECT_DOUBLE_EQ(back.last_observed, 12.5);
    EXPECT_EQ(back.extent_max, landmark.extent_max);
  }
}

TEST(Conversions, BadPosesAndSurfacesAreRefused) {
  geometry_msgs::Pose pose;
  pose.orientation.w = 2.0;
  EXPECT_THROW(qs::fromPoseMsg(pose), std::invalid_argument);
  pose.orientation.w = 1.0;
  pose.position.x = std::nan("");
  EXPECT_THROW(qs::fromPoseMsg(pose), std::invalid_argument);

  std::mt19937 rng(5);
  quadric_slam::QuadricSurface surface =
      qs::toSurfaceMsg(qs::test::randomQuadric(QuadricClass::kSphere, rng), Eigen::Vector3d::Zero(),
                       Eigen::Vector3d::Zero());
  surface.signature[3] = 1;  // no longer a sphere's signature
  EXPECT_THROW(qs::fromSurfaceMsg(surface), std::invalid_argument);
  surface = qs::toSurfaceMsg(qs::test::randomQuadric(QuadricClass::kSphere, rng),
                             Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  surface.scale[0] = -1.0;
  EXPECT_THROW(qs::fromSurfaceMsg(surface), std::invalid_argument);
  EXPECT_THROW(qs::fromCovarianceMsg({1.0, 2.0}, 3), std::invalid_argument);
}
