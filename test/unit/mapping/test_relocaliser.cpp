// Relocalisation against a quadric map with no pose prior (mapping/relocaliser.h) and the
// re-anchoring of the mapper after a loss (mapping/recovery_relocalisation.h), on the synthetic
// room of the mapping tests: true landmarks as the map, noisy measurements of the visible ones.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/recovery_relocalisation.h"
#include "quadric_slam/mapping/relocaliser.h"
#include "quadric_slam/mapping/tracking_recovery.h"
#include "synthetic_world.h"

namespace qs = quadric_slam;
namespace qt = quadric_slam::test;

namespace {

std::map<int, qs::QuadricLandmark> mapOf(const std::vector<qt::TrueLandmark>& world) {
  std::map<int, qs::QuadricLandmark> map;
  for (std::size_t i = 0; i < world.size(); ++i) {
    qs::QuadricLandmark l;
    l.id = static_cast<int>(i) + 1;
    l.quadric_map = world[i].quadric_world;
    l.observations = 10;
    l.extent_min = world[i].extent.min;
    l.extent_max = world[i].extent.max;
    map[l.id] = l;
  }
  return map;
}

std::vector<qs::QuadricMeasurement> observe(const std::vector<qt::TrueLandmark>& world,
                                            const Eigen::Isometry3d& T_world_camera,
                                            std::mt19937& rng) {
  std::vector<qs::QuadricMeasurement> out;
  for (const qt::TrueLandmark& l : world)
    if (qt::visible(l, T_world_camera))
      out.push_back(qt::measure(l, T_world_camera, rng));
  return out;
}

// Views over the room (a grid of positions at eye height, eight directions, looking slightly
// down) that see at least `min_visible` surfaces.
std::vector<Eigen::Isometry3d> viewsSeeing(const std::vector<qt::TrueLandmark>& world,
                                           std::size_t min_visible) {
  std::vector<Eigen::Isometry3d> out;
  for (double x = -3.0; x <= 3.01; x += 1.5)
    for (double y = -3.0; y <= 3.01; y += 1.5)
      for (int a = 0; a < 8; ++a) {
        const double azimuth = a * M_PI / 4 + 0.2;
        const Eigen::Isometry3d T = qt::lookAlong(
            Eigen::Vector3d(x, y, 1.4), Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), -0.5));
        std::size_t visible = 0;
        for (const qt::TrueLandmark& l : world)
          visible += qt::visible(l, T) ? 1 : 0;
        if (visible >= min_visible)
          out.push_back(T);
      }
  return out;
}

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}
double rotationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle();
}

}  // namespace

// From poses all around the room (the map frame is the world): found where enough surfaces are
// in view, and never at a wrong pose.
TEST(Relocaliser, FindsTheCameraAroundTheRoomAndNeverAtAWrongPose) {
  const std::vector<qt::TrueLandmark> world = qt::roomWorld();
  const std::map<int, qs::QuadricLandmark> map = mapOf(world);
  const qs::Relocaliser relocaliser;
  std::mt19937 rng(11);
  int found = 0, wrong = 0, tried = 0;
  double worst_t = 0.0, worst_r = 0.0;
  for (const Eigen::Isometry3d& T_world_camera : viewsSeeing(world, 5)) {
    const std::vector<qs::QuadricMeasurement> observations = observe(world, T_world_camera, rng);
    ++tried;
    const qs::Relocalisation r = relocaliser.relocalise(observations, map);
    if (!r.found)
      continue;
    ++found;
    const double et = translationError(r.T_map_camera, T_world_camera);
    const double er = rotationError(r.T_map_camera, T_world_camera);
    worst_t = std::max(worst_t, et);
    worst_r = std::max(worst_r, er);
    wrong += et > 0.05 || er > 0.03 ? 1 : 0;
    EXPECT_GE(r.supporting_surfaces, 4);
    EXPECT_EQ(r.matches.size(), static_cast<std::size_t>(r.supporting_surfaces));
    for (const auto& [observation, landmark_id] : r.matches)
      EXPECT_TRUE(map.count(landmark_id));
  }
  ASSERT_GE(tried, 12) << "too few views with enough surfaces: the test proves nothing";
  EXPECT_EQ(wrong, 0) << "worst error " << worst_t << " m, " << worst_r << " rad";
  // Half of these views see a surface arrangement that is repeated elsewhere in the room with one
  // surface fewer (4 of 5 surfaces agree with another pose): refused as ambiguous, by design.
  EXPECT_GE(found, tried / 2) << "found " << found << " of " << tried;
  EXPECT_LT(worst_t, 0.04);
  EXPECT_LT(worst_r, 0.02);
}

