// Checker for mapping.test: renders a short synthetic TUM bag of config/scenes/desk.yaml with the
// project's generator, publishes its depth frames one at a time on TUM's topics into the pipeline
// (normal_estimation, quadric_segmentation, odometry, mapping in one manager) and checks what the
// mapping nodelet publishes: the map against the scene's truth, markers, reconstruction, path
// against the ground truth, tf map -> odom, the latched map for a late subscriber, /diagnostics,
// ~save_map / ~load_map round trip, localisation against the loaded map when the sequence plays
// again (time going backwards), and bad input that must be dropped without harm.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <quadric_slam/LoadMap.h>
#include <quadric_slam/QuadricMap.h>
#include <quadric_slam/QuadricObservationArray.h>
#include <quadric_slam/SaveMap.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <set>

#include "frame_player.h"
#include "path_trajectory.h"
#include "quadric_slam/eval/map_metrics.h"
#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/io/landmark_map_file.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/ros/conversions.h"
#include "quadric_slam/ros/markers.h"
#include "quadric_slam/sim/surfaces.h"
#include "desk_bag_test.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;
using qs::test::spinUntil;
using qs::test::toTrajectory;

namespace {

constexpr double kSeconds = 4.0;  // 40 frames at 10 Hz: the camera moves ~0.5 m
constexpr double kRate = 10.0;
constexpr std::size_t kReplayFrames = 12;  // played again against the loaded map

qs::MapFile toMapFile(const quadric_slam::QuadricMap& map) {
  std::vector<qs::QuadricLandmark> landmarks;
  for (const quadric_slam::Quadric& quadric : map.quadrics)
    landmarks.push_back(qs::fromLandmarkMsg(quadric));
  return qs::mapFileFromLandmarks(landmarks, map.header.frame_id);
}

class MappingTest : public qs::test::DeskBagTest {
 protected:
  MappingTest() : DeskBagTest("mapping_test", kRate, kSeconds, 2) {}
};

TEST_F(MappingTest, MapsTheDeskSavesLoadsAndLocalises) {
  ASSERT_TRUE(info_);
  ASSERT_EQ(depths_.size(), truth_.size());
  ros::NodeHandle nh;
  qs::test::FramePlayer player(nh);
  quadric_slam::QuadricMapConstPtr map;
  visualization_msgs::MarkerArrayConstPtr markers;
  sensor_msgs::PointCloud2ConstPtr reconstruction;
  nav_msgs::PathConstPtr path;
  std::map<double, nav_msgs::OdometryConstPtr> odoms;
  std::set<double> observation_stamps;
  diagnostic_msgs::DiagnosticStatus diagnostics;
  int maps_received = 0, reconstructions_received = 0;
  ros::Subscriber map_sub = nh.subscribe<quadric_slam::QuadricMap>(
      "map", 10, [&](const quadric_slam::QuadricMapConstPtr& m) {
        map = m;
        ++maps_received;
      });
  ros::Subscriber markers_sub = nh.subscribe<visualization_msgs::MarkerArray>(
      "markers", 10, [&](const visualization_msgs::MarkerArrayConstPtr& m) { markers = m; });
  ros::Subscriber reconstruction_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      "reconstruction", 10, [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        reconstruction = m;
        ++reconstructions_received;
      });
  ros::Subscriber path_sub =
      nh.subscribe<nav_msgs::Path>("path", 100, [&](const nav_msgs::PathConstPtr& m) { path = m; });
  ros::Subscriber odom_sub = nh.subscribe<nav_msgs::Odometry>(
      "odom", 100,
      [&](const nav_msgs::OdometryConstPtr& m) { odoms[m->header.stamp.toSec()] = m; });
  ros::Subscriber observations_sub = nh.subscribe<quadric_slam::QuadricObservationArray>(
      "observations", 100, [&](const quadric_slam::QuadricObservationArrayConstPtr& m) {
        observation_stamps.insert(m->header.stamp.toSec());
      });
  ros::Subscriber diagnostics_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& m) {
        for (const auto& status : m->status)
          if (status.name.find("mapping") != std::string::npos)
            diagnostics = status;
      });
  auto tf_buffer = std::make_unique<tf2_ros::Buffer>();
  auto tf_listener = std::make_unique<tf2_ros::TransformListener>(*tf_buffer);

  // One connection per subscribing process: all nodelets share the manager's.
  ASSERT_TRUE(spinUntil(
      [&] {
        return path_sub.getNumPublishers() > 0 && map_sub.getNumPublishers() > 0 &&
               odom_sub.getNumPublishers() > 0 && reconstruction_sub.getNumPublishers() > 0;
      },
      60.0))
      << "the pipeline did not come up";
  ASSERT_TRUE(player.waitForSubscribers(10.0)) << "the pipeline does not subscribe";
  ASSERT_TRUE(spinUntil([&] { return map != nullptr; }, 10.0)) << "no latched map at start";
  EXPECT_TRUE(map->quadrics.empty());

  // Publishes a frame (with camera_info) and waits for the mapper's path to reach its stamp: the
  // test checks the computation, not the machine's speed. The very first frame may beat the
  // camera_info to the nodelets (the nodelet drops it by design) and is sent again.
  auto play = [&](const sensor_msgs::ImageConstPtr& depth, int attempts) {
    const ros::Time stamp = depth->header.stamp;
    if (player.play(depth, info_, [&] { return path && path->header.stamp == stamp; }, attempts))
      return true;
    std::printf("mapping: frame %.3f: odom %s, observations %s, path at %.3f; diagnostics: %s\n",
                stamp.toSec(), odoms.count(stamp.toSec()) ? "yes" : "no",
                observation_stamps.count(stamp.toSec()) ? "yes" : "no",
                path ? path->header.stamp.toSec() : 0.0, diagnostics.message.c_str());
    for (const auto& kv : diagnostics.values)
      std::printf("  %s: %s\n", kv.key.c_str(), kv.value.c_str());
    return false;
  };
  for (std::size_t i = 0; i < depths_.size(); ++i)
    ASSERT_TRUE(play(depths_[i], i == 0 ? 3 : 1)) << "no path for frame " << i;
  spinUntil([&] { return false; }, 1.5);  // the last latched messages, a diagnostics report

  // The map: the desk scene's primitives, each seen in >= 5 frames, in the map frame.
  ASSERT_TRUE(map);
  const quadric_slam::QuadricMap mapped = *map;
  EXPECT_EQ(mapped.header.frame_id, "map");
  std::map<int, int> per_class;
  std::set<std::uint32_t> ids;
  for (const quadric_slam::Quadric& q : mapped.quadrics) {
    ++per_class[q.surface.quadric_class];
    ids.insert(q.id);
    EXPECT_GE(q.observations, 5u) << "landmark " << q.id << " entered early";
    EXPECT_TRUE(q.covariance.empty() ||
                q.covariance.size() == std::size_t(q.minimal_dimension) * q.minimal_dimension);
  }
  std::printf("mapping: %zu landmarks: %d planes, %d spheres, %d cylinders, %d cones\n",
              mapped.quadrics.size(), per_class[0], per_class[1], per_class[2], per_class[3]);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_PLANE], 3);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_SPHERE], 1);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_CYLINDER], 1);
  EXPECT_GE(per_class[quadric_slam::QuadricSurface::CLASS_CONE], 1);

  // The path: one pose per frame in the map frame, as accurate as the odometry (millimetres on
  // this scene), against the ground truth.
  ASSERT_TRUE(path);
  EXPECT_EQ(path->header.frame_id, "map");
  EXPECT_EQ(path->poses.size(), truth_.size());
  const qs::AbsoluteTrajectoryError ate_evaluator;
  const qs::AteResult ate = ate_evaluator.evaluate(truth_, toTrajectory(*path));
  qs::Trajectory odometry;
  for (const auto& [stamp, odom] : odoms)
    odometry.push_back({stamp, qs::fromPoseMsg(odom->pose.pose)});
  const qs::AteResult odometry_ate = ate_evaluator.evaluate(truth_, odometry);
  std::printf("mapping: path ATE %.4f m over %zu poses (odometry %.4f m)\n", ate.rmse(),
              ate.pairs(), odometry_ate.rmse());
  EXPECT_EQ(ate.pairs(), truth_.size());
  EXPECT_LT(ate.rmse(), 0.01);
  EXPECT_LT(ate.rmse(), odometry_ate.rmse() + 0.003);

  // The map against the scene's truth, in the ground-truth frame (the path's alignment): every
  // landmark is a real primitive, none twice.
  qs::MapFile truth_map;
  for (const qs::Surface& surface : qs::buildSurfaces(scene_))
    truth_map.quadrics.push_back(surface.toMapQuadric());
  const qs::MapReport report =
      qs::MapEvaluator().evaluate(truth_map, toMapFile(mapped), ate.T_gt_est);
  std::printf("%s", qs::formatMapReport(report).c_str());
  EXPECT_GE(report.matched, 6);
  EXPECT_EQ(report.duplicates, 0);
  EXPECT_EQ(report.unmatched_estimates, 0);

  // Markers: one shape per landmark (plus the DELETEALL and the labels), in the map frame.
  ASSERT_TRUE(markers);
  EXPECT_GT(markers->markers.size(), mapped.quadrics.size());
  for (const visualization_msgs::Marker& marker : markers->markers) {
    if (marker.action != visualization_msgs::Marker::DELETEALL) {
      EXPECT_EQ(marker.header.frame_id, "map");
    }
  }

  // Reconstruction: points on the landmarks, coloured as their markers, labelled with their ids.
  ASSERT_TRUE(reconstruction);
  EXPECT_GE(reconstructions_received, 2);  // the initial empty one and periodic ones
  EXPECT_EQ(reconstruction->header.frame_id, "map");
  EXPECT_GT(reconstruction->width, 1000u);
  std::set<std::string> fields;
  for (const auto& field : reconstruction->fields)
    fields.insert(field.name);
  EXPECT_EQ(fields, (std::set<std::string>{"x", "y", "z", "rgb", "label"}));
  {
    sensor_msgs::PointCloud2ConstIterator<float> x(*reconstruction, "x"),
        rgb(*reconstruction, "rgb");
    sensor_msgs::PointCloud2ConstIterator<std::uint32_t> label(*reconstruction, "label");
    for (; x != x.end(); ++x, ++rgb, ++label) {
      ASSERT_TRUE(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]));
      ASSERT_TRUE(ids.count(*label)) << "point of unknown landmark " << *label;
      std::uint32_t bits;
      const float packed = *rgb;
      std::memcpy(&bits, &packed, sizeof(bits));
      const std_msgs::ColorRGBA colour = qs::landmarkColour(static_cast<int>(*label), 1.0);
      ASSERT_NEAR(((bits >> 16) & 0xff) / 255.0, colour.r, 0.01);
      ASSERT_NEAR(((bits >> 8) & 0xff) / 255.0, colour.g, 0.01);
      ASSERT_NEAR((bits & 0xff) / 255.0, colour.b, 0.01);
    }
  }

  // tf map -> odom (REP-105): a finite rigid transform, close to the identity on this easy run.
  geometry_msgs::TransformStamped map_odom;
  ASSERT_TRUE(tf_buffer->canTransform("map", "odom", ros::Time(0), ros::Duration(2.0)));
  map_odom = tf_buffer->lookupTransform("map", "odom", ros::Time(0));
  const auto& t = map_odom.transform.translation;
  const auto& r = map_odom.transform.rotation;
  EXPECT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z));
  EXPECT_NEAR(r.x * r.x + r.y * r.y + r.z * r.z + r.w * r.w, 1.0, 1e-6);
  EXPECT_LT(std::sqrt(t.x * t.x + t.y * t.y + t.z * t.z), 0.05);
  EXPECT_TRUE(tf_buffer->canTransform("map", "camera", ros::Time(0), ros::Duration(2.0)));
  tf_listener.reset();  // the replay below sends the same stamps again
  tf_buffer.reset();

  // A late subscriber gets the latched map.
  {
    quadric_slam::QuadricMapConstPtr late;
    ros::Subscriber late_sub = nh.subscribe<quadric_slam::QuadricMap>(
        "map", 1, [&](const quadric_slam::QuadricMapConstPtr& m) { late = m; });
    ASSERT_TRUE(spinUntil([&] { return late != nullptr; }, 10.0)) << "the map is not latched";
    EXPECT_EQ(late->quadrics.size(), mapped.quadrics.size());
  }

  // /diagnostics: the mapping nodelet's health with its figures.
  ASSERT_TRUE(spinUntil([&] { return !diagnostics.name.empty(); }, 5.0)) << "no diagnostics";
  std::map<std::string, std::string> values;
  for (const auto& kv : diagnostics.values)
    values[kv.key] = kv.value;
  for (const char* key : {"landmarks", "landmarks: plane", "landmarks: cylinder",
                          "frames processed", "frames dropped", "window keyframes",
                          "solve time (ms, last keyframe)", "last frame: to landmarks"})
    EXPECT_TRUE(values.count(key)) << "diagnostics lack '" << key << "'";
  EXPECT_EQ(values["landmarks"], std::to_string(mapped.quadrics.size()));
  EXPECT_EQ(values["frames processed"], std::to_string(truth_.size()));

  // ~save_map then ~load_map: the same landmarks come back. On save the map and reconstruction
  // are published as saved (counts move on between keyframes; estimates only on keyframes).
  const std::string map_path = (dir_ / "maps" / "desk.yaml").string();
  quadric_slam::SaveMap save;
  save.request.path = map_path;
  const int maps_before_save = maps_received,
            reconstructions_before_save = reconstructions_received;
  ASSERT_TRUE(ros::service::waitForService("mapping/save_map", ros::Duration(5.0)));
  ASSERT_TRUE(ros::service::call("mapping/save_map", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  std::printf("mapping: save_map: %s\n", save.response.message.c_str());
  ASSERT_TRUE(spinUntil(
      [&] {
        return maps_received > maps_before_save &&
               reconstructions_received > reconstructions_before_save;
      },
      5.0))
      << "map and reconstruction not published on save";
  const quadric_slam::QuadricMap saved = *map;
  const std::uint32_t saved_points = reconstruction->width;
  EXPECT_EQ(save.response.num_quadrics, saved.quadrics.size());
  ASSERT_TRUE(fs::exists(map_path));
  EXPECT_TRUE(fs::exists(dir_ / "maps" / "desk.pcd"));
  const qs::MapFile file = qs::readMapYaml(map_path);
  EXPECT_EQ(file.frame_id, "map");
  ASSERT_EQ(file.quadrics.size(), saved.quadrics.size());
  for (std::size_t i = 0; i < file.quadrics.size(); ++i) {
    EXPECT_EQ(file.quadrics[i].id, static_cast<int>(saved.quadrics[i].id));
    EXPECT_EQ(file.quadrics[i].observations, static_cast<int>(saved.quadrics[i].observations));
  }
  quadric_slam::SaveMap save_nowhere;  // empty path and ~map_file empty: a clear refusal
  ASSERT_TRUE(ros::service::call("mapping/save_map", save_nowhere));
  EXPECT_FALSE(save_nowhere.response.success);
  EXPECT_FALSE(save_nowhere.response.message.empty());

  // Same ids, classes, poses and scales (to the file's 9 digits); `counts`: same observations.
  auto expectSameLandmarks = [&](const quadric_slam::QuadricMap& a_map,
                                 const quadric_slam::QuadricMap& b_map, bool counts,
                                 const char* when) {
    ASSERT_EQ(a_map.quadrics.size(), b_map.quadrics.size()) << when;
    for (std::size_t i = 0; i < a_map.quadrics.size(); ++i) {
      const quadric_slam::Quadric &a = a_map.quadrics[i], &b = b_map.quadrics[i];
      EXPECT_EQ(a.id, b.id) << when;
      EXPECT_EQ(a.surface.quadric_class, b.surface.quadric_class) << when << " " << a.id;
      if (counts) {
        EXPECT_EQ(a.observations, b.observations) << when << " " << a.id;
      }
      const Eigen::Isometry3d Ta = qs::fromPoseMsg(a.surface.pose),
                              Tb = qs::fromPoseMsg(b.surface.pose);
      EXPECT_LT((Ta.translation() - Tb.translation()).norm(), 1e-6) << when << " " << a.id;
      EXPECT_LT(Eigen::AngleAxisd(Ta.linear().transpose() * Tb.linear()).angle(), 1e-6)
          << when << " " << a.id;
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(a.surface.scale[k], b.surface.scale[k], 1e-6 * a.surface.scale[k]) << when;
    }
  };
  expectSameLandmarks(mapped, saved, false, "saved vs last keyframe");

  const int maps_before_load = maps_received;
  quadric_slam::LoadMap load;
  load.request.path = map_path;
  load.request.localization_only = true;
  ASSERT_TRUE(ros::service::call("mapping/load_map", load));
  ASSERT_TRUE(load.response.success) << load.response.message;
  std::printf("mapping: load_map: %s\n", load.response.message.c_str());
  EXPECT_EQ(load.response.num_quadrics, saved.quadrics.size());
  ASSERT_TRUE(spinUntil([&] { return maps_received > maps_before_load; }, 5.0));
  expectSameLandmarks(saved, *map, true, "after load");
  // The reconstruction came back from the PCD beside the map (points that project into the same
  // voxel of their surface merge).
  ASSERT_TRUE(
      spinUntil([&] { return reconstructions_received > reconstructions_before_save + 1; }, 5.0));
  std::printf("mapping: reconstruction saved %u points, loaded %u\n", saved_points,
              reconstruction->width);
  EXPECT_GE(reconstruction->width, 0.7 * saved_points);
  EXPECT_LE(reconstruction->width, saved_points);

  // The sequence again (time goes backwards: odometry and mapper reset, the mapper to the loaded
  // map): the camera is localised against the fixed map, which gains no landmark.
  path.reset();
  for (std::size_t i = 0; i < kReplayFrames; ++i)
    ASSERT_TRUE(play(depths_[i], 1)) << "no path for replayed frame " << i;
  spinUntil([&] { return false; }, 0.5);
  ASSERT_EQ(path->poses.size(), kReplayFrames);  // the reset started a new path
  const qs::Trajectory replay_truth(truth_.begin(), truth_.begin() + kReplayFrames);
  const qs::AteResult replay_ate = ate_evaluator.evaluate(replay_truth, toTrajectory(*path));
  std::printf("mapping: localisation ATE %.4f m over %zu poses\n", replay_ate.rmse(),
              replay_ate.pairs());
  EXPECT_LT(replay_ate.rmse(), 0.01);
  expectSameLandmarks(saved, *map, false, "after localisation");
  int observed_again = 0;
  for (std::size_t i = 0; i < map->quadrics.size(); ++i)
    observed_again += map->quadrics[i].observations > saved.quadrics[i].observations;
  EXPECT_GT(observed_again, 0) << "the loaded landmarks were not recognised";

  // Bad input is dropped, named and counted; the nodelet keeps working.
  // The latest report made after the call (reports come once a second).
  auto diagnosticValues = [&] {
    diagnostics = diagnostic_msgs::DiagnosticStatus();
    spinUntil([&] { return false; }, 1.3);
    EXPECT_FALSE(diagnostics.name.empty()) << "no diagnostics";
    std::map<std::string, long> out;
    for (const auto& kv : diagnostics.values) {
      try {
        out[kv.key] = std::stol(kv.value);
      } catch (const std::exception&) {
      }
    }
    return out;
  };
  std::map<std::string, long> before = diagnosticValues();
  EXPECT_EQ(before["resets (time went backwards)"], 1);
  const nav_msgs::Odometry last_odom = *odoms.at(depths_[kReplayFrames - 1]->header.stamp.toSec());
  odom_sub.shutdown();  // so that the subscriber counts below are the manager's
  observations_sub.shutdown();
  ros::Publisher observations_pub =
      nh.advertise<quadric_slam::QuadricObservationArray>("observations", 5);
  ros::Publisher fake_odom_pub = nh.advertise<nav_msgs::Odometry>("odom", 5);
  ASSERT_TRUE(spinUntil(
      [&] {
        return observations_pub.getNumSubscribers() > 0 && fake_odom_pub.getNumSubscribers() > 0;
      },
      10.0));
  auto sendPair =
      [&](double after_s, const std::function<void(nav_msgs::Odometry&)>& spoil_odom,
          const std::function<void(quadric_slam::QuadricObservationArray&)>& spoil_observations) {
        nav_msgs::Odometry odom = last_odom;
        odom.header.stamp += ros::Duration(after_s);
        quadric_slam::QuadricObservationArray observations;
        observations.header.stamp = odom.header.stamp;
        observations.header.frame_id = depths_[0]->header.frame_id;
        spoil_odom(odom);
        spoil_observations(observations);
        fake_odom_pub.publish(odom);
        observations_pub.publish(observations);
        return odom.header.stamp;
      };
  sendPair(
      10.0, [](nav_msgs::Odometry& o) { o.pose.pose.position.x = std::nan(""); },
      [](quadric_slam::QuadricObservationArray&) {});
  sendPair(
      11.0, [](nav_msgs::Odometry& o) { o.pose.pose.orientation.w = 3.0; },
      [](quadric_slam::QuadricObservationArray&) {});
  sendPair(
      12.0, [](nav_msgs::Odometry& o) { o.pose.covariance[0] = -1.0; },
      [](quadric_slam::QuadricObservationArray&) {});
  // A usable frame with one malformed observation: the frame is used, the observation dropped.
  const ros::Time good = sendPair(
      13.0, [](nav_msgs::Odometry&) {},
      [](quadric_slam::QuadricObservationArray& a) {
        quadric_slam::QuadricObservation bad;
        bad.surface.quadric_class = 42;
        a.observations.push_back(bad);
      });
  ASSERT_TRUE(spinUntil([&] { return path && path->header.stamp == good; }, 10.0))
      << "the nodelet stopped after bad input";
  std::map<std::string, long> after = diagnosticValues();
  EXPECT_EQ(after["frames dropped"] - before["frames dropped"], 3);
  EXPECT_EQ(after["observations dropped"] - before["observations dropped"], 1);
  EXPECT_EQ(after["frames processed"] - before["frames processed"], 1);
  std::printf("mapping: diagnostics after bad input: %s\n", diagnostics.message.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "mapping_checker");
  return RUN_ALL_TESTS();
}
