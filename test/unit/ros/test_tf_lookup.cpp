// tf lookups at message stamps (ros/tf_lookup.h), on a tf2 buffer filled by hand, without a master:
// frame ids with a leading '/' are found, stamps resolve in order once their transforms are there,
// and a stamp is given up only when tf cannot bring its transforms any more.
#include <gtest/gtest.h>
#include <tf2_eigen/tf2_eigen.h>

#include "quadric_slam/ros/tf_lookup.h"

namespace qs = quadric_slam;

namespace {

// parent -> child at `seconds`, a translation of x metres along x.
void setTransform(tf2_ros::Buffer& buffer, const std::string& parent, const std::string& child,
                  double seconds, double x) {
  geometry_msgs::TransformStamped tf;
  tf.header.frame_id = parent;
  tf.header.stamp = ros::Time(seconds);
  tf.child_frame_id = child;
  tf.transform.translation.x = x;
  tf.transform.rotation.w = 1.0;
  ASSERT_TRUE(buffer.setTransform(tf, "test"));
}

}  // namespace

TEST(TfLookup, FramesWithALeadingSlashAreFound) {
  tf2_ros::Buffer buffer;
  // As a TUM bag publishes it; tf2 stores it as world -> kinect.
  setTransform(buffer, "/world", "/kinect", 10.0, 1.5);
  std::string error;
  EXPECT_FALSE(buffer.canTransform("/world", "/kinect", ros::Time(10.0), &error))
      << "tf2 itself now accepts '/world': the normalisation is no longer needed";
  const std::optional<Eigen::Isometry3d> T =
      qs::lookupIsometry(buffer, "/world", "/kinect", ros::Time(10.0), &error);
  ASSERT_TRUE(T.has_value()) << error;
  EXPECT_NEAR(T->translation().x(), 1.5, 1e-12);
  // The inverse direction, and an unknown frame with tf2's reason.
  const std::optional<Eigen::Isometry3d> T_inverse =
      qs::lookupIsometry(buffer, "kinect", "/world", ros::Time(10.0), &error);
  ASSERT_TRUE(T_inverse.has_value()) << error;
  EXPECT_NEAR(T_inverse->translation().x(), -1.5, 1e-12);
  error.clear();
  EXPECT_FALSE(qs::lookupIsometry(buffer, "world", "camera", ros::Time(10.0), &error));
  EXPECT_NE(error.find("camera"), std::string::npos) << error;
}

TEST(TfLookup, StampsResolveInOrderOnceTheirTransformsArrive) {
  tf2_ros::Buffer buffer;
  qs::PendingTfLookups pending(2.0);
  for (double t : {1.0, 2.0, 3.0})
    pending.add(ros::Time(t), {{"/world", "/kinect"}});
  // Nothing has arrived yet, and the newest stamp is not 2 s younger than any: all wait.
  EXPECT_TRUE(pending.resolve(buffer, false).empty());
  EXPECT_EQ(pending.waiting(), 3u);

  setTransform(buffer, "world", "kinect", 0.0, 0.0);
  setTransform(buffer, "world", "kinect", 2.0, 2.0);
  std::vector<qs::PendingTfLookups::Resolved> resolved = pending.resolve(buffer, false);
  ASSERT_EQ(resolved.size(), 2u);  // 3 s lies beyond the newest transform: it waits
  EXPECT_EQ(resolved[0].stamp, ros::Time(1.0));
  EXPECT_EQ(resolved[1].stamp, ros::Time(2.0));
  ASSERT_EQ(resolved[0].transforms.size(), 1u);
  EXPECT_NEAR(resolved[0].transforms[0].translation().x(), 1.0, 1e-9);  // interpolated
  EXPECT_EQ(pending.waiting(), 1u);
  EXPECT_EQ(pending.givenUp(), 0u);

  setTransform(buffer, "world", "kinect", 4.0, 4.0);
  resolved = pending.resolve(buffer, false);
  ASSERT_EQ(resolved.size(), 1u);
  EXPECT_NEAR(resolved[0].transforms[0].translation().x(), 3.0, 1e-9);
  EXPECT_EQ(pending.newest(), ros::Time(3.0));
}

TEST(TfLookup, AStampIsGivenUpWhenItsTransformsCannotComeAnyMore) {
  tf2_ros::Buffer buffer;
  setTransform(buffer, "map", "camera", 0.0, 0.0);
  setTransform(buffer, "map", "camera", 10.0, 1.0);
  qs::PendingTfLookups pending(2.0);
  // Two lookups per stamp: resolved only when both are there (world -> kinect never is).
  pending.add(ros::Time(1.0), {{"map", "camera"}, {"world", "kinect"}});
  pending.add(ros::Time(2.0), {{"map", "camera"}});
  EXPECT_TRUE(pending.resolve(buffer, false).empty()) << "the first stamp must block the second";
  pending.add(ros::Time(3.5), {{"map", "camera"}});
  // 3.5 s is more than 2 s after 1 s: the first is given up, the rest follow in order.
  const std::vector<qs::PendingTfLookups::Resolved> resolved = pending.resolve(buffer, false);
  ASSERT_EQ(resolved.size(), 2u);
  EXPECT_EQ(resolved[0].stamp, ros::Time(2.0));
  EXPECT_EQ(resolved[1].stamp, ros::Time(3.5));
  EXPECT_EQ(pending.givenUp(), 1u);
  EXPECT_NE(pending.lastError().find("world"), std::string::npos) << pending.lastError();

  // At the end (no more transforms will come) whatever cannot be resolved is given up.
  pending.add(ros::Time(20.0), {{"map", "camera"}});
  EXPECT_TRUE(pending.resolve(buffer, false).empty());
  EXPECT_TRUE(pending.resolve(buffer, true).empty());
  EXPECT_EQ(pending.waiting(), 0u);
  EXPECT_EQ(pending.givenUp(), 2u);
}
