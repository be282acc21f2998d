#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/odometry/quadric_motion_guess.h"
#include "synthetic_scene.h"

namespace quadric_slam {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A room corner with furniture, in the world frame: floor, two walls, a table top, a cabinet front,
// a column (cylinder), a ball (sphere) and a lamp shade (cone).
std::vector<QuadricModel> roomSurfaces() {
  std::vector<QuadricModel> s;
  s.push_back(quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0.0}));   // floor
  s.push_back(quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 3.0}));   // wall x = 3
  s.push_back(quadricFromShape(PlaneShape{Eigen::Vector3d::UnitY(), 3.5}));   // wall y = 3.5
  s.push_back(quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0.75}));  // table top
  s.push_back(quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 2.2}));   // cabinet front
  s.push_back(quadricFromShape(
      CylinderShape{Eigen::Vector3d(1.8, 2.0, 0.0), Eigen::Vector3d::UnitZ(), 0.15}));
  s.push_back(quadricFromShape(SphereShape{Eigen::Vector3d(1.5, 1.2, 0.9), 0.12}));
  s.push_back(quadricFromShape(
      ConeShape{Eigen::Vector3d(2.0, 2.6, 1.6), -Eigen::Vector3d::UnitZ(), 0.5}));
  return s;
}

QuadricModel inCamera(const QuadricModel& world, const Eigen::Isometry3d& T_world_camera) {
  return QuadricModel(world.quadricClass(), T_world_camera.inverse() * world.pose(), world.scale());
}

// The surfaces as one camera sees them: each observation in the camera frame, with a little noise
// on its pose (the segmenter's fit), 5000 supporting points.
std::vector<QuadricMeasurement> observe(const std::vector<QuadricModel>& world,
                                        const Eigen::Isometry3d& T_world_camera,
                                        std::mt19937& rng, double noise = 0.0) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<QuadricMeasurement> out;
  for (const QuadricModel& q : world) {
    QuadricMeasurement m;
    const Eigen::Vector3d rotation_noise(n(rng), n(rng), n(rng));
    const Eigen::Vector3d translation_noise(n(rng), n(rng), n(rng));
    Eigen::Isometry3d jitter = Eigen::Isometry3d::Identity();
    jitter.linear() =
        Eigen::AngleAxisd(noise * 0.3 * rotation_noise.norm(), rotation_noise.normalized())
            .toRotationMatrix();
    jitter.translation() = noise * translation_noise;
    const QuadricModel camera = inCamera(q, T_world_camera);
    m.quadric_camera = QuadricModel(camera.quadricClass(), jitter * camera.pose(), camera.scale());
    m.num_points = 5000;
    out.push_back(m);
  }
  return out;
}

Eigen::Isometry3d cameraAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  return synthetic::lookAt(eye, target);
}

void expectNear(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth,
                double max_translation, double max_rotation) {
  const Eigen::Isometry3d error = truth.inverse() * estimate;
  EXPECT_LT(error.translation().norm(), max_translation);
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle(), max_rotation);
}

TEST(QuadricMotionGuess, RecoversALargeStepFromAnIdentityPrior) {
  std::mt19937 rng(3);
  const std::vector<QuadricModel> room = roomSurfaces();
  // 25 cm and about 15 degrees between the two frames: far outside ICP's basin.
  const Eigen::Isometry3d T_world_reference =
      cameraAt(Eigen::Vector3d(0.2, 0.3, 1.4), Eigen::Vector3d(2.5, 2.5, 0.8));
  const Eigen::Isometry3d T_world_current =
      cameraAt(Eigen::Vector3d(0.4, 0.15, 1.45), Eigen::Vector3d(3.0, 1.5, 0.6));
  const Eigen::Isometry3d truth = T_world_reference.inverse() * T_world_current;
  ASSERT_GT(truth.translation().norm(), 0.2);
  ASSERT_GT(Eigen::AngleAxisd(truth.linear()).angle(), 10 * kDeg);

  const QuadricMotionGuess guess =
      QuadricMotionGuesser().guess(observe(room, T_world_reference, rng),
                                   observe(room, T_world_current, rng), Eigen::Isometry3d::Identity());
  ASSERT_TRUE(guess.found) << guess.message;
  expectNear(guess.T_reference_current, truth, 1e-6, 1e-6);
  EXPECT_EQ(guess.supporting_surfaces, static_cast<int>(room.size()));
  EXPECT_FALSE(guess.translation_from_prior);
}

