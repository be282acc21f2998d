// BatchRefiner on a synthetic world with known truth (synthetic_world.h: a corridor of planes,
// spheres, cylinders and cones; measurement noise 5 mm / 0.005 rad / 2% of scale; odometry with a
// 2% scale error and a 1 mrad-per-frame yaw bias): after the online mapper has run, recorded by a
// BatchRecorder, the one global dog-leg solve brings the trajectory closer to the truth than the
// online sliding window, the landmarks converge to the true surfaces, the first keyframe (the
// gauge) stays where it was and the frames between keyframes follow their odometry, corrected to
// join the refined keyframes.
// The solve finds the optimum of the whole problem whatever online path led to its start.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <random>
#include <set>

#include "map_report_checks.h"
#include "quadric_slam/eval/map_metrics.h"
#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/mapping/batch_recorder.h"
#include "quadric_slam/mapping/batch_refiner.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

struct RecordedRun {
  Trajectory truth, odometry, online;
  BatchRecorder recorder;
  int keyframes = 0;
};

// The mapper over `poses` with drifting odometry, every result recorded; the whole-map merge
// before saving is recorded too.
RecordedRun runAndRecord(QuadricMapper* mapper, const std::vector<test::TrueLandmark>& world,
                         const std::vector<Eigen::Isometry3d>& poses, int seed,
                         double noise_scale = 1.0) {
  std::mt19937 rng(seed);
  const std::vector<Eigen::Isometry3d> odometry = test::driftingOdometry(poses, rng);
  RecordedRun out;
  for (size_t i = 0; i < poses.size(); ++i) {
    FrameMeasurements frame;
    frame.stamp = 1.0 + i / 30.0;
    for (const test::TrueLandmark& l : world)
      if (test::visible(l, poses[i]))
        frame.observations.push_back(test::measure(l, poses[i], rng, noise_scale));
    OdometryInput odom;
    odom.T_odom_camera = odometry[i];
    const MapperFrameResult r = mapper->process(frame, odom);
    EXPECT_EQ(r.status, FrameStatus::kOk) << r.message;
    out.recorder.record(r, *mapper);
    out.keyframes += r.keyframe;
    out.truth.push_back({frame.stamp, poses[i]});
    out.odometry.push_back({frame.stamp, odometry[i]});
    out.online.push_back({frame.stamp, r.T_map_camera});
  }
  out.recorder.recordMerges(mapper->mergeDuplicates());
  return out;
}

TEST(BatchRefiner, ParamsValidate) {
  BatchRefiner::Params p;
  EXPECT_NO_THROW(p.validate());
  p.max_keyframes = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.noise_rounds = 11;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.noise_tolerance = 0.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.merge_rounds = 11;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  for (int bad : {0, 10001}) {
    p.max_iterations = bad;
    try {
      BatchRefiner refiner(p);
      ADD_FAILURE() << "max_iterations " << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("max_iterations"), std::string::npos);
    }
  }
}

// Nothing recorded: nothing to solve, and nothing is claimed.
TEST(BatchRefiner, EmptyRecordingGivesAnEmptyUnusableSolution) {
  const QuadricMapper mapper;
  const BatchSolution s = BatchRefiner().refine(BatchRecorder(), mapper);
  EXPECT_FALSE(s.statistics.solution_usable);
  EXPECT_TRUE(s.trajectory.empty());
  EXPECT_TRUE(s.keyframe_poses.empty());
}

