// Checker for tum.test: tum.launch plays a synthetic desk bag (rosbag play --clock) into the four
// nodelets. Counted against the bag's own frames: observations for (nearly) every frame, a map
// with every quadric class of the scene, markers and a reconstruction, our tf tree
// map -> odom -> camera beside the bag's /world -> /kinect, the path against the bag's truth
// (groundtruth.txt beside the bag), the ground-truth path beside ours, and the latched map for a
// subscriber that comes late. tum.launch's rgb:=true (its default) plays the bag's colour images
// into the mapper: the reconstruction carries the colours of the rendered surfaces, and every frame
// the mapper processes found its colour image (/diagnostics).
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <nav_msgs/Path.h>
#include <quadric_slam/QuadricMap.h>
#include <quadric_slam/QuadricObservationArray.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <filesystem>
#include <map>
#include <set>

#include "frame_player.h"
#include "path_trajectory.h"
#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/ros/conversions.h"
#include "quadric_slam/ros/markers.h"
#include "synthetic_bag.h"

namespace qs = quadric_slam;
using qs::test::spinUntil;
using qs::test::toTrajectory;

namespace {

// Share of the bag's frames that must come out as observations. Frames are dropped only when the
// pipeline falls behind the player (queues of 2); tum.test plays at a fifth of real time so that
// a loaded 2-core machine keeps up.
constexpr double kMinFrameShare = 0.9;

TEST(TumLaunch, PlaysTheBagIntoAMapThatFollowsTheTruth) {
  ros::NodeHandle nh, private_nh("~");
  std::string bag_path;
  ASSERT_TRUE(private_nh.getParam("bag", bag_path)) << "~bag not set";
  const qs::test::BagDepthFrames bag = qs::test::readBagDepthFrames(bag_path);
  ASSERT_GE(bag.depths.size(), 20u);
  const qs::Trajectory truth = qs::readTumTrajectory(
      (std::filesystem::path(bag_path).parent_path() / "groundtruth.txt").string());
  ASSERT_EQ(truth.size(), bag.depths.size());
  std::set<double> bag_stamps;
  for (const auto& depth : bag.depths)
    bag_stamps.insert(depth->header.stamp.toSec());
  const ros::Time last_stamp = bag.depths.back()->header.stamp;

  std::set<double> observation_stamps;
  quadric_slam::QuadricMapConstPtr map;
  visualization_msgs::MarkerArrayConstPtr markers;
  sensor_msgs::PointCloud2ConstPtr reconstruction;
  nav_msgs::PathConstPtr path, groundtruth_path;
  ros::Subscriber observations_sub = nh.subscribe<quadric_slam::QuadricObservationArray>(
      "observations", 100, [&](const quadric_slam::QuadricObservationArrayConstPtr& m) {
        observation_stamps.insert(m->header.stamp.toSec());
      });
  ros::Subscriber map_sub = nh.subscribe<quadric_slam::QuadricMap>(
      "map", 10, [&](const quadric_slam::QuadricMapConstPtr& m) { map = m; });
  ros::Subscriber markers_sub = nh.subscribe<visualization_msgs::MarkerArray>(
      "markers", 10, [&](const visualization_msgs::MarkerArrayConstPtr& m) { markers = m; });
  ros::Subscriber reconstruction_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      "reconstruction", 10, [&](const sensor_msgs::PointCloud2ConstPtr& m) { reconstruction = m; });
  ros::Subscriber path_sub =
      nh.subscribe<nav_msgs::Path>("path", 100, [&](const nav_msgs::PathConstPtr& m) { path = m; });
  ros::Subscriber groundtruth_sub = nh.subscribe<nav_msgs::Path>(
      "groundtruth_path", 10, [&](const nav_msgs::PathConstPtr& m) { groundtruth_path = m; });
  std::map<std::string, std::string> mapping_diagnostics;
  ros::Subscriber diagnostics_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& m) {
        for (const auto& status : m->status)
          if (status.name.find("mapping") != std::string::npos)
            for (const auto& kv : status.values)
              mapping_diagnostics[kv.key] = kv.value;
      });
  tf2_ros::Buffer tf_buffer(ros::Duration(60.0));
  tf2_ros::TransformListener tf_listener(tf_buffer);

  // The bag plays on its own schedule: wait (wall time) until the player's clock reaches the
  // last frame, then for the pipeline to finish that frame. (rosbag play sends its clock every
  // 10 ms of bag time, so the last clock may stop a few milliseconds short of the last message.)
  const double bag_seconds = (last_stamp - bag.depths.front()->header.stamp).toSec();
  const ros::Time clock_at_end = last_stamp - ros::Duration(0.05);
  ASSERT_TRUE(spinUntil([&] { return ros::Time::isValid() && ros::Time::now() >= clock_at_end; },
                        60.0 + 4.0 * bag_seconds))
      << "the bag's clock (" << ros::Time::now() << ") did not reach its last frame (" << last_stamp
      << ")";
  spinUntil([&] { return path && path->header.stamp == last_stamp; }, 20.0);
  spinUntil([&] { return false; }, 1.0);  // the last latched messages

  // Observations at the input rate: one per bag frame, stamped as the frame.
  std::size_t observed = 0;
  for (double stamp : observation_stamps)
    observed += bag_stamps.count(stamp);
  std::printf("tum: observations for %zu of %zu bag frames\n", observed, bag_stamps.size());
  EXPECT_EQ(observed, observation_stamps.size()) << "observations with stamps not in the bag";
  EXPECT_GE(observed, kMinFrameShare * bag_stamps.size());
  EXPECT_TRUE(observation_stamps.count(*bag_stamps.begin()))
      << "the first frame was lost (the pipeline came up late?)";

  // The map carries every quadric class of the desk scene.
  ASSERT_TRUE(map) << "no map";
  EXPECT_EQ(map->header.frame_id, "map");
  std::map<int, int> per_class;
  for (const quadric_slam::Quadric& q : map->quadrics)
    ++per_class[q.surface.quadric_class];
  std::printf("tum: map of %zu landmarks: %d planes, %d spheres, %d cylinders, %d cones\n",
              map->quadrics.size(), per_class[0], per_class[1], per_class[2], per_class[3]);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_PLANE], 3);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_SPHERE], 1);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_CYLINDER], 1);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_CONE], 1);

  // Markers and reconstruction.
  ASSERT_TRUE(markers) << "no markers";
  EXPECT_GT(markers->markers.size(), map->quadrics.size());
  ASSERT_TRUE(reconstruction) << "no reconstruction";
  EXPECT_EQ(reconstruction->header.frame_id, "map");
  EXPECT_GT(reconstruction->width, 1000u);

  // RGB colours: alpha 255 marks a colour from the image (ros/reconstruction_cloud.h). The desk
  // scene's surfaces are shaded by incidence and textured, so the image colours are many, and
  // differ from the landmark colours the points would otherwise get.
  std::size_t coloured = 0, landmark_coloured = 0;
  std::set<std::uint32_t> colours;
  sensor_msgs::PointCloud2ConstIterator<std::uint32_t> rgb(*reconstruction, "rgb");
  sensor_msgs::PointCloud2ConstIterator<std::uint32_t> label(*reconstruction, "label");
  for (; rgb != rgb.end(); ++rgb, ++label) {
    if ((*rgb >> 24) != 0xFFu)
      continue;
    ++coloured;
    colours.insert(*rgb);
    const std_msgs::ColorRGBA c = qs::landmarkColour(static_cast<int>(*label), 1.0);
    const auto byte = [](float v) { return static_cast<std::uint32_t>(std::lround(v * 255.0f)); };
    landmark_coloured += (*rgb & 0xFFFFFFu) == (byte(c.r) << 16 | byte(c.g) << 8 | byte(c.b));
  }
  std::printf("tum: %zu of %u reconstruction points coloured from the images, %zu colours\n",
              coloured, reconstruction->width, colours.size());
  EXPECT_GE(coloured, 0.95 * reconstruction->width);
  EXPECT_GT(colours.size(), 50u);
  EXPECT_LT(landmark_coloured, 0.01 * coloured + 1);
  // Every frame the mapper processed found its colour image by stamp.
  spinUntil([&] { return mapping_diagnostics.count("frames coloured") > 0; }, 5.0);
  ASSERT_TRUE(mapping_diagnostics.count("frames coloured")) << "no mapping diagnostics";
  const long frames_coloured = std::stol(mapping_diagnostics["frames coloured"]);
  const long frames_without = std::stol(mapping_diagnostics["frames without a matching rgb image"]);
  std::printf("tum: mapper frames coloured %ld, without a matching rgb image %ld\n",
              frames_coloured, frames_without);
  EXPECT_EQ(frames_without, 0);
  EXPECT_GE(frames_coloured, static_cast<long>(kMinFrameShare * bag_stamps.size()));

  // tf: our tree map -> odom -> camera and the bag's /world -> /kinect, two separate trees.
  EXPECT_TRUE(tf_buffer.canTransform("map", "odom", ros::Time(0), ros::Duration(2.0)));
  EXPECT_TRUE(tf_buffer.canTransform("odom", "camera", ros::Time(0), ros::Duration(2.0)));
  EXPECT_TRUE(tf_buffer.canTransform("map", "camera", last_stamp, ros::Duration(2.0)));
  EXPECT_TRUE(tf_buffer.canTransform("world", "kinect", last_stamp, ros::Duration(2.0)));
  EXPECT_TRUE(
      tf_buffer.canTransform("world", "openni_rgb_optical_frame", last_stamp, ros::Duration(2.0)));
  EXPECT_FALSE(tf_buffer.canTransform("map", "world", ros::Time(0)))
      << "our tree joined the bag's (it must leave the bag's /tf untouched)";

  // The final path against the bag's truth, and the truth's path beside ours.
  ASSERT_TRUE(path) << "no path";
  EXPECT_EQ(path->header.frame_id, "map");
  const qs::AteResult ate = qs::AbsoluteTrajectoryError().evaluate(truth, toTrajectory(*path));
  std::printf("tum: path ATE %.4f m over %zu poses\n", ate.rmse(), ate.pairs());
  EXPECT_GE(ate.pairs(), kMinFrameShare * truth.size());
  EXPECT_LT(ate.rmse(), 0.01);
  ASSERT_TRUE(groundtruth_path) << "no groundtruth_path";
  EXPECT_EQ(groundtruth_path->header.frame_id, "map");
  EXPECT_GE(groundtruth_path->poses.size(), 0.5 * truth.size());

  // A subscriber that comes after the bag has ended gets the latched map.
  quadric_slam::QuadricMapConstPtr late;
  ros::Subscriber late_sub = nh.subscribe<quadric_slam::QuadricMap>(
      "map", 1, [&](const quadric_slam::QuadricMapConstPtr& m) { late = m; });
  ASSERT_TRUE(spinUntil([&] { return late != nullptr; }, 10.0)) << "the map is not latched";
  EXPECT_EQ(late->quadrics.size(), map->quadrics.size());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "tum_checker");
  return RUN_ALL_TESTS();
}