// Parallel surfaces at different offsets (a table top above the floor) share one rotation but give
// different lines of translations. When the largest surface of each frame is a different one of
// them, the first pair tried under that rotation matches the table top with the floor: the guess
// must still try the line of the right match rather than keep the rotation's first line (which
// three surfaces agree with, 0.75 m off).
TEST(QuadricMotionGuess, TriesEveryLineOfARotationSharedByParallelSurfaces) {
  std::mt19937 rng(11);
  const std::vector<QuadricModel> room = {
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0.0}),    // floor
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0.75}),   // table top
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 3.0}),    // wall x = 3
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitY(), 3.5})};   // wall y = 3.5
  const Eigen::Isometry3d T_world_reference =
      cameraAt(Eigen::Vector3d(0.2, 0.3, 1.4), Eigen::Vector3d(2.5, 2.5, 0.8));
  const Eigen::Isometry3d T_world_current =
      cameraAt(Eigen::Vector3d(0.4, 0.2, 1.5), Eigen::Vector3d(2.7, 2.2, 0.7));
  const Eigen::Isometry3d truth = T_world_reference.inverse() * T_world_current;
  std::vector<QuadricMeasurement> reference = observe(room, T_world_reference, rng);
  std::vector<QuadricMeasurement> current = observe(room, T_world_current, rng);
  // The floor fills the reference view, the table top the current one.
  reference[0].num_points = 40000;
  reference[1].num_points = 3000;
  current[0].num_points = 3000;
  current[1].num_points = 40000;

  const QuadricMotionGuess guess =
      QuadricMotionGuesser().guess(reference, current, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(guess.found) << guess.message;
  expectNear(guess.T_reference_current, truth, 1e-6, 1e-6);
  EXPECT_EQ(guess.supporting_surfaces, 4);
}

TEST(QuadricMotionGuess, ToleratesFitNoiseMissingAndSpuriousSurfaces) {
  std::mt19937 rng(5);
  const std::vector<QuadricModel> room = roomSurfaces();
  const Eigen::Isometry3d T_world_reference =
      cameraAt(Eigen::Vector3d(0.2, 0.3, 1.4), Eigen::Vector3d(2.5, 2.5, 0.8));
  const Eigen::Isometry3d T_world_current =
      cameraAt(Eigen::Vector3d(0.35, 0.1, 1.5), Eigen::Vector3d(2.8, 2.1, 0.9));
  const Eigen::Isometry3d truth = T_world_reference.inverse() * T_world_current;

  std::vector<QuadricMeasurement> reference = observe(room, T_world_reference, rng, 0.004);
  std::vector<QuadricMeasurement> current = observe(room, T_world_current, rng, 0.004);
  reference.erase(reference.begin() + 3);  // the table top left the reference view
  current.erase(current.begin() + 6);      // the ball is hidden in the current one
  // Spurious planes in each frame, and a fragment of the far wall seen twice.
  current.push_back(observe({quadricFromShape(PlaneShape{Eigen::Vector3d(0.6, 0.8, 0.0), 2.0})},
                            T_world_current, rng)[0]);
  reference.push_back(observe({quadricFromShape(PlaneShape{Eigen::Vector3d(0, 0.6, 0.8), 1.3})},
                              T_world_reference, rng)[0]);
  current.push_back(observe({room[1]}, T_world_current, rng, 0.004)[0]);

  const QuadricMotionGuess guess =
      QuadricMotionGuesser().guess(reference, current, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(guess.found) << guess.message;
  expectNear(guess.T_reference_current, truth, 0.02, 1.0 * kDeg);
  EXPECT_GE(guess.supporting_surfaces, 6);
}

TEST(QuadricMotionGuess, APriorNearTheTruthPicksItAmongSymmetricSolutions) {
  // A square room (walls at x, y = +-2) and its floor: a 90-degree turn about the vertical maps it
  // onto itself, so only the prior tells the two apart.
  std::mt19937 rng(7);
  std::vector<QuadricModel> room = {
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0.0}),
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 2.0}),
      quadricFromShape(PlaneShape{-Eigen::Vector3d::UnitX(), 2.0}),
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitY(), 2.0}),
      quadricFromShape(PlaneShape{-Eigen::Vector3d::UnitY(), 2.0})};
  const Eigen::Isometry3d T_world_reference =
      cameraAt(Eigen::Vector3d(0.0, 0.0, 1.2), Eigen::Vector3d(2.0, 1.0, 0.2));
  const Eigen::Isometry3d T_world_current =
      cameraAt(Eigen::Vector3d(0.1, 0.1, 1.2), Eigen::Vector3d(2.0, 1.5, 0.2));
  const Eigen::Isometry3d truth = T_world_reference.inverse() * T_world_current;
  const QuadricMotionGuess guess = QuadricMotionGuesser().guess(
      observe(room, T_world_reference, rng), observe(room, T_world_current, rng), truth);
  ASSERT_TRUE(guess.found) << guess.message;
  expectNear(guess.T_reference_current, truth, 1e-6, 1e-6);
}