// A corridor with a new object every metre (planes, spheres, cylinders, cones) and drifting
// odometry: each pose was estimated online from landmarks known only from the frames before it;
// the batch also uses every later observation of them (a smoother rather than a filter).
TEST(BatchRefiner, RefinedTrajectoryBeatsTheOnlineWindowAndLandmarksConverge) {
  const std::vector<test::TrueLandmark> world = test::corridorWorld(20);
  const std::vector<Eigen::Isometry3d> poses = test::corridorTrajectory(700);
  QuadricMapper mapper;
  const RecordedRun run = runAndRecord(&mapper, world, poses, 102);
  const BatchRecorder& recorder = run.recorder;
  ASSERT_EQ(recorder.frames().size(), poses.size());
  ASSERT_EQ(static_cast<int>(recorder.keyframes().size()), run.keyframes);

  const BatchSolution solution = BatchRefiner().refine(recorder, mapper);
  const BatchStatistics& s = solution.statistics;
  std::cout << "batch: " << s.keyframes << " keyframes, " << s.landmarks << " landmarks, "
            << s.observation_factors << " observations, " << s.iterations << " iterations, cost "
            << s.initial_cost << " -> " << s.final_cost << " (" << s.report << ")\n";
  ASSERT_TRUE(s.solution_usable) << s.report;
  EXPECT_EQ(s.keyframes, run.keyframes);
  EXPECT_EQ(s.frames, static_cast<int>(poses.size()));
  EXPECT_EQ(s.odometry_factors, run.keyframes - 1);
  EXPECT_EQ(static_cast<std::size_t>(s.observation_factors), recorder.observations());
  EXPECT_EQ(s.skipped_observations, 0);
  EXPECT_EQ(s.landmarks, static_cast<int>(mapper.map().landmarks().size()));
  EXPECT_EQ(s.invalid_landmarks, 0);
  EXPECT_TRUE(s.covariance_computed);
  EXPECT_LT(s.final_cost, s.initial_cost);
  std::cout << "whitened observation residuals: median " << s.observation_residual_median << " p95 "
            << s.observation_residual_p95 << "\n";
  // The synthetic noise is what the covariances say: a k-dimensional whitened residual (k = 3-6)
  // has a norm of about sqrt(k) at the optimum.
  EXPECT_GT(s.observation_residual_median, 1.0);
  EXPECT_LT(s.observation_residual_median, 3.0);
  EXPECT_LT(s.observation_residual_p95, 5.0);
  ASSERT_EQ(solution.trajectory.size(), poses.size());

  // The gauge: the first keyframe (the map frame) does not move.
  EXPECT_TRUE(solution.keyframe_poses[0].isApprox(recorder.keyframes()[0].T_map_camera, 1e-12));
  // Keyframes are their own refined poses; the frames after the last keyframe hang from it through
  // their odometry; the frames between two keyframes follow their odometry up to the small
  // corrections that join the refined keyframes (frame_reattachment.h).
  const int last_keyframe = static_cast<int>(recorder.keyframes().size()) - 1;
  Trajectory hanging;  // every frame hung from its earlier keyframe, the re-attachment before
  for (std::size_t i = 0; i < recorder.frames().size(); ++i) {
    const RecordedFrame& f = recorder.frames()[i];
    ASSERT_GE(f.keyframe, 0);
    const RecordedKeyframe& kf = recorder.keyframes()[f.keyframe];
    const Eigen::Isometry3d hung =
        solution.keyframe_poses[f.keyframe] * kf.T_odom_camera.inverse() * f.T_odom_camera;
    hanging.push_back({f.stamp, hung});
    if (f.is_keyframe || f.keyframe == last_keyframe) {
      EXPECT_LT(minus(solution.trajectory[i].T_map_camera, hung).norm(), 1e-9) << i;
    }
    if (f.is_keyframe) {
      EXPECT_LT(
          minus(solution.trajectory[i].T_map_camera, solution.keyframe_poses[f.keyframe]).norm(),
          1e-9);
    }
    if (i > 0) {
      // Each step differs from the odometry's by a fraction of the keyframes' disagreement.
      const RecordedFrame& previous = recorder.frames()[i - 1];
      const Eigen::Isometry3d odometry_step = previous.T_odom_camera.inverse() * f.T_odom_camera;
      const Eigen::Isometry3d refined_step =
          solution.trajectory[i - 1].T_map_camera.inverse() * solution.trajectory[i].T_map_camera;
      EXPECT_LT(minus(odometry_step, refined_step).head<3>().norm(), 0.005) << i;
    }
    EXPECT_EQ(solution.trajectory[i].stamp, run.truth[i].stamp);
  }

  Trajectory refined;
  for (const RefinedPose& p : solution.trajectory)
    refined.push_back({p.stamp, p.T_map_camera});
  const AbsoluteTrajectoryError ate;
  const double odometry_ate = ate.evaluate(run.truth, run.odometry).rmse();
  const double online_ate = ate.evaluate(run.truth, run.online).rmse();
  const AteResult refined_ate = ate.evaluate(run.truth, refined);
  const double hanging_ate = ate.evaluate(run.truth, hanging).rmse();
  std::cout << "ATE RMSE odometry " << odometry_ate << " m, online " << online_ate << " m, refined "
            << refined_ate.rmse() << " m (frames hung from their earlier keyframe: " << hanging_ate
            << " m)\n";
  // Spreading the keyframes' disagreement over the frames between them beats carrying it forward.
  EXPECT_LT(refined_ate.rmse(), hanging_ate);
  // Seeds 101-103: odometry 50-52 cm, online 8.2-9.6 mm, refined 6.8-8.3 mm (0.84-0.86 of the
  // online ATE; with a window of 3 keyframes the same).
  EXPECT_LT(refined_ate.rmse(), 0.9 * online_ate);
  EXPECT_LT(refined_ate.rmse(), 0.03 * odometry_ate);

  // The map, refined and online, against the true surfaces in the map frame (the first camera
  // pose: the gauge; the position-only ATE alignment of a nearly straight path leaves the roll
  // about it free, which would tilt every surface alike).
  const MapEvaluator evaluator;
  const MapReport refined_map =
      evaluator.evaluate(test::truthMap(world), test::estimateMap(solution.landmarks), poses[0]);
  const MapReport online_map =
      evaluator.evaluate(test::truthMap(world), test::estimateMap(mapper.landmarks()), poses[0]);
  std::cout << "refined map:\n"
            << formatMapReport(refined_map) << "online map:\n"
            << formatMapReport(online_map);
  EXPECT_EQ(refined_map.matched, static_cast<int>(world.size()));
  EXPECT_EQ(refined_map.duplicates, 0);
  EXPECT_EQ(refined_map.unmatched_estimates, 0);
  // Seed 102: refined plane normals 0.24 deg / offsets 2.1 mm, sphere centres 1.9 cm / radii
  // 0.4 mm, cylinder axes 0.20 deg / 2.0 cm / radii 0.5 mm, cone apices 2.0 cm / axes 0.20 deg /
  // half-angles 0.05 deg (the positions drift along the corridor with the odometry's scale error,
  // which no surface in view can observe).
  EXPECT_LT(test::meanError(refined_map, "plane", "normal_angle_deg"), 0.35);
  EXPECT_LT(test::meanError(refined_map, "plane", "offset_m"), 0.005);
  EXPECT_LT(test::meanError(refined_map, "sphere", "center_m"), 0.03);
  EXPECT_LT(test::meanError(refined_map, "sphere", "radius_m"), 0.001);
  EXPECT_LT(test::meanError(refined_map, "cylinder", "axis_angle_deg"), 0.3);
  EXPECT_LT(test::meanError(refined_map, "cylinder", "axis_distance_m"), 0.03);
  EXPECT_LT(test::meanError(refined_map, "cylinder", "radius_m"), 0.001);
  EXPECT_LT(test::meanError(refined_map, "cone", "apex_m"), 0.03);
  EXPECT_LT(test::meanError(refined_map, "cone", "axis_angle_deg"), 0.3);
  EXPECT_LT(test::meanError(refined_map, "cone", "half_angle_deg"), 0.1);
  // Where the surfaces are is better known after the batch than online (online, seed 102: plane
  // offsets 8.3 mm, sphere centres 2.4 cm, cylinder axes 2.6 cm, cone apices 2.5 cm).
  for (const auto& [quadric_class, position] :
       std::vector<std::pair<std::string, std::string>>{{"plane", "offset_m"},
                                                        {"sphere", "center_m"},
                                                        {"cylinder", "axis_distance_m"},
                                                        {"cone", "apex_m"}})
    EXPECT_LT(test::meanError(refined_map, quadric_class, position),
              test::meanError(online_map, quadric_class, position))
        << quadric_class;
  // Refined covariances: one per landmark, of its class's minimal size.
  for (const QuadricLandmark& l : solution.landmarks)
    EXPECT_EQ(l.covariance.rows(), minimalDimension(l.quadric_map.quadricClass())) << l.id;
}

