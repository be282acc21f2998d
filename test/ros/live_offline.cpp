// Checker for live_offline.test (the four nodelets in one manager) and
// live_offline_two_managers.test (the front end in one manager, the mapper in a second process, so
// that observations and their supporting points go over TCP): the live nodelet pipeline and the
// offline pipeline class QuadricSlam (the same config/*.yaml, read by loadSlamParams) on the same
// synthetic desk bag must give the same map and the same trajectories. The offline side is the
// offline runner run_bag (a thin shell over QuadricSlam), beside this checker; both maps are
// taken after the last frame through the same writer (the nodelet's ~save_map, run_bag's
// map.yaml; run_bag's offline batch refinement, which the live mapper does not have, is turned off
// with --no-batch). (The message QuadricMap and the core class of that name cannot meet in one
// translation unit: the pipeline runs in its own process.)
//
// The frames are published one at a time, each after the mapper's path has reached the previous
// one, so that the comparison is about the computation and not about frames dropped by a loaded
// machine.
#include <gtest/gtest.h>
#include <unistd.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <quadric_slam/SaveMap.h>
#include <ros/ros.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "frame_player.h"
#include "path_trajectory.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/ros/conversions.h"
#include "synthetic_bag.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;
using qs::test::spinUntil;

namespace {

constexpr double kSeconds = 4.0;  // 40 frames at 10 Hz: the camera moves ~0.5 m
constexpr double kRate = 10.0;
// Live and offline run the same stage classes with the same parameters on the same numbers: the
// results must agree to the rounding of the files they are compared through.
// The files hold 9 significant digits.
constexpr double kPositionTolerance = 1e-6;  // m
constexpr double kAngleTolerance = 1e-6;     // rad
constexpr double kScaleTolerance = 1e-6;     // relative

struct PoseDifference {
  double position = 0.0, angle = 0.0;
};
PoseDifference difference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return {(a.translation() - b.translation()).norm(),
          Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle()};
}

std::map<std::string, int> landmarksPerClass(const qs::MapFile& map) {
  std::map<std::string, int> out;
  for (const qs::MapFileQuadric& quadric : map.quadrics)
    ++out[quadric.quadric_class];
  return out;
}

using PoseByStamp = std::map<double, Eigen::Isometry3d>;

PoseByStamp byStamp(const qs::Trajectory& trajectory) {
  PoseByStamp out;
  for (const qs::StampedPose& pose : trajectory)
    out[pose.stamp] = pose.T_world_sensor;
  return out;
}

// A trajectory file rounds the stamp to microseconds: the poses are looked up by rounded stamp.
double roundedStamp(double stamp) { return std::round(stamp * 1e6) / 1e6; }

// Reconstruction points per landmark id in a PCD with a label field.
std::map<std::uint32_t, int> pointsPerLandmark(const std::string& pcd_path) {
  pcl::PointCloud<pcl::PointXYZL> cloud;
  if (pcl::io::loadPCDFile(pcd_path, cloud) != 0)
    ADD_FAILURE() << "cannot read " << pcd_path;
  std::map<std::uint32_t, int> out;
  for (const pcl::PointXYZL& point : cloud)
    ++out[point.label];
  return out;
}

struct SlamRun {
  qs::MapFile map;  // after the last frame
  std::map<std::uint32_t, int> reconstruction;  // points per landmark
  PoseByStamp T_map_camera, T_odom_camera;
};

// run_bag (the offline runner over QuadricSlam, installed beside this checker) on the bag, with
// the package's config/*.yaml.
SlamRun runOffline(const std::string& bag_path, const fs::path& out_dir) {
  const fs::path run_bag = fs::canonical("/proc/self/exe").parent_path() / "run_bag";
  const std::string command = run_bag.string() + " " + bag_path + " --out " + out_dir.string() +
                              " --config " + QUADRIC_SLAM_SOURCE_DIR +
                              "/config --quiet --no-rgb --no-batch > " +
                              (out_dir.parent_path() / "run_bag.log").string() + " 2>&1";
  SlamRun run;
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << "run_bag failed: " << command;
    return run;
  }
  run.map = qs::readMapYaml((out_dir / "map.yaml").string());
  run.reconstruction = pointsPerLandmark((out_dir / "reconstruction.pcd").string());
  run.T_map_camera = byStamp(qs::readTumTrajectory((out_dir / "trajectory.txt").string()));
  run.T_odom_camera = byStamp(qs::readTumTrajectory((out_dir / "trajectory_odom.txt").string()));
  return run;
}

class LiveOfflineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("live_offline_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    bag_path_ = (dir_ / "desk.bag").string();
    qs::test::writeDeskBag(bag_path_, kRate, kSeconds, 2);
    frames_ = qs::test::readBagDepthFrames(bag_path_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string bag_path_;
  qs::test::BagDepthFrames frames_;
};

TEST_F(LiveOfflineTest, TheNodeletsAndQuadricSlamGiveTheSameMapAndTrajectories) {
  ASSERT_TRUE(frames_.info);
  ASSERT_FALSE(frames_.depths.empty());
  ros::NodeHandle nh;
  qs::test::FramePlayer player(nh);
  nav_msgs::PathConstPtr path;
  SlamRun live;
  ros::Subscriber path_sub =
      nh.subscribe<nav_msgs::Path>("path", 100, [&](const nav_msgs::PathConstPtr& m) { path = m; });
  ros::Subscriber odom_sub = nh.subscribe<nav_msgs::Odometry>(
      "odom", 100, [&](const nav_msgs::OdometryConstPtr& m) {
        live.T_odom_camera[roundedStamp(m->header.stamp.toSec())] = qs::fromPoseMsg(m->pose.pose);
      });
  ASSERT_TRUE(spinUntil(
      [&] { return path_sub.getNumPublishers() > 0 && odom_sub.getNumPublishers() > 0; }, 60.0))
      << "the pipeline did not come up";
  ASSERT_TRUE(player.waitForSubscribers(10.0)) << "the pipeline does not subscribe";

  for (std::size_t i = 0; i < frames_.depths.size(); ++i) {
    const ros::Time stamp = frames_.depths[i]->header.stamp;
    ASSERT_TRUE(player.play(frames_.depths[i], frames_.info,
                            [&] { return path && path->header.stamp == stamp; }, i == 0 ? 3 : 1))
        << "no path for frame " << i;
  }
  spinUntil([&] { return false; }, 0.5);  // the last odometry
  for (const qs::StampedPose& pose : qs::test::toTrajectory(*path))
    live.T_map_camera[roundedStamp(pose.stamp)] = pose.T_world_sensor;
  quadric_slam::SaveMap save;
  save.request.path = (dir_ / "live" / "map.yaml").string();
  ASSERT_TRUE(ros::service::waitForService("mapping/save_map", ros::Duration(10.0)));
  ASSERT_TRUE(ros::service::call("mapping/save_map", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  live.map = qs::readMapYaml(save.request.path);
  live.reconstruction = pointsPerLandmark((dir_ / "live" / "map.pcd").string());

  const SlamRun offline = runOffline(bag_path_, dir_ / "offline");

  // The same map: landmarks per class, then each landmark (same id) with the same surface.
  const std::map<std::string, int> live_classes = landmarksPerClass(live.map),
                                   offline_classes = landmarksPerClass(offline.map);
  std::printf("live_offline: live %zu landmarks, offline %zu\n", live.map.quadrics.size(),
              offline.map.quadrics.size());
  for (const auto& [quadric_class, count] : offline_classes)
    std::printf("  %s: live %d, offline %d\n", quadric_class.c_str(),
                live_classes.count(quadric_class) ? live_classes.at(quadric_class) : 0, count);
  EXPECT_EQ(live_classes, offline_classes);
  EXPECT_GE(offline_classes.size(), 4u) << "the desk's planes, sphere, cylinders and cone";
  ASSERT_EQ(live.map.quadrics.size(), offline.map.quadrics.size());
  PoseDifference worst_landmark;
  double worst_scale = 0.0;
  for (std::size_t i = 0; i < live.map.quadrics.size(); ++i) {
    const qs::MapFileQuadric &a = live.map.quadrics[i], &b = offline.map.quadrics[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.quadric_class, b.quadric_class) << "landmark " << a.id;
    EXPECT_EQ(a.observations, b.observations) << "landmark " << a.id;
    const PoseDifference d = difference(a.T_map_quadric, b.T_map_quadric);
    EXPECT_LT(d.position, kPositionTolerance) << "landmark " << a.id;
    EXPECT_LT(d.angle, kAngleTolerance) << "landmark " << a.id;
    worst_landmark.position = std::max(worst_landmark.position, d.position);
    worst_landmark.angle = std::max(worst_landmark.angle, d.angle);
    for (int k = 0; k < 3; ++k) {
      const double relative =
          std::abs(a.scale[k] - b.scale[k]) / std::max(std::abs(b.scale[k]), 1e-9);
      EXPECT_LT(relative, kScaleTolerance) << "landmark " << a.id << " scale " << k;
      worst_scale = std::max(worst_scale, relative);
    }
  }
  std::printf("live_offline: landmarks differ by at most %.2e m, %.2e rad, scale %.2e\n",
              worst_landmark.position, worst_landmark.angle, worst_scale);
  // The same reconstruction: the supporting points reached the mapper (over TCP with two
  // managers) as they reach QuadricSlam.
  EXPECT_EQ(live.reconstruction, offline.reconstruction) << "reconstruction points per landmark";
  std::size_t points = 0;
  for (const auto& [id, count] : offline.reconstruction)
    points += count;
  std::printf("live_offline: reconstruction %zu points on %zu landmarks\n", points,
              offline.reconstruction.size());
  EXPECT_GT(points, 1000u);

  // The same trajectories: every frame, in the map and in the odom frame.
  auto compare = [](const PoseByStamp& a, const PoseByStamp& b, const char* name) {
    EXPECT_EQ(a.size(), b.size()) << name;
    PoseDifference worst;
    for (const auto& [stamp, pose] : b) {
      const auto it = a.find(stamp);
      if (it == a.end()) {
        ADD_FAILURE() << name << ": live has no pose at " << stamp;
        continue;
      }
      const PoseDifference d = difference(it->second, pose);
      worst.position = std::max(worst.position, d.position);
      worst.angle = std::max(worst.angle, d.angle);
    }
    std::printf("live_offline: %s: %zu poses, differ by at most %.2e m, %.2e rad\n", name,
                b.size(), worst.position, worst.angle);
    EXPECT_LT(worst.position, kPositionTolerance) << name;
    EXPECT_LT(worst.angle, kAngleTolerance) << name;
  };
  EXPECT_EQ(offline.T_map_camera.size(), frames_.depths.size());
  compare(live.T_map_camera, offline.T_map_camera, "map -> camera");
  compare(live.T_odom_camera, offline.T_odom_camera, "odom -> camera");
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "live_offline_checker");
  return RUN_ALL_TESTS();
}
