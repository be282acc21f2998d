// BatchRecorder: what the batch refinement sees of a run. The left and the right part of a wall
// are mapped first as two landmarks, then its middle makes them one surface and the mapper merges
// them after a window solve: every recorded observation of the merged landmark, also on keyframes
// that left the window long before, now names the survivor, none is lost, and the batch finds
// every observed landmark in the map. A recorder that ignored the merges would point observations
// at a landmark the map no longer has. The recording follows the mapper's frames and keyframes
// one to one, and a cleared recorder is empty.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "quadric_slam/mapping/batch_recorder.h"
#include "quadric_slam/mapping/batch_refiner.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

const Eigen::Vector3d kUnitX = Eigen::Vector3d::UnitX(), kUnitY = Eigen::Vector3d::UnitY(),
                      kUnitZ = Eigen::Vector3d::UnitZ();

std::map<int, int> observationsPerLandmark(const BatchRecorder& recorder) {
  std::map<int, int> out;
  for (const RecordedKeyframe& keyframe : recorder.keyframes())
    for (const WindowObservation& observation : keyframe.observations)
      ++out[observation.landmark_id];
  return out;
}

// The scenario of QuadricMapper's LandmarksFoundToBeOneSurfaceAreMergedAndReported (exact
// odometry: a drift would tell the two parts apart). `following` records every result as it is;
// `ignoring` records the same results with their merges taken out.
TEST(BatchRecorder, ObservationsOfAMergedLandmarkGoToItsSurvivor) {
  const std::vector<std::vector<test::TrueLandmark>> pieces = test::wallInThreeParts(36);
  const std::vector<Eigen::Isometry3d> poses = test::slideAlongWall(36, -0.3, 0.3);
  std::mt19937 rng(63);
  QuadricMapper::Params params;
  params.window.size = 4;  // the parts' first keyframes leave the window before the merge
  QuadricMapper mapper(params);
  BatchRecorder following, ignoring;
  std::vector<LandmarkMerge> merges;
  int keyframes = 0;
  for (size_t i = 0; i < poses.size(); ++i) {
    FrameMeasurements frame;
    frame.stamp = 1.0 + i / 30.0;
    for (const test::TrueLandmark& piece : pieces[i])
      frame.observations.push_back(test::measure(piece, poses[i], rng));
    OdometryInput odom;
    odom.T_odom_camera = poses.front().inverse() * poses[i];
    const MapperFrameResult r = mapper.process(frame, odom);
    ASSERT_EQ(r.status, FrameStatus::kOk) << r.message;
    keyframes += r.keyframe;
    following.record(r, mapper);
    MapperFrameResult without_merges = r;
    without_merges.merges.clear();
    ignoring.record(without_merges, mapper);
    merges.insert(merges.end(), r.merges.begin(), r.merges.end());
  }
  ASSERT_EQ(merges.size(), 1u) << "the scenario no longer merges the wall's parts";
  const int merged = merges[0].merged_id, survivor = merges[0].survivor_id;
  EXPECT_EQ(following.frames().size(), poses.size());
  EXPECT_EQ(static_cast<int>(following.keyframes().size()), keyframes);

  const std::map<int, int> followed = observationsPerLandmark(following);
  const std::map<int, int> ignored = observationsPerLandmark(ignoring);
  // The merged landmark had recorded observations of its own (else the test proves nothing) ...
  ASSERT_GT(ignored.count(merged), 0u);
  // ... which now belong to the survivor: none lost, none left on the merged id.
  EXPECT_EQ(followed.count(merged), 0u);
  EXPECT_EQ(following.observations(), ignoring.observations());
  EXPECT_EQ(followed.at(survivor), ignored.at(survivor) + ignored.at(merged));
  for (const auto& [id, count] : followed)
    EXPECT_GT(mapper.map().landmarks().count(id), 0u) << "observations of a dead landmark " << id;

  // The batch sees survivors only; with the merges ignored it must skip the merged landmark's
  // observations.
  const BatchRefiner refiner;
  const BatchSolution solution = refiner.refine(following, mapper);
  ASSERT_TRUE(solution.statistics.solution_usable) << solution.statistics.report;
  EXPECT_EQ(solution.statistics.skipped_observations, 0);
  EXPECT_EQ(static_cast<std::size_t>(solution.statistics.observation_factors),
            following.observations());
  EXPECT_EQ(refiner.refine(ignoring, mapper).statistics.skipped_observations, ignored.at(merged));
  // A recording over max_keyframes is not solved: the online estimates come back, not usable.
  BatchRefiner::Params small;
  small.max_keyframes = static_cast<int>(following.keyframes().size()) - 1;
  const BatchSolution refused = BatchRefiner(small).refine(following, mapper);
  EXPECT_FALSE(refused.statistics.solution_usable);
  EXPECT_NE(refused.statistics.report.find("max_keyframes"), std::string::npos);
  ASSERT_EQ(refused.keyframe_poses.size(), following.keyframes().size());
  EXPECT_TRUE(refused.keyframe_poses.back().isApprox(following.keyframes().back().T_map_camera));

  // Merges made outside process() (the whole-map merge before saving) are followed the same way.
  BatchRecorder later = ignoring;
  later.recordMerges(merges);
  EXPECT_EQ(observationsPerLandmark(later), followed);

  following.clear();
  EXPECT_TRUE(following.keyframes().empty());
  EXPECT_TRUE(following.frames().empty());
  EXPECT_EQ(following.observations(), 0u);
}

// A refused frame is not recorded (it is not in the online trajectory either).
TEST(BatchRecorder, RefusedFramesAreNotRecorded) {
  QuadricMapper mapper;
  BatchRecorder recorder;
  FrameMeasurements frame;
  frame.stamp = 1.0;
  recorder.record(mapper.process(frame, OdometryInput{}), mapper);
  frame.stamp = 0.5;  // not after the previous frame: refused
  const MapperFrameResult refused = mapper.process(frame, OdometryInput{});
  ASSERT_EQ(refused.status, FrameStatus::kRejectedStamp);
  recorder.record(refused, mapper);
  EXPECT_EQ(recorder.frames().size(), 1u);
  EXPECT_EQ(recorder.keyframes().size(), 1u);  // the first frame is a keyframe
  EXPECT_TRUE(recorder.frames()[0].is_keyframe);
  EXPECT_EQ(recorder.frames()[0].keyframe, 0);
}

}  // namespace
}  // namespace quadric_slam