// The batch is the whole problem's optimum, not a function of the online estimation: mapped
// with a window of 10 or of 3 keyframes (other online estimates, the same recorded factors when
// the keyframes agree), it ends at the same cost.
TEST(BatchRefiner, EndsAtTheSameOptimumFromDifferentOnlineWindows) {
  const std::vector<test::TrueLandmark> world = test::corridorWorld(20);
  const std::vector<Eigen::Isometry3d> poses = test::corridorTrajectory(700);
  std::vector<BatchStatistics> stats;
  for (int size : {10, 3}) {
    QuadricMapper::Params params;
    params.window.size = size;
    QuadricMapper mapper(params);
    const RecordedRun run = runAndRecord(&mapper, world, poses, 101);
    stats.push_back(BatchRefiner().refine(run.recorder, mapper).statistics);
    ASSERT_TRUE(stats.back().solution_usable);
  }
  ASSERT_EQ(stats[0].keyframes, stats[1].keyframes) << "other keyframes: not the same problem";
  ASSERT_EQ(stats[0].observation_factors, stats[1].observation_factors);
  EXPECT_NE(stats[0].initial_cost, stats[1].initial_cost);  // the online estimates differ
  EXPECT_NEAR(stats[0].final_cost, stats[1].final_cost, 1e-5 * stats[0].final_cost);
}