// An empty square room (floor and four equal walls) looks the same after every quarter turn:
// the match is ambiguous and must be refused, not guessed.
TEST(Relocaliser, RefusesTheSymmetricSolutionsOfAnEmptySquareRoom) {
  std::vector<qt::TrueLandmark> world = qt::roomWorld();
  world.resize(5);  // floor and four walls
  const std::map<int, qs::QuadricLandmark> map = mapOf(world);
  std::mt19937 rng(3);
  // Near the centre, looking into a corner: floor and two walls (and three surfaces agree with
  // each of four poses).
  const Eigen::Isometry3d T_world_camera = qt::lookAlong(
      Eigen::Vector3d(2.6, 2.4, 1.4), Eigen::Vector3d(1.0, 1.0, -0.5));
  const std::vector<qs::QuadricMeasurement> observations = observe(world, T_world_camera, rng);
  ASSERT_GE(observations.size(), 3u);
  qs::Relocaliser::Params params;
  params.min_supporting_surfaces = 3;
  const qs::Relocalisation r = qs::Relocaliser(params).relocalise(observations, map);
  EXPECT_FALSE(r.found) << "accepted one of the symmetric poses";
  EXPECT_NE(r.message.find("ambiguous"), std::string::npos) << r.message;
  EXPECT_GE(r.runner_up_weight, params.max_ambiguity * r.support_weight);
}

TEST(Relocaliser, NeedsEnoughSurfaces) {
  const std::vector<qt::TrueLandmark> world = qt::roomWorld();
  const std::map<int, qs::QuadricLandmark> map = mapOf(world);
  std::mt19937 rng(5);
  const Eigen::Isometry3d T_world_camera = viewsSeeing(world, 5).front();
  std::vector<qs::QuadricMeasurement> observations = observe(world, T_world_camera, rng);
  observations.resize(std::min<std::size_t>(observations.size(), 3));
  const qs::Relocalisation r = qs::Relocaliser().relocalise(observations, map);
  EXPECT_FALSE(r.found);
  EXPECT_FALSE(r.message.empty());
  EXPECT_FALSE(qs::Relocaliser().relocalise({}, map).found);
  EXPECT_FALSE(qs::Relocaliser().relocalise(observe(world, T_world_camera, rng), {}).found);
}

