#include <gtest/gtest.h>

#include <atomic>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "quadric_slam/sim/sequence_generator.h"

using namespace quadric_slam;

namespace {

Renderer ballRenderer() {
  Scene scene;
  PrimitiveSpec ball;
  ball.name = "ball";
  ball.type = PrimitiveType::kSphere;
  ball.radius = 0.45;  // about 2800 of the 4800 pixels: a large view (kLargeViewPixels)
  ball.T_world_primitive.translation() = Eigen::Vector3d(0, 0, 1.5);
  scene.primitives.push_back(ball);
  PrimitiveSpec other = ball;
  other.name = "other";
  other.T_world_primitive.translation() = Eigen::Vector3d(0, 0, -1.5);  // behind frames 0..9
  scene.primitives.push_back(other);
  return Renderer(buildSurfaces(scene), {100, 100, 39.5, 29.5, 80, 60}, {}, {});
}

}  // namespace

TEST(SequenceGenerator, DeliversFramesInOrderAndCountsObservations) {
  const Renderer renderer = ballRenderer();
  std::vector<StampedPose> poses(20);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    poses[k].stamp = 1.0 + k / 30.0;
    if (k >= 10)  // turn around: the second ball is seen, the first is not
      poses[k].T_world_sensor.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).matrix();
  }
  SequenceGenerator::Params params;
  params.threads = 3;
  params.max_in_flight = 4;
  const SequenceGenerator generator(renderer, params);
  std::vector<std::size_t> order;
  std::atomic<int> per_frame_calls{0};
  std::vector<int> large_views(3, 0);  // counted here from the labels, as the stats should
  const SequenceGenerator::Stats stats = generator.run(
      poses, [&](std::size_t, const StampedPose&, const RenderedFrame&) { ++per_frame_calls; },
      [&](std::size_t index, const StampedPose& pose, const RenderedFrame& frame) {
        EXPECT_EQ(pose.stamp, poses[index].stamp);
        EXPECT_EQ(frame.labels.cols, 80);
        for (int id = 1; id <= 2; ++id)
          large_views[id] += cv::countNonZero(frame.labels == id) >= kLargeViewPixels ? 1 : 0;
        order.push_back(index);
      });
  ASSERT_EQ(order.size(), poses.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    EXPECT_EQ(order[k], k);
  EXPECT_EQ(per_frame_calls.load(), 20);
  ASSERT_EQ(stats.observations.size(), 3u);
  EXPECT_EQ(stats.observations[1], 10);
  EXPECT_EQ(stats.observations[2], 10);
  EXPECT_GT(stats.pixels[1], 10 * 100);
  ASSERT_EQ(stats.large_views.size(), 3u);
  EXPECT_EQ(stats.large_views[1], large_views[1]);
  EXPECT_EQ(stats.large_views[2], large_views[2]);
  EXPECT_EQ(large_views[1], 10);
}

TEST(SequenceGenerator, RethrowsCallbackErrors) {
  const Renderer renderer = ballRenderer();
  std::vector<StampedPose> poses(12);
  const SequenceGenerator generator(renderer, {});
  EXPECT_THROW(generator.run(poses, {},
                             [](std::size_t index, const StampedPose&, const RenderedFrame&) {
                               if (index == 5)
                                 throw std::runtime_error("disk full");
                             }),
               std::runtime_error);
  SequenceGenerator::Params bad;
  bad.threads = 0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}
