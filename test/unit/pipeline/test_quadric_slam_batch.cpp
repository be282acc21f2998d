// The pipeline class with the offline batch refinement (batch_refinement, on in the package's
// config/mapping.yaml for run_bag): on a rendered desk sequence in which the lens is covered for a
// second, every mapped frame and keyframe is recorded, lost frames are not, the refined trajectory
// holds exactly the mapped frames and is as accurate as the online one, and the landmarks held
// fixed online while the map waited to be anchored again are refined (that mode is not a fixed
// map). Off (the nodelets' default), nothing is recorded and refineBatch() refuses; past
// batch_max_keyframes the recording stops; a reset (time going backwards) starts it again.
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>

#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"

namespace qs = quadric_slam;

namespace {

const std::string kConfigDir = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config";

qs::SyntheticFrameSource deskSource(double seconds) {
  qs::SyntheticFrameSource::Params params;
  params.seconds = seconds;
  params.rate = 10.0;
  params.seed = 5;
  params.rgb = false;
  return qs::SyntheticFrameSource(qs::readSceneYaml(kConfigDir + "/scenes/desk.yaml"), params);
}

}  // namespace

TEST(QuadricSlamBatch, RecordsTheMappedFramesAndRefinesThroughALossOfTracking) {
  qs::SlamParams params = qs::loadSlamParams(kConfigDir);
  ASSERT_TRUE(params.batch_refinement) << "config/mapping.yaml turns it on for run_bag";
  qs::QuadricSlam slam(params);
  qs::SyntheticFrameSource source = deskSource(5.0);
  qs::Trajectory online;
  int keyframes = 0, lost = 0, recovering = 0;
  qs::RgbdFrame frame;
  for (int k = 0; source.next(frame); ++k) {
    if (k >= 20 && k < 30)  // the lens covered for a second: no depth at all
      frame.depth_m.setTo(std::numeric_limits<float>::quiet_NaN());
    const qs::SlamFrameResult result = slam.process(frame);
    lost += result.odometry.status == qs::TrackingStatus::kLost;
    recovering += result.recovering && result.mapped;
    if (!result.mapped)
      continue;
    online.push_back({frame.stamp, result.mapping.T_map_camera});
    keyframes += result.mapping.keyframe;
  }
  ASSERT_GT(lost, 0) << "the covered lens no longer loses tracking: the test proves less";
  ASSERT_GT(recovering, 0) << "no frame was mapped while waiting to be anchored";
  EXPECT_EQ(slam.batchRecorder().frames().size(), online.size());
  EXPECT_EQ(static_cast<int>(slam.batchRecorder().keyframes().size()), keyframes);

  const qs::BatchSolution solution = slam.refineBatch();
  ASSERT_TRUE(solution.statistics.solution_usable) << solution.statistics.report;
  EXPECT_EQ(solution.statistics.fixed_landmarks, 0);
  EXPECT_EQ(solution.statistics.skipped_observations, 0);
  // Every landmark of the online map is in the refined one unless the batch merged it or no
  // keyframe observes it (then it could neither refine nor check it: BatchSolution::landmarks).
  EXPECT_EQ(solution.landmarks.size() +
                static_cast<std::size_t>(solution.statistics.merged_landmarks +
                                         solution.statistics.unobserved_landmarks),
            slam.mapper().map().landmarks().size());
  ASSERT_EQ(solution.trajectory.size(), online.size());
  qs::Trajectory refined;
  for (std::size_t i = 0; i < online.size(); ++i) {
    EXPECT_EQ(solution.trajectory[i].stamp, online[i].stamp);
    refined.push_back({solution.trajectory[i].stamp, solution.trajectory[i].T_map_camera});
  }
  const qs::AbsoluteTrajectoryError ate;
  const double online_ate = ate.evaluate(source.groundTruth(), online).rmse();
  const double refined_ate = ate.evaluate(source.groundTruth(), refined).rmse();
  std::printf("ATE online %.5f m, refined %.5f m (%d keyframes, %d iterations)\n", online_ate,
              refined_ate, keyframes, solution.statistics.iterations);
  // On this millimetre-accurate scene both are at the noise floor (about 2 mm).
  EXPECT_LT(refined_ate, 0.01);
  EXPECT_LT(refined_ate, online_ate + 0.001);
}

TEST(QuadricSlamBatch, OffRecordsNothingAndResetStartsAgain) {
  qs::SlamParams params = qs::loadSlamParams(kConfigDir);
  params.batch_refinement = false;
  qs::QuadricSlam off(params);
  params.batch_refinement = true;
  qs::QuadricSlam on(params);
  params.batch.max_keyframes = 1;
  qs::QuadricSlam bounded(params);
  qs::SyntheticFrameSource source = deskSource(1.0);
  qs::RgbdFrame frame;
  std::size_t mapped = 0;
  while (source.next(frame)) {
    off.process(frame);
    bounded.process(frame);
    mapped += on.process(frame).mapped;
  }
  ASSERT_GT(mapped, 0u);
  // Past batch.max_keyframes the recording stops and is freed, and nothing is solved.
  ASSERT_GE(on.batchRecorder().keyframes().size(), 2u);
  EXPECT_TRUE(bounded.batchRecorder().frames().empty());
  const qs::BatchSolution not_solved = bounded.refineBatch();
  EXPECT_FALSE(not_solved.statistics.solution_usable);
  EXPECT_NE(not_solved.statistics.report.find("batch_max_keyframes"), std::string::npos);
  EXPECT_TRUE(off.batchRecorder().frames().empty());
  EXPECT_TRUE(off.batchRecorder().keyframes().empty());
  EXPECT_THROW(off.refineBatch(), std::logic_error);
  EXPECT_EQ(on.batchRecorder().frames().size(), mapped);

  // Time going backwards resets the map: the recording starts again with it.
  frame.stamp -= 10.0;
  const qs::SlamFrameResult after_reset = on.process(frame);
  ASSERT_TRUE(after_reset.reset);
  EXPECT_EQ(on.batchRecorder().frames().size(), after_reset.mapped ? 1u : 0u);
}