TEST(Relocaliser, ValidatesItsParameters) {
  const auto throwsNaming = [](qs::Relocaliser::Params p, const std::string& field) {
    try {
      qs::Relocaliser r(p);
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << field << " was not refused";
  };
  qs::Relocaliser::Params p;
  p.min_supporting_surfaces = 2;
  throwsNaming(p, "min_supporting_surfaces");
  p = {};
  p.max_ambiguity = 0.0;
  throwsNaming(p, "max_ambiguity");
  p = {};
  p.extent_margin = -0.1;
  throwsNaming(p, "extent_margin");
  p = {};
  p.min_plane_points = -1;
  throwsNaming(p, "min_plane_points");
  p = {};
  p.matcher.max_offset_difference = 0.0;
  throwsNaming(p, "max_offset_difference");
  p = {};
  p.matcher.max_reference_features = 1;
  throwsNaming(p, "max_reference_features");
}

// The mapper after a loss: the odometry restarted 1 m and 40 degrees from the truth. Its pose
// associates with nothing; the relocalisation re-anchors the odometry in the map, the frame then
// associates from the relocalised pose and the mapper's pose is the true one; after
// confirm_frames such frames mapping resumes.
TEST(RecoveryRelocalisation, ReanchorsTheMapperAfterAJump) {
  const std::vector<qt::TrueLandmark> world = qt::roomWorld();
  std::vector<qs::QuadricLandmark> landmarks;
  for (const auto& [id, l] : mapOf(world))
    landmarks.push_back(l);
  qs::QuadricMapper mapper;
  mapper.loadLandmarks(landmarks, /*fixed=*/true);
  qs::TrackingRecovery recovery;
  recovery.trackingLost(static_cast<int>(landmarks.size()));
  ASSERT_TRUE(recovery.recovering());
  mapper.setLocalizationOnly(true);

  std::mt19937 rng(7);
  // A view of at least five surfaces, then 1 cm and 0.01 rad per frame.
  const Eigen::Isometry3d start = viewsSeeing(world, 5).at(3);
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k < 6; ++k)
    truth.push_back(start *
                    qs::makeIsometry(Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d::UnitY())
                                         .toRotationMatrix(),
                                     Eigen::Vector3d(0.01 * k, 0.0, 0.0)));
  // The odometry believes the camera is where it was before the loss: truth moved back by a
  // 1 m / 40 degree jump.
  const Eigen::Isometry3d jump = qs::makeIsometry(
      Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
      Eigen::Vector3d(0.6, -0.8, 0.0));
  const Eigen::Isometry3d T_odom_world = jump;  // odometry = this * truth
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
  int reanchored = 0;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Isometry3d T_world_camera = truth[k];
    const Eigen::Isometry3d T_odom_camera = T_odom_world * T_world_camera;
    qs::FrameMeasurements frame;
    frame.stamp = 1.0 + 0.1 * k;
    frame.observations = observe(world, T_world_camera, rng);
    const qs::RecoveryRelocalisation step =
        qs::relocaliseWhileRecovering(&recovery, &mapper, frame.observations, T_odom_camera,
                                      T_map_odom);
    reanchored += step.reanchored ? 1 : 0;
    if (k == 0) {
      ASSERT_TRUE(step.attempted);
      ASSERT_TRUE(step.result.found) << step.result.message;
      EXPECT_TRUE(step.reanchored);
    } else {
      EXPECT_FALSE(step.attempted) << "frame " << k << ": the pose was already anchored";
    }
    qs::OdometryInput odometry;
    odometry.T_odom_camera = T_odom_camera;
    const qs::MapperFrameResult result = mapper.process(frame, odometry);
    ASSERT_EQ(result.status, qs::FrameStatus::kOk) << result.message;
    T_map_odom = result.T_map_odom;
    EXPECT_LT(translationError(result.T_map_camera, T_world_camera), 0.03) << "frame " << k;
    EXPECT_LT(rotationError(result.T_map_camera, T_world_camera), 0.02) << "frame " << k;
    EXPECT_GE(qs::landmarkAssociations(result.update), 3) << "frame " << k;
    recovery.frameMapped(qs::landmarkAssociations(result.update));
  }
  EXPECT_EQ(reanchored, 1);
  EXPECT_EQ(recovery.relocalisations(), 1);
  EXPECT_FALSE(recovery.recovering()) << "mapping did not resume after the re-anchored frames";
  EXPECT_EQ(recovery.recoveries(), 1);
}

// Without a jump the odometry's pose is right: the relocalisation finds the same pose and leaves
// the odometry chain alone.
TEST(RecoveryRelocalisation, LeavesACorrectOdometryPoseAlone) {
  const std::vector<qt::TrueLandmark> world = qt::roomWorld();
  std::vector<qs::QuadricLandmark> landmarks;
  for (const auto& [id, l] : mapOf(world))
    landmarks.push_back(l);
  qs::QuadricMapper mapper;
  mapper.loadLandmarks(landmarks, /*fixed=*/true);
  qs::TrackingRecovery recovery;
  recovery.trackingLost(static_cast<int>(landmarks.size()));
  std::mt19937 rng(9);
  const Eigen::Isometry3d T_world_camera = viewsSeeing(world, 5).at(3);
  const qs::RecoveryRelocalisation step = qs::relocaliseWhileRecovering(
      &recovery, &mapper, observe(world, T_world_camera, rng), T_world_camera,
      Eigen::Isometry3d::Identity());
  ASSERT_TRUE(step.attempted);
  ASSERT_TRUE(step.result.found) << step.result.message;
  EXPECT_FALSE(step.reanchored);
  EXPECT_EQ(recovery.relocalisationAttempts(), 1);
  EXPECT_EQ(recovery.relocalisations(), 0);
}

TEST(QuadricMapperRelocalise, RefusesANonRigidCorrection) {
  qs::QuadricMapper mapper;
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.linear() *= 2.0;
  EXPECT_THROW(mapper.relocalise(bad), std::invalid_argument);
}
