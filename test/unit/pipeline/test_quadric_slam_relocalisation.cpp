// Relocalisation against the quadric map through the pipeline class (issue 12: "a generated
// sequence with 2 s of blank frames and a 1 m jump: lost, then relocalised within 1 s of the view
// returning; 0 duplicate landmarks; ATE after"). A rendered desk sequence at 10 Hz: the desk for
// 3 s, then the lens is covered for 2 s (no depth at all) and meanwhile the camera is carried
// 1.35 m along its arc around the desk, turning by 60 degrees; then the desk again for 3 s. The
// odometry restarts from its pose before the loss, 0.8 m and 60 degrees from the truth when the
// view returns, so only a relocalisation against the map's landmarks can anchor it again.
// (Turns of 50 degrees or less the odometry's own quadric motion guess recovers.) The same with
// the loss in the first frames, before any surface was seen often enough to be a landmark.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "quadric_slam/eval/map_metrics.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/io/landmark_map_file.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/synthetic_frame_source.h"
#include "quadric_slam/sim/trajectory.h"
#include "quadric_slam/sim/trajectory_jump.h"

namespace qs = quadric_slam;

namespace {

constexpr double kRate = 10.0;
constexpr int kFirstBlank = 30, kViewReturns = 50, kFrames = 80;
constexpr int kJumpFrame = 40;  // the camera is carried away while the lens is covered
constexpr double kTurn = -90.0 * M_PI / 180.0;  // about 2 m along the arc

double rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v)
    sum += x * x;
  return v.empty() ? std::numeric_limits<double>::infinity() : std::sqrt(sum / v.size());
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()))];
}

// The map against the scene's surfaces (the map frame is the first camera pose; the gates are
// the evaluator's defaults).
qs::MapReport evaluateMap(const qs::Scene& scene, const qs::QuadricSlam& slam,
                          const Eigen::Isometry3d& T_world_map) {
  qs::MapFile truth_map;
  for (const qs::Surface& s : qs::buildSurfaces(scene))
    truth_map.quadrics.push_back(s.toMapQuadric());
  return qs::MapEvaluator(qs::MapEvaluator::Params{})
      .evaluate(truth_map, qs::mapFileFromLandmarks(slam.mapper().landmarks(), "map"), T_world_map);
}

// The desk scene's hand-held path at kRate, carried kTurn about the scene's centre from frame
// jump_frame on (the jump falls between two frames, so that resampling never interpolates
// across it), rendered without colour.
std::unique_ptr<qs::SyntheticFrameSource> jumpedDeskSource(const qs::Scene& scene, int jump_frame,
                                                           int frames, double turn = kTurn) {
  const qs::Trajectory handheld = qs::HandheldTrajectory(scene.handheld)
                                      .generate(scene.centre_of_interest, kRate, frames / kRate, 5);
  EXPECT_EQ(handheld.size(), static_cast<std::size_t>(frames));
  const double jump_stamp = handheld[jump_frame].stamp - 0.5 / kRate;
  const qs::Trajectory jumped =
      qs::withJump(handheld, jump_stamp,
                   qs::turnAbout(scene.centre_of_interest, Eigen::Vector3d::UnitZ(), turn));
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("relocalisation_" + std::to_string(::getpid()) + ".txt"))
                               .string();
  qs::writeTumTrajectory(jumped, path);
  qs::SyntheticFrameSource::Params source_params;
  source_params.seconds = frames / kRate;
  source_params.rate = kRate;
  source_params.seed = 5;
  source_params.rgb = false;
  source_params.driving_trajectory = path;
  auto source = std::make_unique<qs::SyntheticFrameSource>(scene, source_params);
  std::filesystem::remove(path);
  EXPECT_EQ(source->size(), static_cast<std::size_t>(frames));
  return source;
}
}  // namespace