TEST(QuadricMotionGuess, TwoPlanesLeaveOneDirectionToThePrior) {
  // A floor and one wall fix the rotation and two translation directions; the third (along the
  // wall, parallel to the floor) comes from the prior.
  std::mt19937 rng(11);
  const std::vector<QuadricModel> corner = {
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0.0}),
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 3.0})};
  const Eigen::Isometry3d T_world_reference =
      cameraAt(Eigen::Vector3d(0.0, 0.0, 1.2), Eigen::Vector3d(3.0, 0.5, 0.5));
  const Eigen::Isometry3d T_world_current =
      cameraAt(Eigen::Vector3d(0.2, 0.1, 1.3), Eigen::Vector3d(3.0, 0.8, 0.4));
  const Eigen::Isometry3d truth = T_world_reference.inverse() * T_world_current;
  QuadricMotionGuesser::Params params;
  params.min_supporting_surfaces = 2;
  const QuadricMotionGuess guess = QuadricMotionGuesser(params).guess(
      observe(corner, T_world_reference, rng), observe(corner, T_world_current, rng),
      Eigen::Isometry3d::Identity());
  ASSERT_TRUE(guess.found) << guess.message;
  EXPECT_TRUE(guess.translation_from_prior);
  // Rotation exact; the translation's component along the free direction (world y, seen from the
  // reference camera) is the prior's, zero; the other two are exact.
  const Eigen::Vector3d free_direction = T_world_reference.linear().transpose() * Eigen::Vector3d::UnitY();
  EXPECT_LT(Eigen::AngleAxisd(guess.T_reference_current.linear() * truth.linear().transpose()).angle(),
            1e-6);
  EXPECT_NEAR(free_direction.dot(guess.T_reference_current.translation()), 0.0, 1e-4);
  const Eigen::Vector3d constrained = truth.translation() - free_direction * free_direction.dot(truth.translation());
  EXPECT_LT((guess.T_reference_current.translation() -
             free_direction * free_direction.dot(guess.T_reference_current.translation()) - constrained)
                .norm(),
            1e-4);
}

TEST(QuadricMotionGuess, SaysWhyWhenTheSurfacesCannotFixTheRotation) {
  std::mt19937 rng(13);
  const std::vector<QuadricModel> parallel = {
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 2.0}),
      quadricFromShape(PlaneShape{Eigen::Vector3d::UnitX(), 3.0})};
  const Eigen::Isometry3d T = cameraAt(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(3, 0, 1));
  const QuadricMotionGuess guess = QuadricMotionGuesser().guess(
      observe(parallel, T, rng), observe(parallel, T, rng), Eigen::Isometry3d::Identity());
  EXPECT_FALSE(guess.found);
  EXPECT_NE(guess.message.find("non-parallel"), std::string::npos) << guess.message;
}

TEST(QuadricMotionGuess, ParamsAreValidated) {
  QuadricMotionGuesser::Params p;
  p.max_angle_difference = 0.0;
  EXPECT_THROW(QuadricMotionGuesser{p}, std::invalid_argument);
  p = {};
  p.min_supporting_surfaces = 1;
  EXPECT_THROW(QuadricMotionGuesser{p}, std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam
