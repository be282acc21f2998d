// SlidingWindow: the gauge (first keyframe fixed, later the oldest pose held by a prior), a small
// window converging to the truth, sliding (size bound, landmarks leaving keep their estimate) and
// the folded landmark priors taking over when a landmark is seen again; a merged landmark's
// observations and prior moving to the survivor.
#include <gtest/gtest.h>

#include <deque>
#include <random>

#include "quadric_slam/geometry/symmetry.h"
#include "quadric_slam/mapping/window.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

// Landmarks straight from measurements (min_observations 1), for window tests.
LandmarkRegistry::Params immediateLandmarks() {
  LandmarkRegistry::Params p;
  p.min_observations = 1;
  return p;
}

// Poses along a line looking at a small scene of every class.
std::vector<Eigen::Isometry3d> cameraLine(int n) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i)
    poses.push_back(test::lookAlong(Eigen::Vector3d(-2.5, -0.6 + 0.12 * i, 1.2),
                                    Eigen::Vector3d(1.0, 0.0, -0.4)));
  return poses;
}

std::vector<test::TrueLandmark> smallScene() {
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Z = Eigen::Vector3d::UnitZ();
  return {test::plane(Eigen::Vector3d(0, 0, 0), Z, X, 3, 3),
          test::plane(Eigen::Vector3d(1.5, 0, 1), -X, Eigen::Vector3d::UnitY(), 3, 1),
          test::sphere(Eigen::Vector3d(0, -0.5, 0.3), 0.25),
          test::cylinder(Eigen::Vector3d(0.3, 0.5, 0.5), Z, 0.12, 0.5),
          test::cone(Eigen::Vector3d(-0.3, 0.1, 0.8), -Z, 0.3, 0.5)};
}

Keyframe keyframeAt(int index, const Eigen::Isometry3d& T_true, const Eigen::Isometry3d& T_previous,
                    const Eigen::Isometry3d& T_estimate) {
  Keyframe kf;
  kf.frame_index = index;
  kf.stamp = index * 0.1;
  kf.T_map_camera = T_estimate;
  kf.T_odom_camera = T_true;
  kf.T_previous_this = T_previous.inverse() * T_true;
  kf.increment_covariance = Matrix6d::Identity() * 1e-4;
  return kf;
}

