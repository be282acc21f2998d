// Frame ids as tf2 and rviz accept them: without a leading '/', however they arrive (a TUM bag's
// "/openni_rgb_optical_frame", a parameter written "/map").
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "quadric_slam/ros/frame_ids.h"

namespace qs = quadric_slam;

TEST(FrameIds, LeadingSlashesGoAndNothingElseChanges) {
  EXPECT_EQ(qs::withoutLeadingSlash("/openni_rgb_optical_frame"), "openni_rgb_optical_frame");
  EXPECT_EQ(qs::withoutLeadingSlash("//world"), "world");
  EXPECT_EQ(qs::withoutLeadingSlash("camera"), "camera");
  // Only a leading '/': a namespaced frame keeps its inner ones.
  EXPECT_EQ(qs::withoutLeadingSlash("/robot/camera"), "robot/camera");
  EXPECT_EQ(qs::withoutLeadingSlash("robot/camera/"), "robot/camera/");
  EXPECT_EQ(qs::withoutLeadingSlash("/"), "");
  EXPECT_EQ(qs::withoutLeadingSlash(""), "");
}

TEST(FrameIds, SameFrameIgnoresOnlyTheLeadingSlash) {
  EXPECT_TRUE(qs::sameFrame("/odom", "odom"));
  EXPECT_TRUE(qs::sameFrame("odom", "/odom"));
  EXPECT_TRUE(qs::sameFrame("map", "map"));
  EXPECT_FALSE(qs::sameFrame("/map", "odom"));
  EXPECT_FALSE(qs::sameFrame("map", "Map"));
  EXPECT_FALSE(qs::sameFrame("robot/map", "map"));
}

TEST(FrameIds, OutputFrameIsTheConfiguredOneElseTheInputsWithoutSlash) {
  EXPECT_EQ(qs::outputFrameId("", "/openni_rgb_optical_frame"), "openni_rgb_optical_frame");
  EXPECT_EQ(qs::outputFrameId("camera", "/openni_rgb_optical_frame"), "camera");
  EXPECT_EQ(qs::outputFrameId("/camera", "/openni_rgb_optical_frame"), "camera");
  EXPECT_EQ(qs::outputFrameId("", "camera_depth_optical_frame"), "camera_depth_optical_frame");
}

TEST(FrameIds, FrameParametersAreReadWithoutSlashAndLoggedSo) {
  const qs::YamlParamReader reader(YAML::Load("{map_frame: /map, odom_frame: odom}"));
  qs::ParamLog log;
  std::string map_frame = "default_map", odom_frame, camera_frame = "/camera";
  qs::readFrameParam(reader, "map_frame", map_frame, log);
  qs::readFrameParam(reader, "odom_frame", odom_frame, log);
  // Absent: the default stays, also without its slash.
  qs::readFrameParam(reader, "camera_frame", camera_frame, log);
  EXPECT_EQ(map_frame, "map");
  EXPECT_EQ(odom_frame, "odom");
  EXPECT_EQ(camera_frame, "camera");
  EXPECT_EQ(log.str(), "\n  map_frame: map\n  odom_frame: odom\n  camera_frame: camera");
  EXPECT_THROW(qs::readFrameParam(qs::YamlParamReader(YAML::Load("{map_frame: [1]}")),
                                  "map_frame", map_frame, log),
               std::invalid_argument);
}