// Observations noisier than their covariances say (as a segment's fit covariance is against a
// depth camera's systematic error): weighted as stated they outweigh the odometry; with the
// variance factor estimated from their residuals the batch weighs them by what they are.
TEST(BatchRefiner, ObservationsNoisierThanStatedAreWeighedByTheirEstimatedVariance) {
  const std::vector<test::TrueLandmark> world = test::corridorWorld(20);
  const std::vector<Eigen::Isometry3d> poses = test::corridorTrajectory(700);
  const double noise_scale = 4.0;  // the true variance is 16 x the stated one
  QuadricMapper mapper;
  const RecordedRun run = runAndRecord(&mapper, world, poses, 102, noise_scale);
  const AbsoluteTrajectoryError ate;
  std::vector<double> refined_ate;
  for (int rounds : {0, 3}) {
    BatchRefiner::Params params;
    params.noise_rounds = rounds;
    const BatchSolution solution = BatchRefiner(params).refine(run.recorder, mapper);
    const BatchStatistics& s = solution.statistics;
    ASSERT_TRUE(s.solution_usable) << s.report;
    Trajectory refined;
    for (const RefinedPose& p : solution.trajectory)
      refined.push_back({p.stamp, p.T_map_camera});
    refined_ate.push_back(ate.evaluate(run.truth, refined).rmse());
    std::cout << "noise_rounds " << rounds << ": " << s.solves << " solves, residual median "
              << s.observation_residual_median << " sigma, factor " << s.observation_variance_factor
              << "; refined ATE " << refined_ate.back() << " m (online "
              << ate.evaluate(run.truth, run.online).rmse() << " m)\n";
    if (rounds == 0) {
      EXPECT_EQ(s.observation_variance_factor, 1.0);
      EXPECT_EQ(s.solves, 1);
      EXPECT_GT(s.observation_residual_median, 4.0);  // sqrt(16 k): the covariances are wrong
      continue;
    }
    // At the optimum the residuals are smaller than the noise (the fit takes up some of it).
    EXPECT_GT(s.observation_variance_factor, 6.0);
    EXPECT_LT(s.observation_variance_factor, 24.0);
    EXPECT_GT(s.observation_residual_median, 1.0);
    EXPECT_LT(s.observation_residual_median, 3.0);
  }
  EXPECT_LT(refined_ate[1], 0.9 * refined_ate[0]);
}

// The batch's merge passes (mapping/landmark_merger.h, tested with the refined covariances and
// their cross-covariances). The run is mapped with merging off, so that what is one surface in
// the world stays two landmarks online; the batch is then given the same landmarks in a mapper
// whose merging is on (the default).
struct UnmergedRun {
  RecordedRun run;
  std::vector<QuadricLandmark> online;
};

UnmergedRun runWithoutMerging(const std::vector<test::TrueLandmark>& world,
                              const std::vector<Eigen::Isometry3d>& poses, int seed) {
  QuadricMapper::Params params;
  params.map.merging.enabled = false;
  QuadricMapper unmerged(params);
  UnmergedRun out{runAndRecord(&unmerged, world, poses, seed), unmerged.landmarks()};
  return out;
}

