// The pipeline class split in two (frontEnd / backEnd): the front end of the next frame on a thread
// of its own while the back end works on this one, as scripts/run_bag runs by default, gives
// exactly what process() gives frame after frame — the same odometry, the same mapped poses, the
// same observations and the same map — also through a skipped frame (a depth image that does not
// fit its intrinsics) and a reset (time going backwards), which the back end must see in frame
// order.
#include <gtest/gtest.h>

#include <future>
#include <string>
#include <vector>

#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"

namespace qs = quadric_slam;

namespace {

const std::string kConfigDir = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config";

// A rendered desk sequence of 3 s at 10 Hz; frame 8 is cropped (its size no longer fits its
// intrinsics: skipped) and from frame 20 on the stamps start again (time going backwards: reset).
std::vector<qs::RgbdFrame> deskFrames() {
  qs::SyntheticFrameSource::Params params;
  params.seconds = 3.0;
  params.rate = 10.0;
  params.seed = 3;
  params.rgb = false;
  qs::SyntheticFrameSource source(qs::readSceneYaml(kConfigDir + "/scenes/desk.yaml"), params);
  std::vector<qs::RgbdFrame> frames;
  qs::RgbdFrame frame;
  while (source.next(frame)) {
    frames.push_back(frame);
    frames.back().depth_m = frame.depth_m.clone();
  }
  frames[8].depth_m = frames[8].depth_m(cv::Rect(0, 0, 320, 240)).clone();
  for (std::size_t i = 20; i < frames.size(); ++i)
    frames[i].stamp -= 1.5;
  return frames;
}

void expectSamePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const char* what,
                    std::size_t frame) {
  EXPECT_TRUE(a.matrix().isApprox(b.matrix(), 1e-12)) << what << " differs at frame " << frame;
}

}  // namespace

TEST(QuadricSlamPipelined, FrontEndAheadOnAnotherThreadGivesWhatProcessGives) {
  const std::vector<qs::RgbdFrame> frames = deskFrames();
  const qs::SlamParams params = qs::loadSlamParams(kConfigDir);

  qs::QuadricSlam sequential(params);
  std::vector<qs::SlamFrameResult> expected;
  std::vector<std::size_t> expected_detections;
  for (const qs::RgbdFrame& frame : frames) {
    expected.push_back(sequential.process(frame));
    expected_detections.push_back(sequential.segmentation().detections.size());
  }

  qs::QuadricSlam pipelined(params);
  qs::FrontEndFrame slot[2];
  std::future<void> ahead =
      std::async(std::launch::async, [&] { pipelined.frontEnd(frames[0], &slot[0]); });
  int skipped = 0, resets = 0, mapped = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ahead.get();
    if (i + 1 < frames.size())
      ahead = std::async(std::launch::async,
                         [&, i] { pipelined.frontEnd(frames[i + 1], &slot[(i + 1) % 2]); });
    const qs::SlamFrameResult got = pipelined.backEnd(&slot[i % 2]);
    const qs::SlamFrameResult& want = expected[i];
    ASSERT_EQ(got.processed, want.processed) << "frame " << i << ": " << got.message;
    EXPECT_EQ(got.reset, want.reset) << "frame " << i;
    EXPECT_EQ(got.message, want.message) << "frame " << i;
    skipped += !got.processed;
    resets += got.reset;
    if (!got.processed)
      continue;
    ASSERT_EQ(got.measurements.observations.size(), want.measurements.observations.size())
        << "frame " << i;
    for (std::size_t m = 0; m < got.measurements.observations.size(); ++m)
      expectSamePose(got.measurements.observations[m].quadric_camera.pose(),
                     want.measurements.observations[m].quadric_camera.pose(), "an observation", i);
    EXPECT_EQ(got.odometry.status, want.odometry.status) << "frame " << i;
    expectSamePose(got.odometry.T_odom_camera, want.odometry.T_odom_camera, "the odometry", i);
    ASSERT_EQ(got.mapped, want.mapped) << "frame " << i;
    if (got.mapped) {
      ++mapped;
      expectSamePose(got.mapping.T_map_camera, want.mapping.T_map_camera, "the mapped pose", i);
      EXPECT_EQ(got.mapping.keyframe, want.mapping.keyframe) << "frame " << i;
    }
    // The latest frame's cloud and segmentation are the back end's, as after process().
    EXPECT_EQ(pipelined.cloud().size(), frames[i].depth_m.total()) << "frame " << i;
    EXPECT_EQ(pipelined.segmentation().detections.size(), expected_detections[i]) << "frame " << i;
  }
  EXPECT_EQ(skipped, 1) << "the cropped frame no longer is skipped: the test proves less";
  EXPECT_EQ(resets, 1) << "the stamps going backwards no longer reset: the test proves less";
  EXPECT_GT(mapped, 15);

  const auto a = sequential.mapper().landmarks(), b = pipelined.mapper().landmarks();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t l = 0; l < a.size(); ++l) {
    EXPECT_EQ(a[l].id, b[l].id);
    expectSamePose(a[l].quadric_map.pose(), b[l].quadric_map.pose(), "a landmark", l);
  }
  EXPECT_EQ(sequential.reconstruction().size(), pipelined.reconstruction().size());
  // Every stage timed as often (the front end's timings reach the timer through the back end).
  const auto want_stages = sequential.timer().summaries(),
             got_stages = pipelined.timer().summaries();
  ASSERT_EQ(got_stages.size(), want_stages.size());
  for (const auto& [stage, summary] : want_stages)
    EXPECT_EQ(got_stages.at(stage).count, summary.count) << stage;
}