TEST(QuadricSlamRelocalisation, RelocalisesAfterBlankFramesAndAJumpWithoutDuplicates) {
  const qs::Scene scene =
      qs::readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/desk.yaml");
  std::unique_ptr<qs::SyntheticFrameSource> jumped = jumpedDeskSource(scene, kJumpFrame, kFrames);
  qs::SyntheticFrameSource& source = *jumped;
  const qs::Trajectory& truth = source.groundTruth();
  const double jump = (truth[kJumpFrame].T_world_sensor.translation() -
                       truth[kJumpFrame - 1].T_world_sensor.translation())
                          .norm();
  ASSERT_GT(jump, 0.95) << "the camera must be carried about 1 m while the lens is covered";

  const qs::SlamParams params =
      qs::loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config");
  // The motion from the last frame before the blank to the return is beyond what the odometry's
  // own quadric motion guess searches from its prior (the last pose), so that only the map can
  // place the camera again (a smaller jump the odometry now finds by itself).
  const Eigen::Isometry3d unseen_motion =
      truth[kFirstBlank - 1].T_world_sensor.inverse() * truth[kViewReturns].T_world_sensor;
  EXPECT_TRUE(Eigen::AngleAxisd(unseen_motion.linear()).angle() >
                  params.odometry.guess.max_rotation_from_prior ||
              unseen_motion.translation().norm() > params.odometry.guess.max_translation_from_prior)
      << "the jump is within the odometry's motion guess: it does not test relocalisation";
  qs::QuadricSlam slam(params);
  // The map frame is the first camera pose.
  const Eigen::Isometry3d T_map_world = truth.front().T_world_sensor.inverse();
  std::vector<double> errors_before, errors_after, attempt_ms;
  int lost_blank = 0, reanchored_at = -1, recovered_at = -1;
  double odometry_error_on_return = 0.0;
  std::vector<qs::QuadricMeasurement> return_observations;
  std::size_t landmarks_before_loss = 0;
  int duplicates_before_loss = -1;
  qs::RgbdFrame frame;
  for (int k = 0; source.next(frame); ++k) {
    const bool blank = k >= kFirstBlank && k < kViewReturns;
    if (blank)
      frame.depth_m.setTo(std::numeric_limits<float>::quiet_NaN());
    if (k == kFirstBlank) {
      landmarks_before_loss = slam.mapper().map().landmarks().size();
      duplicates_before_loss = evaluateMap(scene, slam, truth.front().T_world_sensor).duplicates;
    }
    const int recoveries = slam.recovery().recoveries();
    const qs::SlamFrameResult result = slam.process(frame);
    ASSERT_TRUE(result.processed) << "frame " << k << ": " << result.message;
    const Eigen::Isometry3d T_map_true = T_map_world * truth[k].T_world_sensor;
    if (blank) {
      lost_blank += result.odometry.status == qs::TrackingStatus::kLost ? 1 : 0;
      EXPECT_FALSE(result.mapped) << "frame " << k << ": a blank frame reached the map";
    }
    if (result.relocalisation.attempted)
      attempt_ms.push_back(1e3 * result.relocalisation.seconds);
    if (k == kViewReturns) {
      // Where the odometry (restarted from its last pose) puts the camera, against the truth.
      odometry_error_on_return =
          ((T_map_world * truth[kFirstBlank - 1].T_world_sensor).translation() -
           T_map_true.translation())
              .norm();
      return_observations = result.measurements.observations;
    }
    if (result.relocalisation.reanchored && reanchored_at < 0)
      reanchored_at = k;
    if (k >= kViewReturns && recovered_at < 0 && slam.recovery().recoveries() > recoveries)
      recovered_at = k;
    if (!result.mapped)
      continue;
    const double error =
        (result.mapping.T_map_camera.translation() - T_map_true.translation()).norm();
    if (k < kFirstBlank)
      errors_before.push_back(error);
    else if (recovered_at >= 0)
      errors_after.push_back(error);
  }

  // Lost during the blank: every covered frame.
  EXPECT_EQ(lost_blank, kViewReturns - kFirstBlank);
  // Far outside the association gates (about 10 cm) and, above, outside the odometry's own
  // quadric motion guess (odometry/quadric_motion_guess.h): only the map can place the camera
  // again.
  EXPECT_GT(odometry_error_on_return, 0.7)
      << "the odometry's pose must be far from the truth when the view returns";
  ASSERT_GE(landmarks_before_loss, 5u) << "the desk was not mapped before the loss";
  EXPECT_EQ(slam.recovery().losses(), 1);
  // Relocalised, and mapping resumed, within 1 s (10 frames) of the view returning.
  ASSERT_GE(reanchored_at, kViewReturns) << "never relocalised";
  ASSERT_GE(recovered_at, kViewReturns) << "mapping never resumed after the loss";
  EXPECT_LT(recovered_at - kViewReturns, 10);
  EXPECT_GE(slam.recovery().relocalisations(), 1);
  EXPECT_FALSE(slam.recovery().recovering());

  // No duplicates, no garbage: every landmark is a distinct surface of the scene.
  const std::vector<qs::QuadricLandmark> landmarks = slam.mapper().landmarks();
  const qs::MapReport report = evaluateMap(scene, slam, truth.front().T_world_sensor);
  EXPECT_EQ(duplicates_before_loss, 0);
  EXPECT_EQ(report.duplicates, 0) << "a surface mapped before the loss was mapped again";
  EXPECT_EQ(report.unmatched_estimates, 0) << "landmarks that are no surface of the scene";
  EXPECT_TRUE(
      slam.mapper().map().merger().findDuplicates(slam.mapper().map().landmarks(), nullptr).empty())
      << "the merger finds landmarks that are the same surface";

  // The trajectory in the map after the relocalisation is as good as before the loss.
  const double ate_before = rms(errors_before), ate_after = rms(errors_after);
  ASSERT_GE(errors_after.size(), 15u);
  EXPECT_LT(ate_before, 0.03);
  EXPECT_LT(ate_after, 0.03);

  // Time of one relocalisation attempt on the frame where the view returned (repeated).
  std::vector<double> repeat_ms;
  for (int i = 0; i < 20; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const qs::Relocalisation r = slam.recovery().relocaliser().relocalise(
        return_observations, slam.mapper().map().landmarks());
    repeat_ms.push_back(
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    EXPECT_TRUE(r.found) << r.message;
  }
  std::printf(
      "relocalisation: jump %.2f m, odometry off by %.2f m on return; %d lost frames; "
      "re-anchored at frame +%d, mapping resumed at +%d; %d attempts (%.1f / %.1f ms median / "
      "max), repeated on the return frame: median %.1f ms p95 %.1f ms; position RMSE before the "
      "loss %.1f cm (%zu frames), after %.1f cm (%zu frames); %zu landmarks before the loss, %zu "
      "at the end (%d matched, %d duplicates, %d unmatched)\n",
      jump, odometry_error_on_return, lost_blank, reanchored_at - kViewReturns,
      recovered_at - kViewReturns, static_cast<int>(attempt_ms.size()),
      attempt_ms.empty() ? 0.0 : quantile(attempt_ms, 0.5),
      attempt_ms.empty() ? 0.0 : quantile(attempt_ms, 1.0), quantile(repeat_ms, 0.5),
      quantile(repeat_ms, 0.95), 100 * ate_before, errors_before.size(), 100 * ate_after,
      errors_after.size(), landmarks_before_loss, landmarks.size(), report.matched,
      report.duplicates, report.unmatched_estimates);
}

namespace {

// A loss in the first frames of a run: the desk for kEarlyBlank frames (each surface seen fewer
// times than a landmark needs), then the lens covered for 1 s while the camera is carried 60
// degrees along its arc (beyond the odometry's own motion guess), then the desk again. (At 75
// degrees and more the landmarks of four frames, each from one noisy view, leave the relocaliser
// ambiguous for several frames.)
constexpr int kEarlyBlank = 4, kEarlyJump = 9, kEarlyReturn = 14, kEarlyFrames = 45;
constexpr double kEarlyTurn = -60.0 * M_PI / 180.0;

struct EarlyLossRun {
  std::size_t landmarks_at_loss = 0;  // in the map just after the first lost frame
  std::vector<double> errors_after;   // position errors in the map once mapping goes on
  int relocalisations = 0;
  qs::MapReport report;
};

EarlyLossRun runEarlyLoss(const qs::Scene& scene, const qs::SlamParams& params) {
  std::unique_ptr<qs::SyntheticFrameSource> source =
      jumpedDeskSource(scene, kEarlyJump, kEarlyFrames, kEarlyTurn);
  const qs::Trajectory& truth = source->groundTruth();
  const Eigen::Isometry3d T_map_world = truth.front().T_world_sensor.inverse();
  qs::QuadricSlam slam(params);
  EarlyLossRun run;
  qs::RgbdFrame frame;
  for (int k = 0; source->next(frame); ++k) {
    if (k >= kEarlyBlank && k < kEarlyReturn)
      frame.depth_m.setTo(std::numeric_limits<float>::quiet_NaN());
    const qs::SlamFrameResult result = slam.process(frame);
    EXPECT_TRUE(result.processed) << "frame " << k << ": " << result.message;
    if (k == kEarlyBlank)
      run.landmarks_at_loss = slam.mapper().map().landmarks().size();
    if (k >= kEarlyReturn && result.mapped && !result.recovering)
      run.errors_after.push_back((result.mapping.T_map_camera.translation() -
                                  (T_map_world * truth[k].T_world_sensor).translation())
                                     .norm());
  }
  run.relocalisations = slam.recovery().relocalisations();
  run.report = evaluateMap(scene, slam, truth.front().T_world_sensor);
  return run;
}

}  // namespace

// Before any surface was seen often enough to be a landmark there is nothing to relocalise
// against, and the map went on from the odometry's restart pose, apart from the frames before the
// loss (generated fr1_desk at every 20th frame: lost in frames 5-7, SLAM ATE 18.7 cm). The
// candidates seen in at least recovery_promote_on_loss_min_observations frames now become
// landmarks at the loss, and the camera is relocalised against them when the view returns.
TEST(QuadricSlamRelocalisation, ALossBeforeTheFirstLandmarksIsRelocalisedOnTheirCandidates) {
  const qs::Scene scene =
      qs::readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/desk.yaml");
  qs::SlamParams params = qs::loadSlamParams(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config");
  ASSERT_LT(kEarlyBlank, params.mapping.map.min_observations)
      << "the loss must come before any candidate could become a landmark";

  const EarlyLossRun promoted = runEarlyLoss(scene, params);
  EXPECT_GE(promoted.landmarks_at_loss,
            static_cast<std::size_t>(params.recovery.min_map_landmarks));
  EXPECT_GE(promoted.relocalisations, 1);
  ASSERT_GE(promoted.errors_after.size(), 15u) << "mapping never resumed after the loss";
  EXPECT_LT(rms(promoted.errors_after), 0.03);
  EXPECT_EQ(promoted.report.duplicates, 0);
  EXPECT_EQ(promoted.report.unmatched_estimates, 0) << "landmarks that are no surface of the scene";

  // The same run without the promotion: the frames after the loss are off by the jump.
  params.recovery.promote_on_loss_min_observations = 0;
  const EarlyLossRun apart = runEarlyLoss(scene, params);
  EXPECT_EQ(apart.landmarks_at_loss, 0u);
  ASSERT_FALSE(apart.errors_after.empty());
  EXPECT_GT(rms(apart.errors_after), 0.3);
  std::printf(
      "loss before the first landmarks: %zu landmarks promoted at the loss, %d relocalisations, "
      "position RMSE after %.1f cm (%zu frames); without the promotion %.1f cm; map %d matched, "
      "%d duplicates, %d unmatched\n",
      promoted.landmarks_at_loss, promoted.relocalisations, 100 * rms(promoted.errors_after),
      promoted.errors_after.size(), 100 * rms(apart.errors_after), promoted.report.matched,
      promoted.report.duplicates, promoted.report.unmatched_estimates);
}