BatchSolution refineWithMerging(const UnmergedRun& unmerged, int merge_rounds) {
  QuadricMapper merging;
  merging.loadLandmarks(unmerged.online, false);
  BatchRefiner::Params params;
  params.merge_rounds = merge_rounds;
  return BatchRefiner(params).refine(unmerged.run.recorder, merging);
}

int landmarksOfClass(const std::vector<QuadricLandmark>& landmarks, QuadricClass c) {
  return static_cast<int>(std::count_if(landmarks.begin(), landmarks.end(), [&](const auto& l) {
    return l.quadric_map.quadricClass() == c;
  }));
}

// A plane of the corridor's wall between world x = from and x = to.
test::TrueLandmark wallFragment(double from, double to) {
  return test::plane(Eigen::Vector3d(0.5 * (from + to), 2, 1.5), -Eigen::Vector3d::UnitY(),
                     Eigen::Vector3d::UnitX(), 0.5 * (to - from), 1.5);
}

// The corridor's wall reported in two fragments meeting at x = 6 m, both in view from the first
// frame: two wall landmarks online (merging off), one after the batch, whose covariance is no
// larger than either fragment's; every other surface once.
TEST(BatchRefiner, AWallSeenAsTwoFragmentsBecomesOneLandmark) {
  std::vector<test::TrueLandmark> world = test::corridorWorld(12);
  world[1] = wallFragment(-1.0, 6.0);
  world.push_back(wallFragment(6.0, 17.0));
  const std::vector<Eigen::Isometry3d> poses = test::corridorTrajectory(450);
  const UnmergedRun unmerged = runWithoutMerging(world, poses, 103);
  const int planes_online = landmarksOfClass(unmerged.online, QuadricClass::kPlane);
  ASSERT_GE(planes_online, 3) << "the floor and both fragments of the wall";

  const BatchSolution off = refineWithMerging(unmerged, 0);
  const BatchSolution on = refineWithMerging(unmerged, 3);
  ASSERT_TRUE(off.statistics.solution_usable && on.statistics.solution_usable);
  std::cout << "planes online " << planes_online << ", after the batch without merging "
            << landmarksOfClass(off.landmarks, QuadricClass::kPlane) << " (duplicate pairs "
            << off.duplicates.size() << "), with merging "
            << landmarksOfClass(on.landmarks, QuadricClass::kPlane) << " (" << on.merges.size()
            << " merges, duplicate pairs left " << on.duplicates.size() << ")\n";
  EXPECT_TRUE(off.merges.empty());
  EXPECT_FALSE(off.duplicates.empty());
  EXPECT_EQ(on.statistics.merged_landmarks, static_cast<int>(on.merges.size()));
  EXPECT_EQ(on.landmarks.size() + on.merges.size(), unmerged.online.size());
  EXPECT_TRUE(on.duplicates.empty());
  EXPECT_EQ(landmarksOfClass(on.landmarks, QuadricClass::kPlane), 2) << "the floor and the wall";

  // Against the truth with one wall: every surface once, none left over.
  const std::vector<test::TrueLandmark> truth = test::corridorWorld(12);
  const MapEvaluator evaluator;
  const MapReport report =
      evaluator.evaluate(test::truthMap(truth), test::estimateMap(on.landmarks), poses[0]);
  std::cout << formatMapReport(report);
  EXPECT_EQ(report.matched, static_cast<int>(truth.size()));
  EXPECT_EQ(report.duplicates, 0);
  EXPECT_EQ(report.unmatched_estimates, 0);

  // The wall's survivor is better known than either fragment was in the same batch.
  std::map<int, const QuadricLandmark*> parts;
  for (const QuadricLandmark& l : off.landmarks)
    parts[l.id] = &l;
  for (const LandmarkMerge& merge : on.merges) {
    const QuadricLandmark* survivor = nullptr;
    for (const QuadricLandmark& l : on.landmarks)
      if (l.id == merge.survivor_id)
        survivor = &l;
    ASSERT_NE(survivor, nullptr);
    for (int part : {merge.merged_id, merge.survivor_id})
      EXPECT_LE(survivor->covariance.trace(), parts.at(part)->covariance.trace()) << part;
  }
}

