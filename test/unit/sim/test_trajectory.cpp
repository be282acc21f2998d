#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "quadric_slam/sim/trajectory.h"
#include "../test_data.h"

using namespace quadric_slam;

namespace {

StampedPose pose(double stamp, const Eigen::Vector3d& t, double angle) {
  StampedPose p;
  p.stamp = stamp;
  p.T_world_sensor.translation() = t;
  p.T_world_sensor.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).matrix();
  return p;
}

const std::string kFr1Desk =
    test::sharedData("tum_groundtruth/rgbd_dataset_freiburg1_desk-groundtruth.txt").string();

}  // namespace

TEST(Trajectory, InterpolatesLinearlyAndSlerps) {
  const std::vector<StampedPose> t = {pose(10.0, {0, 0, 0}, 0.0), pose(11.0, {1, 2, 3}, 1.0)};
  const Eigen::Isometry3d mid = interpolatePose(t, 10.25);
  EXPECT_NEAR((mid.translation() - Eigen::Vector3d(0.25, 0.5, 0.75)).norm(), 0, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(mid.rotation()).angle(), 0.25, 1e-12);
  EXPECT_THROW(interpolatePose(t, 9.99), std::out_of_range);
  EXPECT_THROW(interpolatePose(t, 11.01), std::out_of_range);
  EXPECT_NEAR((interpolatePose(t, 11.0).translation() - Eigen::Vector3d(1, 2, 3)).norm(), 0, 1e-12);
}

TEST(Trajectory, ResamplesAt30HzFromTheFirstStamp) {
  std::vector<StampedPose> t;
  for (int i = 0; i <= 100; ++i)
    t.push_back(pose(5.0 + 0.01 * i + 0.003 * (i % 2), {0.01 * i, 0, 0}, 0.0));
  const std::vector<StampedPose> frames = resampleTrajectory(t, 30.0, 10.0);
  ASSERT_EQ(frames.size(), 31u);  // 5.0 .. 6.0 s: k / 30 <= 1.0
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_NEAR(frames[k].stamp, 5.0 + k / 30.0, 1e-9);
    EXPECT_NEAR(frames[k].T_world_sensor.translation().x(),
                interpolatePose(t, frames[k].stamp).translation().x(), 1e-12);
  }
  EXPECT_EQ(resampleTrajectory(t, 30.0, 0.5).size(), 15u);
}

TEST(Trajectory, ReadsTheRealFr1DeskGroundTruth) {
  QS_SKIP_WITHOUT_SHARED_DATA(kFr1Desk, test::kFullGroundTruth);
  const std::vector<StampedPose> t = readDrivingTrajectory(kFr1Desk);
  ASSERT_EQ(t.size(), 2335u);
  EXPECT_NEAR(t.front().stamp, 1305031449.7996, 1e-4);
  EXPECT_NEAR(t.front().T_world_sensor.translation().x(), 1.2334, 1e-9);
  const std::vector<StampedPose> frames = resampleTrajectory(t, 30.0, 10.0);
  EXPECT_EQ(frames.size(), 300u);
  // Written back in TUM format, the first line keeps the file's values.
  std::ostringstream written;
  writeTumTrajectory({t.front()}, written);
  EXPECT_NE(written.str().find("\n1305031449.799600 1.2334 "), std::string::npos) << written.str();
}

TEST(Trajectory, SkipsRepeatedStampsOfTheRealFr2DeskFile) {
  const std::string path =
      test::sharedData("tum_groundtruth/rgbd_dataset_freiburg2_desk-groundtruth.txt").string();
  QS_SKIP_WITHOUT_SHARED_DATA(path, test::kFullGroundTruth);
  const std::vector<StampedPose> t = readDrivingTrajectory(path);
  EXPECT_GT(t.size(), 20000u);
  for (std::size_t k = 1; k < t.size(); ++k)
    ASSERT_GT(t[k].stamp, t[k - 1].stamp);
}

TEST(Trajectory, MalformedFilesNameTheLine) {
  const std::string path = testing::TempDir() + "/bad_trajectory.txt";
  auto errorOf = [&](const std::string& text) -> std::string {
    {
      std::ofstream out(path);
      out << text;
    }
    try {
      readDrivingTrajectory(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(errorOf("# comment\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n").find(":3:"),
            std::string::npos);
  const std::string decreasing =
      errorOf("1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n1.5 0 0 0 0 0 0 1\n");
  EXPECT_NE(decreasing.find("stamps must not decrease (1.5"), std::string::npos) << decreasing;
  EXPECT_EQ(errorOf("1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n"), "");
  EXPECT_NE(errorOf("1.0 0 0 0 0 0 0 1\n").find("fewer than two poses"), std::string::npos);
}

TEST(Trajectory, LookAtUsesTheOpticalConvention) {
  // Looking along world +x with z up: image x (right) = world -y, image y (down) = world -z.
  const Eigen::Isometry3d T = lookAt({0, 0, 1}, {2, 0, 1});
  EXPECT_NEAR((T.linear().col(2) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((T.linear().col(0) - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((T.linear().col(1) - Eigen::Vector3d(0, 0, -1)).norm(), 0, 1e-12);
  EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
}

TEST(Trajectory, HandheldMotionIsSeededSmoothAndLooksAtTheCentre) {
  HandheldTrajectory::Params p;
  const HandheldTrajectory motion(p);
  const Eigen::Vector3d centre(0.25, 0.85, 0.75);
  const std::vector<StampedPose> a = motion.generate(centre, 30.0, 10.0, 1);
  const std::vector<StampedPose> b = motion.generate(centre, 30.0, 10.0, 1);
  const std::vector<StampedPose> c = motion.generate(centre, 30.0, 10.0, 2);
  ASSERT_EQ(a.size(), 300u);
  double differs = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_NEAR(a[k].stamp, p.start_stamp + k / 30.0, 1e-6);
    EXPECT_TRUE(a[k].T_world_sensor.isApprox(b[k].T_world_sensor, 1e-15));
    differs = std::max(
        differs, (a[k].T_world_sensor.translation() - c[k].T_world_sensor.translation()).norm());
    // The optical axis passes near the centre of interest.
    const Eigen::Vector3d to_centre = centre - a[k].T_world_sensor.translation();
    const Eigen::Vector3d axis = a[k].T_world_sensor.linear().col(2);
    EXPECT_LT((to_centre - to_centre.dot(axis) * axis).norm(), 2 * p.gaze_wobble);
    const double distance = std::hypot(to_centre.x(), to_centre.y());
    EXPECT_NEAR(distance, p.distance, 2 * p.wobble);
    if (k > 0) {  // hand-held speeds: < 1.5 m/s, < 2 rad/s
      const Eigen::Isometry3d step = a[k - 1].T_world_sensor.inverse() * a[k].T_world_sensor;
      EXPECT_LT(step.translation().norm() * 30.0, 1.5);
      EXPECT_LT(Eigen::AngleAxisd(step.rotation()).angle() * 30.0, 2.0);
    }
  }
  EXPECT_GT(differs, 0.01);
  p.distance = 0.0;
  EXPECT_THROW(HandheldTrajectory{p}, std::invalid_argument);
}
