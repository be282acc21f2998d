#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>

#include "quadric_slam/io/trajectory_io.h"

using quadric_slam::StampedPose;
using quadric_slam::Trajectory;

namespace {

std::string errorOf(const std::string& text) {
  std::istringstream in(text);
  try {
    quadric_slam::parseTumTrajectory(in, "traj.txt");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(TrajectoryIo, ParsesCommentsSeparatorsAndNormalisesQuaternions) {
  std::istringstream in(
      "# ground truth trajectory\n"
      "\n"
      "1305031098.6659 1.3563 0.6305 1.6380 0 0 0 2\n"
      "1.5,\t1,2,3, 0,0,0.7071067811865476,0.7071067811865476\r\n"
      "   # indented comment\n");
  const Trajectory t = quadric_slam::parseTumTrajectory(in, "x");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_DOUBLE_EQ(t[0].stamp, 1305031098.6659);
  EXPECT_TRUE(t[0].T_world_sensor.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_TRUE(t[0].T_world_sensor.translation().isApprox(Eigen::Vector3d(1.3563, 0.6305, 1.638)));
  // 90 degrees about z: the sensor x axis is the world y axis.
  EXPECT_TRUE((t[1].T_world_sensor.linear() * Eigen::Vector3d::UnitX())
                  .isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE(t[1].T_world_sensor.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(TrajectoryIo, MalformedLinesNameFileAndLine) {
  const std::string few = errorOf("# c\n1 2 3 4 0 0 0 1\n2 3 4 5 0 0 1\n");
  EXPECT_NE(few.find("traj.txt:3:"), std::string::npos) << few;
  EXPECT_NE(few.find("expected 8 fields"), std::string::npos) << few;
  const std::string nan = errorOf("1 2 3 4 0 0 0 1\n2 x 4 5 0 0 0 1\n");
  EXPECT_NE(nan.find("traj.txt:2:"), std::string::npos) << nan;
  EXPECT_NE(nan.find("tx"), std::string::npos) << nan;
  const std::string zero_q = errorOf("1 2 3 4 0 0 0 0\n");
  EXPECT_NE(zero_q.find("traj.txt:1: quaternion"), std::string::npos) << zero_q;
  EXPECT_NE(errorOf("1 2 3 4 0 0 0 inf\n").find("qw"), std::string::npos);
  EXPECT_THROW(quadric_slam::readTumTrajectory("/nonexistent/dir/traj.txt"), std::runtime_error);
}

TEST(TrajectoryIo, WriteThenReadRoundTrips) {
  Trajectory t;
  for (int k = 0; k < 5; ++k) {
    StampedPose p;
    p.stamp = 1341847980.723020 + 0.033 * k;
    p.T_world_sensor.linear() =
        Eigen::AngleAxisd(0.4 * k - 1.0, Eigen::Vector3d(1, -2, 0.5).normalized())
            .toRotationMatrix();
    p.T_world_sensor.translation() = Eigen::Vector3d(0.1 * k, -2.5 + k, 1e-3 * k * k);
    t.push_back(p);
  }
  const std::string path = ::testing::TempDir() + "/trajectory_io_roundtrip.txt";
  quadric_slam::writeTumTrajectory(t, path, "written by the test");
  const Trajectory back = quadric_slam::readTumTrajectory(path);
  std::remove(path.c_str());
  ASSERT_EQ(back.size(), t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    EXPECT_NEAR(back[k].stamp, t[k].stamp, 1e-6);
    EXPECT_TRUE(back[k].T_world_sensor.isApprox(t[k].T_world_sensor, 1e-8)) << k;
  }
}

TEST(TrajectoryIo, PoseByPoseWriterGivesTheSameFile) {
  Trajectory t;
  for (int k = 0; k < 4; ++k) {
    StampedPose p;
    p.stamp = 100.0 + 0.1 * k;
    p.T_world_sensor.linear() =
        Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
    p.T_world_sensor.translation() = Eigen::Vector3d(k, -0.5 * k, 2.0);
    t.push_back(p);
  }
  const std::string path = ::testing::TempDir() + "/trajectory_io_writer.txt";
  {
    quadric_slam::TumTrajectoryWriter writer(path, "written pose by pose");
    for (const StampedPose& p : t)
      writer.append(p);
    // Each pose is on disk as soon as it is appended (a long run can be watched or cut short).
    EXPECT_EQ(quadric_slam::readTumTrajectory(path).size(), t.size());
  }
  std::ifstream in(path);
  const std::string streamed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ostringstream whole;
  quadric_slam::writeTumTrajectory(t, whole, "written pose by pose");
  EXPECT_EQ(streamed, whole.str());
  std::remove(path.c_str());
  EXPECT_THROW(quadric_slam::TumTrajectoryWriter("/nonexistent-dir/x.txt"), std::runtime_error);
}