// Two table tops at one height, 2 m apart along the corridor: one plane, two surfaces. Their
// parameters agree, their extents do not touch: the batch keeps them two while merging is on.
TEST(BatchRefiner, TwoTablesAtOneHeightStayTwo) {
  std::vector<test::TrueLandmark> world = test::corridorWorld(12);
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), along = Eigen::Vector3d::UnitX();
  world.push_back(test::plane(Eigen::Vector3d(4.0, 0.1, 0.7), up, along, 0.5, 0.3));
  world.push_back(test::plane(Eigen::Vector3d(7.0, 0.1, 0.7), up, along, 0.5, 0.3));
  const std::vector<Eigen::Isometry3d> poses = test::corridorTrajectory(450);
  const UnmergedRun unmerged = runWithoutMerging(world, poses, 104);
  const BatchSolution on = refineWithMerging(unmerged, 3);
  ASSERT_TRUE(on.statistics.solution_usable);
  EXPECT_TRUE(on.merges.empty());
  EXPECT_TRUE(on.duplicates.empty());
  // The table landmarks: horizontal planes 0.7 m above the floor.
  std::vector<const QuadricLandmark*> tables;
  for (const QuadricLandmark& l : on.landmarks) {
    const Eigen::Isometry3d T_world_quadric = poses[0] * l.quadric_map.pose();
    if (l.quadric_map.quadricClass() == QuadricClass::kPlane &&
        std::abs(T_world_quadric.linear().col(0).z()) > 0.99 &&
        std::abs(T_world_quadric.translation().z() - 0.7) < 0.05)
      tables.push_back(&l);
  }
  ASSERT_EQ(tables.size(), 2u);
  const LandmarkMerger merger;
  const LandmarkMerger::Comparison c = merger.compare(*tables[0], *tables[1]);
  std::cout << "tables: d^2 " << c.squared_distance << " (gate "
            << merger.gate(QuadricClass::kPlane) << "), extents touch " << c.extents_touch << "\n";
  EXPECT_TRUE(c.within_gate) << "one plane";
  EXPECT_FALSE(c.extents_touch) << "two surfaces";
}


// A landmark of the map that no recorded keyframe observes (here one loaded into the mapper beside
// the run's own, a copy of a run's landmark 3 m further along its normal under a new id) has no
// block in the batch: the refined map leaves it out and counts it; every observed landmark stays.
TEST(BatchRefiner, ALandmarkNoKeyframeObservesIsLeftOutOfTheRefinedMap) {
  const std::vector<test::TrueLandmark> world = test::corridorWorld(12);
  const std::vector<Eigen::Isometry3d> poses = test::corridorTrajectory(150);
  QuadricMapper::Params params;
  params.map.merging.enabled = false;
  QuadricMapper online(params);
  const RecordedRun run = runAndRecord(&online, world, poses, 7);
  std::vector<QuadricLandmark> landmarks = online.landmarks();
  ASSERT_FALSE(landmarks.empty());
  QuadricLandmark unobserved = landmarks.front();
  int max_id = 0;
  for (const QuadricLandmark& l : landmarks)
    max_id = std::max(max_id, l.id);
  unobserved.id = max_id + 1;
  Eigen::Isometry3d T = unobserved.quadric_map.pose();
  T.translation() += 3.0 * T.linear().col(0);
  unobserved.quadric_map =
      QuadricModel(unobserved.quadric_map.quadricClass(), T, unobserved.quadric_map.scale(),
                   unobserved.quadric_map.signature());
  landmarks.push_back(unobserved);
  QuadricMapper mapper;
  mapper.loadLandmarks(landmarks, false);

  const BatchSolution solution = BatchRefiner().refine(run.recorder, mapper);
  ASSERT_TRUE(solution.statistics.solution_usable) << solution.statistics.report;
  EXPECT_EQ(solution.statistics.unobserved_landmarks, 1);
  EXPECT_EQ(solution.statistics.landmarks, static_cast<int>(landmarks.size()) - 1);
  std::set<int> ids;
  for (const QuadricLandmark& l : solution.landmarks)
    ids.insert(l.id);
  EXPECT_EQ(ids.count(unobserved.id), 0u);
  EXPECT_EQ(solution.landmarks.size() + solution.merges.size(), landmarks.size() - 1);
}

}  // namespace
}  // namespace quadric_slam