TEST(SlidingWindow, ParamsValidate) {
  SlidingWindow::Params p;
  EXPECT_NO_THROW(p.validate());
  p.size = 1;
  EXPECT_THROW(SlidingWindow{p}, std::invalid_argument);
  p = {};
  p.max_iterations = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.oldest_pose_rotation_sigma = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.observation_huber = -1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

// Exact measurements, perfect odometry, perturbed initial poses and landmarks: the window returns
// to the truth, with the first keyframe (the map frame) untouched.
TEST(SlidingWindow, SmallWindowConvergesWithTheFirstKeyframeFixed) {
  const std::vector<test::TrueLandmark> scene = smallScene();
  const std::vector<Eigen::Isometry3d> poses = cameraLine(5);
  std::mt19937 rng(51);
  LandmarkRegistry map(immediateLandmarks());
  // Landmarks from perturbed measurements at the first pose (1 cm / 0.5 deg scale errors).
  std::vector<QuadricMeasurement> first;
  for (const test::TrueLandmark& l : scene)
    first.push_back(test::measure(l, poses[0], rng, 2.0));
  const MapUpdate u = map.integrate(1, 0.1, first, poses[0], Matrix6d::Zero());
  ASSERT_EQ(u.promoted.size(), scene.size());

  SlidingWindow window;
  for (int i = 0; i < 5; ++i) {
    Vector6d noise;
    for (int j = 0; j < 6; ++j)
      noise[j] = std::normal_distribution<double>(0, 0.02)(rng);
    Keyframe kf = keyframeAt(i + 1, poses[i], poses[std::max(i - 1, 0)],
                             i == 0 ? poses[0] : plus(poses[i], noise));
    for (size_t l = 0; l < scene.size(); ++l)
      kf.observations.push_back({u.promoted[l], test::measure(scene[l], poses[i], rng, 0.0)});
    window.addKeyframe(kf, map);
  }
  const WindowStatistics s = window.optimize(&map);
  EXPECT_TRUE(s.solution_usable);
  EXPECT_EQ(s.keyframes, 5);
  EXPECT_EQ(s.pose_priors, 0);  // the first keyframe is fixed instead
  EXPECT_EQ(s.odometry_factors, 4);
  EXPECT_EQ(s.observation_factors, 25);
  EXPECT_EQ(s.landmark_blocks, 5);
  EXPECT_EQ(s.parameter_blocks, 10);
  EXPECT_LT(s.final_cost, 1e-8 * std::max(1.0, s.initial_cost));
  EXPECT_TRUE(window.keyframes()[0].T_map_camera.isApprox(poses[0], 1e-12));
  for (int i = 0; i < 5; ++i)
    EXPECT_LT(minus(window.keyframes()[i].T_map_camera, poses[i]).norm(), 1e-6) << i;
  for (size_t l = 0; l < scene.size(); ++l) {
    const QuadricLandmark& landmark = map.landmark(u.promoted[l]);
    EXPECT_LT(surfaceMinus(landmark.quadric_map, scene[l].quadric_world).norm(), 1e-6) << l;
    EXPECT_EQ(landmark.covariance.rows(), minimalDimension(landmark.quadric_map.quadricClass()));
  }
}

// Size 3: the window never holds more than 3 keyframes; once the first has left the oldest pose
// gets a prior; a landmark seen only by keyframes that left is out of the problem and keeps its
// estimate; seen again, it re-enters with its folded prior.
TEST(SlidingWindow, SlidesAndFoldsLeavingObservationsIntoPriors) {
  const std::vector<test::TrueLandmark> scene = smallScene();
  const std::vector<Eigen::Isometry3d> poses = cameraLine(8);
  std::mt19937 rng(52);
  LandmarkRegistry map(immediateLandmarks());
  std::vector<QuadricMeasurement> first;
  for (const test::TrueLandmark& l : scene)
    first.push_back(test::measure(l, poses[0], rng));
  const MapUpdate u = map.integrate(1, 0.1, first, poses[0], Matrix6d::Zero());
  const int sphere_id = u.promoted[2];

  SlidingWindow::Params p;
  p.size = 3;
  p.schur_marginalization = false;  // the folded priors
  SlidingWindow window(p);
  QuadricModel sphere_when_left;
  for (int i = 0; i < 8; ++i) {
    Keyframe kf = keyframeAt(i + 1, poses[i], poses[std::max(i - 1, 0)], poses[i]);
    for (size_t l = 0; l < scene.size(); ++l) {
      const bool sphere_visible = i < 2 || i == 7;  // seen at the start and at the end only
      if (static_cast<int>(l) == 2 && !sphere_visible)
        continue;
      kf.observations.push_back({u.promoted[l], test::measure(scene[l], poses[i], rng)});
    }
    window.addKeyframe(kf, map);
    const WindowStatistics s = window.optimize(&map);
    EXPECT_LE(s.keyframes, 3);
    EXPECT_EQ(s.pose_priors, i >= 3 ? 1 : 0) << i;
    if (i >= 4 && i < 7) {
      EXPECT_FALSE(window.containsLandmark(sphere_id)) << i;
      EXPECT_EQ(s.landmark_blocks, 4);
      if (i == 4)
        sphere_when_left = map.landmark(sphere_id).quadric_map;
      EXPECT_TRUE(map.landmark(sphere_id).quadric_map.matrix().isApprox(sphere_when_left.matrix()))
          << "a landmark out of the window keeps its estimate";
    }
    if (i >= 3) {
      // Every landmark in the window has a prior from the keyframes that left.
      EXPECT_EQ(s.landmark_priors, s.landmark_blocks) << i;
      EXPECT_EQ(s.residual_blocks,
                s.odometry_factors + s.pose_priors + s.observation_factors + s.landmark_priors);
    }
  }
  EXPECT_TRUE(window.containsLandmark(sphere_id));
  EXPECT_EQ(window.keyframes().front().frame_index, 6);
  EXPECT_LT((sphereShape(map.landmark(sphere_id).quadric_map).center -
             sphereShape(scene[2].quadric_world).center)
                .norm(),
            0.01);
}

// A prior folded from many leaving keyframes holds a landmark against one wrong measurement
// (a 10 cm offset), where a window without that history follows the outlier much further (the
// outlier is shared between the landmark and the last pose).
TEST(SlidingWindow, FoldedAndMarginalisedPriorsKeepTheHistory) {
  const test::TrueLandmark wall = test::plane(Eigen::Vector3d(1.5, 0, 1), -Eigen::Vector3d::UnitX(),
                                              Eigen::Vector3d::UnitY(), 3, 1);
  const std::vector<Eigen::Isometry3d> poses = cameraLine(12);
  auto finalOffsetError = [&](int keyframes_before, bool schur) {
    std::mt19937 rng(53);
    LandmarkRegistry map(immediateLandmarks());
    const MapUpdate u = map.integrate(1, 0.1, {test::measure(wall, poses[0], rng, 0.0)}, poses[0],
                                      Matrix6d::Zero());
    SlidingWindow::Params p;
    p.size = 2;
    p.observation_huber = 0;
    p.schur_marginalization = schur;
    SlidingWindow window(p);
    const int first = 11 - keyframes_before;
    for (int i = first; i < 12; ++i) {
      Keyframe kf = keyframeAt(i + 1, poses[i], poses[std::max(i - 1, 0)], poses[i]);
      QuadricMeasurement m = test::measure(wall, poses[i], rng, 0.0);
      if (i == 11) {  // the last measurement is off by 10 cm along the normal
        Eigen::VectorXd d = Eigen::VectorXd::Zero(3);
        d[0] = 0.1;
        m.quadric_camera = m.quadric_camera.plusMinimal(d);
      }
      kf.observations.push_back({u.promoted[0], m});
      window.addKeyframe(kf, map);
      window.optimize(&map);
    }
    return std::abs(planeShape(map.landmark(u.promoted[0]).quadric_map).offset -
                    planeShape(wall.quadric_world).offset);
  };
  for (bool schur : {false, true}) {
    const double without_history = finalOffsetError(1, schur);
    const double with_history = finalOffsetError(10, schur);
    std::cout << (schur ? "marginalised" : "folded")
              << ": plane offset error after a 10 cm outlier: window only " << without_history
              << " m, with 9 keyframes that left " << with_history << " m\n";
    EXPECT_GT(without_history, 0.005) << schur;
    EXPECT_LT(with_history, 0.3 * without_history) << schur;
  }
}

// A landmark merged into another (mapping/landmark_merger.h): its observations in the window
// become factors on the survivor, its folded prior goes with them, and the next solve has one
// block for the surface.
TEST(SlidingWindow, MergedLandmarkObservationsMoveToTheSurvivor) {
  const test::TrueLandmark floor = test::plane(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ(),
                                               Eigen::Vector3d::UnitX(), 3, 3);
  const test::TrueLandmark ball = test::sphere(Eigen::Vector3d(0, -0.5, 0.3), 0.25);
  const std::vector<Eigen::Isometry3d> poses = cameraLine(6);
  std::mt19937 rng(53);
  LandmarkRegistry map(immediateLandmarks());
  for (int id : {1, 2}) {  // the floor twice (two fragments that became landmarks)
    QuadricLandmark l;
    l.id = id;
    l.quadric_map = floor.quadric_world;
    l.extent_min = floor.extent.min;
    l.extent_max = floor.extent.max;
    map.insertLandmark(l);
  }
  QuadricLandmark l3;
  l3.id = 3;
  l3.quadric_map = ball.quadric_world;
  map.insertLandmark(l3);
  SlidingWindow::Params p;
  p.size = 4;  // two keyframes leave: landmark 2's observations are folded into a prior
  p.schur_marginalization = false;
  SlidingWindow window(p);
  for (int i = 0; i < 6; ++i) {
    Keyframe kf = keyframeAt(i + 1, poses[i], poses[std::max(i - 1, 0)], poses[i]);
    kf.observations.push_back({1, test::measure(floor, poses[i], rng)});
    kf.observations.push_back({2, test::measure(floor, poses[i], rng)});
    kf.observations.push_back({3, test::measure(ball, poses[i], rng)});
    window.addKeyframe(kf, map);
  }
  EXPECT_EQ(window.optimize(&map).landmark_priors, 3);
  window.mergeLandmark(2, 1, map.landmark(1).quadric_map);
  map.absorbLandmark(2, map.landmark(1));
  EXPECT_FALSE(window.containsLandmark(2));
  EXPECT_EQ(window.landmarkIds(), (std::set<int>{1, 3}));
  for (const Keyframe& kf : window.keyframes())
    for (const WindowObservation& o : kf.observations)
      EXPECT_NE(o.landmark_id, 2);
  const WindowStatistics s = window.optimize(&map);
  EXPECT_TRUE(s.solution_usable);
  EXPECT_EQ(s.landmark_blocks, 2);
  EXPECT_EQ(s.observation_factors, 12);  // 4 keyframes x 3 observations, now on 2 landmarks
  EXPECT_EQ(s.landmark_priors, 2);       // landmark 2's prior fused into landmark 1's
  EXPECT_LT(surfaceMinus(map.landmark(1).quadric_map, floor.quadric_world).norm(), 0.01);
}

// The merge with the marginalisation prior: a merged landmark that is a variable of the prior is
// eliminated from it, the survivor keeps its factors, and the next solve has one block for the
// surface.
TEST(SlidingWindow, MergedLandmarkLeavesTheMarginalisationPrior) {
  const test::TrueLandmark floor = test::plane(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ(),
                                               Eigen::Vector3d::UnitX(), 3, 3);
  const test::TrueLandmark ball = test::sphere(Eigen::Vector3d(0, -0.5, 0.3), 0.25);
  const std::vector<Eigen::Isometry3d> poses = cameraLine(6);
  std::mt19937 rng(54);
  LandmarkRegistry map(immediateLandmarks());
  for (int id : {1, 2}) {
    QuadricLandmark l;
    l.id = id;
    l.quadric_map = floor.quadric_world;
    l.extent_min = floor.extent.min;
    l.extent_max = floor.extent.max;
    map.insertLandmark(l);
  }
  QuadricLandmark l3;
  l3.id = 3;
  l3.quadric_map = ball.quadric_world;
  map.insertLandmark(l3);
  SlidingWindow::Params p;
  p.size = 4;
  SlidingWindow window(p);
  for (int i = 0; i < 6; ++i) {
    Keyframe kf = keyframeAt(i + 1, poses[i], poses[std::max(i - 1, 0)], poses[i]);
    kf.observations.push_back({1, test::measure(floor, poses[i], rng)});
    kf.observations.push_back({2, test::measure(floor, poses[i], rng)});
    kf.observations.push_back({3, test::measure(ball, poses[i], rng)});
    window.addKeyframe(kf, map);
    const WindowStatistics s = window.optimize(&map);
    EXPECT_EQ(s.marginalized_keyframes, i >= 4 ? 1 : 0) << i;
    EXPECT_EQ(s.marginalization_priors, i >= 5 ? 1 : 0) << i;
    EXPECT_EQ(s.pose_priors, 0) << i;  // the gauge: the first keyframe, then the prior
  }
  EXPECT_EQ(window.keyframes().size(), 4u);
  ASSERT_GE(window.marginalizationPrior().find(PriorVariable::Kind::kLandmark, 2), 0);
  window.mergeLandmark(2, 1, map.landmark(1).quadric_map);
  map.absorbLandmark(2, map.landmark(1));
  EXPECT_LT(window.marginalizationPrior().find(PriorVariable::Kind::kLandmark, 2), 0);
  EXPECT_GE(window.marginalizationPrior().find(PriorVariable::Kind::kLandmark, 1), 0);
  const WindowStatistics s = window.optimize(&map);
  EXPECT_TRUE(s.solution_usable);
  EXPECT_EQ(s.landmark_blocks, 2);
  EXPECT_EQ(s.observation_factors, 12);
  EXPECT_EQ(s.marginalization_priors, 1);
  EXPECT_LT(surfaceMinus(map.landmark(1).quadric_map, floor.quadric_world).norm(), 0.01);
}

// Size 3 with marginalisation: the window holds at most 3 keyframes after each solve (one more
// during it), no pose prior is ever needed (the prior carries the gauge), the prior's variables
// are window variables, and a landmark that left (eliminated) re-enters with its map covariance as
// a prior when it is seen again.
TEST(SlidingWindow, MarginalisesLeavingKeyframesIntoOnePrior) {
  const std::vector<test::TrueLandmark> scene = smallScene();
  const std::vector<Eigen::Isometry3d> poses = cameraLine(8);
  std::mt19937 rng(55);
  LandmarkRegistry map(immediateLandmarks());
  std::vector<QuadricMeasurement> first;
  for (const test::TrueLandmark& l : scene)
    first.push_back(test::measure(l, poses[0], rng));
  const MapUpdate u = map.integrate(1, 0.1, first, poses[0], Matrix6d::Zero());
  const int sphere_id = u.promoted[2];
  SlidingWindow::Params p;
  p.size = 3;
  SlidingWindow window(p);
  for (int i = 0; i < 8; ++i) {
    Keyframe kf = keyframeAt(i + 1, poses[i], poses[std::max(i - 1, 0)], poses[i]);
    for (size_t l = 0; l < scene.size(); ++l) {
      if (static_cast<int>(l) == 2 && !(i < 2 || i == 7))
        continue;  // the sphere is seen at the start and at the end only
      kf.observations.push_back({u.promoted[l], test::measure(scene[l], poses[i], rng)});
    }
    window.addKeyframe(kf, map);
    const WindowStatistics s = window.optimize(&map);
    EXPECT_TRUE(s.solution_usable) << i;
    EXPECT_LE(s.keyframes, 4) << i;
    EXPECT_LE(window.keyframes().size(), 3u) << i;
    EXPECT_EQ(s.pose_priors, 0) << i;
    EXPECT_EQ(s.marginalization_priors, i >= 4 ? 1 : 0) << i;
    const LinearizedPrior& prior = window.marginalizationPrior();
    if (i >= 3) {
      ASSERT_FALSE(prior.empty()) << i;
      for (const PriorVariable& v : prior.variables) {
        if (v.kind == PriorVariable::Kind::kLandmark)
          EXPECT_TRUE(window.containsLandmark(v.id)) << i;
        else
          EXPECT_GE(v.id, window.keyframes().front().frame_index) << i;
      }
      EXPECT_EQ(prior.J.cols(), prior.tangentSize());
    }
    if (i >= 4 && i < 7) {
      // The sphere's last observation (keyframe 2) has left: it was eliminated.
      EXPECT_FALSE(window.containsLandmark(sphere_id)) << i;
      EXPECT_LT(prior.find(PriorVariable::Kind::kLandmark, sphere_id), 0) << i;
    }
    if (i == 7) {
      EXPECT_EQ(s.landmark_priors, 1);  // the sphere, back with its covariance
    }
  }
  EXPECT_LT((sphereShape(map.landmark(sphere_id).quadric_map).center -
             sphereShape(scene[2].quadric_world).center)
                .norm(),
            0.01);
  EXPECT_LT(minus(window.keyframes().back().T_map_camera, poses[7]).norm(), 0.02);
}

// The point of marginalising: on a small problem (5 surfaces of every class, 14 keyframes,
// drifting odometry, measurement noise), a window of 4 keyframes that marginalises the leaving
// ones ends where the full batch over all 14 keyframes ends, and closer than the window with the
// folded priors (which drops the odometry of leaving keyframes and holds the oldest pose by an
// arbitrary prior). Compared: every landmark (surface error in its minimal space) and the poses
// of the final window.
TEST(SlidingWindow, MarginalisationMatchesTheFullBatch) {
  const std::vector<test::TrueLandmark> scene = smallScene();
  const int n = 14;
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i)
    poses.push_back(test::lookAlong(Eigen::Vector3d(-2.5, -0.8 + 0.12 * i, 1.2),
                                    Eigen::Vector3d(1.0, 0.1 * std::sin(0.5 * i), -0.4)));
  std::mt19937 rng(56);
  const std::vector<Eigen::Isometry3d> odometry = test::driftingOdometry(poses, rng);
  std::vector<std::vector<WindowObservation>> observations(n);
  LandmarkRegistry start(immediateLandmarks());
  std::vector<QuadricMeasurement> first;
  for (const test::TrueLandmark& l : scene)
    first.push_back(test::measure(l, poses[0], rng));
  const MapUpdate u = start.integrate(1, 0.1, first, poses[0], Matrix6d::Zero());
  ASSERT_EQ(u.promoted.size(), scene.size());
  for (int i = 0; i < n; ++i)
    for (size_t l = 0; l < scene.size(); ++l)
      if (test::visible(scene[l], poses[i]))
        observations[i].push_back({u.promoted[l], test::measure(scene[l], poses[i], rng)});

  struct Result {
    LandmarkRegistry map;
    std::deque<Keyframe> window;
  };
  auto run = [&](int size, bool schur, bool every_keyframe) {
    Result r{start, {}};
    SlidingWindow::Params p;
    p.size = size;
    p.observation_huber = 0;  // least squares: the batch is the reference
    p.max_iterations = every_keyframe ? 20 : 100;
    p.schur_marginalization = schur;
    SlidingWindow window(p);
    for (int i = 0; i < n; ++i) {
      Keyframe kf;
      kf.frame_index = i + 1;
      kf.stamp = 0.1 * (i + 1);
      kf.T_odom_camera = odometry[i];
      kf.T_previous_this = i == 0 ? Eigen::Isometry3d::Identity()
                                  : Eigen::Isometry3d(odometry[i - 1].inverse() * odometry[i]);
      kf.increment_covariance = Matrix6d::Identity() * 1e-4;
      // Initialised from the previous estimate and the odometry (as the mapper does).
      kf.T_map_camera = i == 0 ? poses[0]
                               : Eigen::Isometry3d(window.keyframes().back().T_map_camera *
                                                   kf.T_previous_this);
      kf.observations = observations[i];
      window.addKeyframe(kf, r.map);
      if (every_keyframe || i == n - 1) {
        EXPECT_TRUE(window.optimize(&r.map).solution_usable);
      }
    }
    r.window = window.keyframes();
    return r;
  };
  const Result batch = run(n, true, false);
  ASSERT_EQ(batch.window.size(), static_cast<size_t>(n));
  const Result marginalised = run(4, true, true);
  const Result folded = run(4, false, true);

  auto landmarkError = [&](const Result& r) {
    double worst = 0.0;
    for (int id : u.promoted)
      worst = std::max(worst, surfaceMinus(r.map.landmark(id).quadric_map,
                                           batch.map.landmark(id).quadric_map)
                                  .norm());
    return worst;
  };
  auto poseError = [&](const Result& r) {
    double worst = 0.0;
    for (const Keyframe& kf : r.window)
      worst = std::max(
          worst, minus(kf.T_map_camera, batch.window[kf.frame_index - 1].T_map_camera).norm());
    return worst;
  };
  auto truthError = [&](const Result& r) {
    double worst = 0.0;
    for (const Keyframe& kf : r.window)
      worst = std::max(worst, minus(kf.T_map_camera, poses[kf.frame_index - 1]).norm());
    return worst;
  };
  std::cout << "against the full batch (max minimal-space error): marginalised landmarks "
            << landmarkError(marginalised) << " poses " << poseError(marginalised)
            << "; folded landmarks " << landmarkError(folded) << " poses " << poseError(folded)
            << " (batch poses against the truth " << truthError(batch) << ")\n";
  EXPECT_LT(landmarkError(marginalised), 2e-3);
  EXPECT_LT(poseError(marginalised), 2e-3);
  EXPECT_LT(landmarkError(marginalised), 0.5 * landmarkError(folded));
  EXPECT_LT(poseError(marginalised), 0.5 * poseError(folded));
}

}  // namespace
}  // namespace quadric_slam
